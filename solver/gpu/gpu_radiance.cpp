#include "solver/gpu/gpu_radiance.h"

#include "base/error.h"

#include <cmath>
#include <string>

namespace waxwork {
RadianceRows shading_radiance_rows(const BoundarySurface& surface, const ShadingSurface& shading) {
    RadianceRows rows;
    rows.vertex.resize(shading.size());
    rows.eta.resize(shading.size());
    for (size_t d = 0; d < shading.size(); ++d) {
        const int32_t s = shading.surface_vertex[d];
        if (s < 0 || static_cast<size_t>(s) >= surface.vertices.size() || surface.eta.size() != surface.vertices.size())
            throw InvalidArgumentError("GPU radiance: shading vertex " + std::to_string(d) +
                                       " copies no vertex of the surface");
        rows.vertex[d] = surface.vertices[s];
        rows.eta[d] = surface.eta[s];
    }
    return rows;
}

GpuRadiance::GpuRadiance(GpuKernels& kernels, const RadianceRows& rows, size_t phi_rows)
    : kernels_(&kernels), rows_(rows.vertex.size()), phi_rows_(phi_rows) {
    const std::vector<int32_t>& row_vertex = rows.vertex;
    const std::vector<double>& row_eta = rows.eta;
    if (row_eta.size() != rows_)
        throw InvalidArgumentError("GPU radiance: " + std::to_string(row_eta.size()) + " eta values for " +
                                   std::to_string(rows_) + " rows");
    std::vector<float> a(rows_), c(rows_);
    for (size_t r = 0; r < rows_; ++r) {
        if (row_vertex[r] < 0 || static_cast<size_t>(row_vertex[r]) >= phi_rows)
            throw InvalidArgumentError("GPU radiance: row " + std::to_string(r) + " reads vertex " +
                                       std::to_string(row_vertex[r]) + " of " + std::to_string(phi_rows));
        if (!(row_eta[r] >= 1.0) || !std::isfinite(row_eta[r]))
            throw InvalidArgumentError("GPU radiance: row " + std::to_string(r) + " has eta " +
                                       number_text(row_eta[r]));
        const ExitantRadianceWeights w = exitant_radiance_weights(row_eta[r]);
        a[r] = static_cast<float>(w.phi_weight);
        c[r] = static_cast<float>(w.q_weight);
    }
    row_vertex_ = GpuBuffer::from<int32_t>(kernels.gl(), row_vertex);
    phi_weight_ = GpuBuffer::from<float>(kernels.gl(), a);
    q_weight_ = GpuBuffer::from<float>(kernels.gl(), c);
    q_ = kernels.vector(rows_);
    row_phi_ = kernels.vector(rows_);
}

void GpuRadiance::set_light(const std::vector<std::array<double, 3>>& q) {
    if (q.size() != rows_)
        throw InvalidArgumentError("GPU radiance: " + std::to_string(q.size()) + " light values for " +
                                   std::to_string(rows_) + " rows");
    std::vector<float> data(3 * rows_);
    for (size_t i = 0; i < rows_; ++i)
        for (int k = 0; k < 3; ++k) data[3 * i + k] = static_cast<float>(q[i][k]);
    q_.write(0, data.size() * sizeof(float), data.data());
}

void GpuRadiance::compute(const GpuBuffer& phi, GpuBuffer& e, const RadianceOptions& options) {
    if (phi.bytes() < 3 * phi_rows_ * sizeof(float) || e.bytes() < 3 * rows_ * sizeof(float))
        throw InvalidArgumentError("GPU radiance: the phi or E buffer is too small");
    if (rows_ == 0) return;
    kernels_->gather(rows_, row_vertex_, phi, row_phi_);
    kernels_->radiance(rows_, phi_weight_, q_weight_, row_phi_, q_, e, options.clamp_negative);
}

}  // namespace waxwork
