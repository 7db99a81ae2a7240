#include "solver/radiance.h"

#include "base/error.h"
#include "solver/material.h"

#include <algorithm>
#include <numbers>
#include <string>

namespace waxwork {

ExitantRadianceWeights exitant_radiance_weights(double eta) {
    const double fdr = diffuse_fresnel_reflectance(eta);
    const double a = (1.0 + fdr) / (1.0 - fdr);
    const double outside = 1.0 / (4.0 * std::numbers::pi * eta * eta);  // Eq. 3's 1 / (4 pi), then 1 / eta^2
    return {(1.0 + 1.0 / a) * outside, 4.0 / (1.0 + fdr) * outside};
}

double exitant_radiance_factor(double phi, double q, double eta, bool clamp_negative) {
    const ExitantRadianceWeights w = exitant_radiance_weights(eta);
    const double e = w.phi_weight * phi - w.q_weight * q;
    return clamp_negative ? std::max(e, 0.0) : e;
}

double exitant_radiance(double phi, double q, double eta, double cos_view, bool clamp_negative) {
    // F_t of the exitant direction: by reciprocity, the transmittance for light arriving from outside
    // at the same angle.
    return fresnel_transmittance(cos_view, eta) * exitant_radiance_factor(phi, q, eta, clamp_negative);
}

std::vector<double> boundary_vertex_eta(const TetMesh& mesh, const TetConnectivity& conn,
                                        const std::vector<TetMaterial>& materials) {
    if (materials.size() != mesh.tet_count())
        throw InvalidArgumentError("boundary_vertex_eta: " + std::to_string(materials.size()) + " materials for " +
                                   std::to_string(mesh.tet_count()) + " tets");
    std::vector<double> weighted(mesh.vertex_count(), 0.0), weight(mesh.vertex_count(), 0.0);
    for (const BoundaryFace& f : conn.boundary_faces) {
        const auto& p = mesh.positions;
        const double area =
            (p[f.vertices[1]] - p[f.vertices[0]]).cross(p[f.vertices[2]] - p[f.vertices[0]]).norm();
        for (int32_t v : f.vertices) {
            weighted[v] += area * materials[f.tet].eta;
            weight[v] += area;
        }
    }
    std::vector<double> eta(mesh.vertex_count(), 1.0);
    for (size_t v = 0; v < eta.size(); ++v)
        if (weight[v] > 0) eta[v] = weighted[v] / weight[v];
    return eta;
}

std::vector<std::array<float, 3>> exitant_radiance_factors(const TetMesh& mesh, const TetConnectivity& conn,
                                                           const std::vector<TetMaterial>& materials,
                                                           const std::vector<std::array<double, 3>>& phi,
                                                           const std::vector<std::array<double, 3>>& q,
                                                           const RadianceOptions& options) {
    if (phi.size() != mesh.vertex_count() || q.size() != mesh.vertex_count())
        throw InvalidArgumentError("exitant_radiance_factors: phi and q need one value per vertex");
    const std::vector<double> eta = boundary_vertex_eta(mesh, conn, materials);
    std::vector<std::array<float, 3>> out(mesh.vertex_count(), {0.f, 0.f, 0.f});
    for (int32_t v : conn.boundary_vertices)
        for (int c = 0; c < 3; ++c)
            out[v][c] = static_cast<float>(exitant_radiance_factor(phi[v][c], q[v][c], eta[v], options.clamp_negative));
    return out;
}

std::vector<std::array<float, 3>> shading_radiance_factors(const BoundarySurface& surface,
                                                           const ShadingSurface& shading,
                                                           const std::vector<std::array<double, 3>>& phi,
                                                           const std::vector<std::array<double, 3>>& shading_q,
                                                           const RadianceOptions& options) {
    if (shading_q.size() != shading.size() || surface.eta.size() != surface.vertices.size())
        throw InvalidArgumentError("shading_radiance_factors: " + std::to_string(shading_q.size()) +
                                   " light values for " + std::to_string(shading.size()) + " shading vertices");
    std::vector<std::array<float, 3>> out(shading.size());
    for (size_t d = 0; d < shading.size(); ++d) {
        const int32_t s = shading.surface_vertex[d];
        const int32_t v = surface.vertices[s];
        if (static_cast<size_t>(v) >= phi.size())
            throw InvalidArgumentError("shading_radiance_factors: phi has " + std::to_string(phi.size()) +
                                       " values; surface vertex " + std::to_string(s) + " is volume vertex " +
                                       std::to_string(v));
        for (int c = 0; c < 3; ++c)
            out[d][c] = static_cast<float>(
                exitant_radiance_factor(phi[v][c], shading_q[d][c], surface.eta[s], options.clamp_negative));
    }
    return out;
}

}  // namespace waxwork
