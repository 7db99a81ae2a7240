// Jacobi-preconditioned BiCGSTAB on the GPU (float, solver/gpu/gpu_kernels.h) for the three rgb systems of
// a coarse multires level at once: the algorithm of multires/bicgstab.h with its breakdown, stagnation,
// divergence and revert rules applied per channel (a channel that stops is frozen while the others go
// on). Float reaches relative residuals of ~1e-6 at best; the coarse levels only provide start vectors
// (the level-0 CG decides the accuracy), so that is enough.
#pragma once

#include "multires/bicgstab.h"
#include "solver/gpu/gpu_kernels.h"
#include "solver/gpu/gpu_matrix.h"

#include <array>

namespace waxwork {

// Solves A x = b per channel with x the start vector on entry (device buffers of A's size, rgb
// interleaved). inv_diag: the Jacobi preconditioner (GpuKernels::extract_diagonal). On return x is
// finite per channel and its true residual no larger than the start vector's (else reverted).
std::array<BicgstabResult, 3> solve_gpu_bicgstab(GpuKernels& kernels, const GpuMatrix& a, const GpuBuffer& inv_diag,
                                                 const GpuBuffer& b, GpuBuffer& x, const BicgstabOptions& options = {});

}  // namespace waxwork
