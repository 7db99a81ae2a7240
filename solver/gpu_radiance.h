// The view-independent exitant radiance factor of solver/radiance.h (Li et al. 2013, Eq. 3 without
// F_t) computed on the device from the resident fluence, so a renderer on the same context can read E
// without a round trip through the CPU:
//     E = max( (1 + 1/A) / (4 pi) phi - 4 / ((1 + F_dr) 4 pi) q, 0 )
// The two weights depend only on the boundary vertex's eta (boundary_vertex_eta), so they are
// uploaded once per material change; they are zero at interior vertices (E = 0 there, as on the CPU).
#pragma once

#include "solver/gpu_kernels.h"
#include "solver/radiance.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <vector>

namespace waxwork {

class GpuRadiance {
public:
    GpuRadiance(GpuKernels& kernels, const TetMesh& mesh, const TetConnectivity& connectivity,
                const std::vector<TetMaterial>& materials);

    // q per vertex (volume order), uploaded once per lighting change.
    void set_light(const std::vector<std::array<double, 3>>& q);
    // e = E per vertex, rgb interleaved (a buffer of kernels.vector(rows)); phi from the solver
    // (GpuDiffusionSolver::solution_buffer).
    void compute(const GpuBuffer& phi, GpuBuffer& e, const RadianceOptions& options = {});
    size_t size() const { return rows_; }

private:
    GpuKernels* kernels_;
    size_t rows_;
    GpuBuffer phi_weight_, q_weight_, q_;
};

}  // namespace waxwork
