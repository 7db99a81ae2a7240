#include "solver/gpu_radiance.h"

#include "solver/material.h"
#include "tetops/error.h"

#include <numbers>
#include <string>

namespace waxwork {

GpuRadiance::GpuRadiance(GpuKernels& kernels, const TetMesh& mesh, const TetConnectivity& connectivity,
                         const std::vector<TetMaterial>& materials)
    : kernels_(&kernels), rows_(mesh.vertex_count()) {
    const std::vector<double> eta = boundary_vertex_eta(mesh, connectivity, materials);
    std::vector<float> a(rows_, 0.0f), c(rows_, 0.0f);
    for (int32_t v : connectivity.boundary_vertices) {
        // exitant_radiance_factor's coefficients (Eq. 3), linear in phi and q.
        const double fdr = diffuse_fresnel_reflectance(eta[v]);
        const double big_a = (1.0 + fdr) / (1.0 - fdr);
        a[v] = static_cast<float>((1.0 + 1.0 / big_a) / (4.0 * std::numbers::pi));
        c[v] = static_cast<float>(4.0 / (1.0 + fdr) / (4.0 * std::numbers::pi));
    }
    phi_weight_ = GpuBuffer::from<float>(kernels.gl(), a);
    q_weight_ = GpuBuffer::from<float>(kernels.gl(), c);
    q_ = kernels.vector(rows_);
}

void GpuRadiance::set_light(const std::vector<std::array<double, 3>>& q) {
    if (q.size() != rows_)
        throw InvalidArgumentError("GPU radiance: " + std::to_string(q.size()) + " light values for " +
                                   std::to_string(rows_) + " vertices");
    std::vector<float> data(3 * rows_);
    for (size_t i = 0; i < rows_; ++i)
        for (int k = 0; k < 3; ++k) data[3 * i + k] = static_cast<float>(q[i][k]);
    q_.write(0, data.size() * sizeof(float), data.data());
}

void GpuRadiance::compute(const GpuBuffer& phi, GpuBuffer& e, const RadianceOptions& options) {
    kernels_->radiance(rows_, phi_weight_, q_weight_, phi, q_, e, options.clamp_negative);
}

}  // namespace waxwork
