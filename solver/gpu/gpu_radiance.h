// The view-independent exitant radiance factor of solver/radiance.h (Li et al. 2013, Eq. 3 without
// F_t) computed on the device from the resident fluence, so a renderer on the same context can read E
// without a round trip through the CPU:
//     E = max( phi_weight phi - q_weight q, 0 )   (exitant_radiance_weights of the row's eta)
// at chosen rows, each reading phi at one volume vertex: the renderer's shading vertices
// (shading_surface.h), several of which read the same vertex where the surface is split at a crease,
// each with its own q. The two weights depend only on the row's eta, so they are uploaded once per
// shading or material change.
#pragma once

#include "solver/gpu/gpu_kernels.h"
#include "solver/radiance.h"

#include <array>
#include <cstdint>
#include <vector>

namespace waxwork {

// What each row of E reads: row r takes phi at volume vertex `vertex[r]` with relative index `eta[r]`.
struct RadianceRows {
    std::vector<int32_t> vertex;
    std::vector<double> eta;
    bool operator==(const RadianceRows&) const = default;
};

// The rows of the shading vertices of `surface` split as `shading`: each copy reads its surface
// vertex's volume vertex and eta. Throws InvalidArgumentError for a copy of no surface vertex.
RadianceRows shading_radiance_rows(const BoundarySurface& surface, const ShadingSurface& shading);

class GpuRadiance {
public:
    // E at `rows`, for phi over `phi_rows` volume vertices. Throws InvalidArgumentError for mismatched
    // sizes, a vertex out of range or an eta that is not finite and at least 1.
    GpuRadiance(GpuKernels& kernels, const RadianceRows& rows, size_t phi_rows);

    // q per row, uploaded once per lighting change.
    void set_light(const std::vector<std::array<double, 3>>& q);
    // e = E per row, rgb interleaved (3 floats per row); phi per volume vertex from the solver
    // (GpuDiffusionSolver::solution_buffer).
    void compute(const GpuBuffer& phi, GpuBuffer& e, const RadianceOptions& options = {});
    size_t size() const { return rows_; }

private:
    GpuKernels* kernels_;
    size_t rows_, phi_rows_;
    GpuBuffer row_vertex_, phi_weight_, q_weight_, q_, row_phi_;
};

}  // namespace waxwork
