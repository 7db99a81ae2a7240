// The multigrid V-cycle of multires/multigrid_preconditioner.h on the GPU (OpenGL 4.3 compute
// shaders): z = B r for the three rgb channels at once, one V-cycle from a zero start, with the same
// algorithm and coefficients as the CPU MultigridPreconditioner::apply_rgb in float (Chebyshev
// smoothing on each level's Galerkin operator, P^T restriction, Eq. 16 interpolation P back).
//
// The operators are built on the host (the Galerkin products, the dropping and lumping, the Gershgorin
// bounds and the coarsest factorisation) by the CPU preconditioner this object borrows, and uploaded
// once: each level's three-channel operator as a GpuMatrix, its inverse diagonal, P^l and its
// transpose. The kernels (GpuKernels::multigrid_smooth, multigrid_residual, interpolate) perform the
// CPU float V-cycle's operations in its order without fused multiply-adds (`precise`), and the
// coarsest solve is the CPU's own, so the device result is apply_rgb's bit for bit on llvmpipe
// (tests/multires/gpu_multigrid_preconditioner_test.cpp). llvmpipe (Mesa 22.3, LLVM 15) happens to give
// the same bits without `precise` too (tried); it is there for drivers that contract a * b + c into
// fused multiply-adds, which GLSL allows by default. A driver that fused anyway would differ by float
// rounding only.
//
// The coarsest level is solved on the host with the CPU preconditioner's exact sparse LDL^T
// factorisation (one read-back of the coarsest right-hand side and one upload of its solution per
// V-cycle, 3 x at most min_coarse_vertices floats each: a few KB). Why not on the device: the exact
// alternatives there are a dense inverse (n_c^2 floats per channel: 12 MB and 3M multiply-adds per
// V-cycle at n_c = 1000, more than a level-0 product at 50K tets on llvmpipe, and a float inverse of
// an ill-conditioned operator loses the accuracy the factorisation keeps) or triangular solves (a
// sequential chain of dispatches); an inexact device solve (a few Chebyshev or CG iterations) would
// change B, and CG would no longer run the preconditioner the CPU runs. The round trip costs one
// synchronisation, and each CG step synchronises twice anyway for its reductions. Measured on
// llvmpipe (bench/gpu_solver_bench.cpp, BM_GpuMultigridVcycle; 2 loaded cores): spot at 50K tets (4
// levels, 326 coarsest rows) 10.1 ms per V-cycle, of which the round trip is 0.03 ms; at 500K (5
// levels, 523 rows) 85 ms and 0.09 ms.
//
// Why no further fusion: each smoothing step is already one dispatch (residual, Chebyshev update and
// the new iterate together); what is left per level is the residual before the restriction, the
// restriction and the prolongation, each a sweep that needs the previous one finished everywhere.
#pragma once

#include "multires/multigrid_preconditioner.h"
#include "solver/gpu/gpu_kernels.h"
#include "solver/gpu/gpu_matrix.h"

#include <memory>
#include <span>
#include <vector>

namespace waxwork {

class GpuMultigridPreconditioner {
public:
    // Uploads `preconditioner`'s levels; runs with `kernels` (which must hold the products of `format`).
    // Both must outlive this object, and the kernels' OpenGL context must be current whenever it is
    // used. The V-cycle is always the float one (MultigridOptions::single_precision is not consulted:
    // the device has no double smoothing kernels). Throws GpuError when the driver fails.
    GpuMultigridPreconditioner(GpuKernels& kernels, MultigridPreconditioner& preconditioner,
                               GpuMatrixFormat format = GpuMatrixFormat::SellCSigma);
    ~GpuMultigridPreconditioner();
    GpuMultigridPreconditioner(const GpuMultigridPreconditioner&) = delete;
    GpuMultigridPreconditioner& operator=(const GpuMultigridPreconditioner&) = delete;

    size_t size() const;
    size_t level_count() const { return levels_.size(); }

    // z = B r on the device, r and z rgb-interleaved float vectors of size() vertices (3 floats each,
    // distinct buffers). Throws InvalidArgumentError on a size mismatch or r aliasing z.
    void apply(const GpuBuffer& r, GpuBuffer& z);

    // After painting changed the level-0 rows `changed_rows` (ascending; the hierarchy's level 0 already
    // holds the new values, as for MultigridPreconditioner::update_values): updates the CPU
    // preconditioner, then uploads only the recomputed rows of every level (operator entries and
    // inverse diagonal) and the new Chebyshev coefficients. The device then holds what a new object
    // built on the updated preconditioner would hold, bit for bit.
    void update_values(std::span<const int32_t> changed_rows);

    // Level l's operator and inverse diagonal on the device (level 0: the fine matrix, in float: what
    // the CG's products use, so the matrix is stored once).
    const GpuMatrix& matrix(size_t level) const;
    const GpuBuffer& inverse_diagonal(size_t level) const;

private:
    struct Level;
    void upload_inverse_diagonal(size_t l, std::span<const int32_t> rows);
    // Runs the V-cycle from level l with right-hand side `b`; returns the buffer holding its x.
    GpuBuffer* vcycle(size_t l, const GpuBuffer& b, GpuBuffer* x, GpuBuffer* other);

    GpuKernels& kernels_;
    MultigridPreconditioner& preconditioner_;
    std::vector<std::unique_ptr<Level>> levels_;
    std::vector<float> coarse_b_, coarse_x_;  // host staging of the coarsest solve
};

}  // namespace waxwork
