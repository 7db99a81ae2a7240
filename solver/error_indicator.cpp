#include "solver/error_indicator.h"

#include "base/error.h"
#include "solver/material.h"

#include <Eigen/Dense>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace waxwork {

std::vector<double> gradient_jump_indicator(const TetMesh& mesh, const TetConnectivity& connectivity,
                                            const std::vector<std::array<double, 3>>& phi,
                                            const std::vector<TetMaterial>& materials, double mm_per_unit) {
    const size_t tet_count = mesh.tet_count();
    if (phi.size() != mesh.vertex_count())
        throw InvalidArgumentError("error indicator: " + std::to_string(phi.size()) + " phi values for " +
                                   std::to_string(mesh.vertex_count()) + " vertices");
    if (materials.size() != tet_count)
        throw InvalidArgumentError("error indicator: " + std::to_string(materials.size()) + " materials for " +
                                   std::to_string(tet_count) + " tets");
    if (connectivity.tet_neighbors.size() != tet_count)
        throw InvalidArgumentError("error indicator: the connectivity was built for another mesh");
    if (!(mm_per_unit > 0) || !std::isfinite(mm_per_unit))
        throw InvalidArgumentError("error indicator: mm per unit must be a positive number");
    std::array<double, 3> scale{};
    for (size_t v = 0; v < phi.size(); ++v)
        for (int c = 0; c < 3; ++c) {
            if (!std::isfinite(phi[v][c]))
                throw InvalidArgumentError("error indicator: phi is not finite at vertex " + std::to_string(v));
            scale[c] = std::max(scale[c], std::abs(phi[v][c]));
        }
    for (double& s : scale) s = s > 0 ? 1.0 / s : 0.0;

    // Per tet and channel the flux kappa grad(phi), constant on a linear tet, in units of the channel's
    // largest phi per mm. grad(phi) solves E^T g = (phi_k - phi_0)_k with E's columns the edges from
    // vertex 0.
    std::vector<std::array<Eigen::Vector3d, 3>> flux(tet_count);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tet_count, 1024), [&](const auto& range) {
        for (size_t t = range.begin(); t != range.end(); ++t) {
            const Tet& tet = mesh.tets[t];
            Eigen::Matrix3d edges;
            for (int k = 0; k < 3; ++k)
                edges.col(k) = (mesh.positions[tet[k + 1]] - mesh.positions[tet[0]]) * mm_per_unit;
            const Eigen::PartialPivLU<Eigen::Matrix3d> lu(edges.transpose());
            for (int c = 0; c < 3; ++c) {
                Eigen::Vector3d differences;
                for (int k = 0; k < 3; ++k) differences[k] = (phi[tet[k + 1]][c] - phi[tet[0]][c]) * scale[c];
                const double kappa = diffusion_coefficient(materials[t].mua[c], materials[t].musp[c]);
                flux[t][c] = kappa * lu.solve(differences);
            }
        }
    });

    std::vector<double> eta(tet_count, 0.0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tet_count, 1024), [&](const auto& range) {
        for (size_t t = range.begin(); t != range.end(); ++t) {
            const Tet& tet = mesh.tets[t];
            double sum = 0;
            for (int f = 0; f < 4; ++f) {
                const int32_t u = connectivity.tet_neighbors[t][f];
                if (u < 0) continue;
                const Eigen::Vector3d a = mesh.positions[tet[kTetFaces[f][0]]] * mm_per_unit;
                const Eigen::Vector3d b = mesh.positions[tet[kTetFaces[f][1]]] * mm_per_unit;
                const Eigen::Vector3d d = mesh.positions[tet[kTetFaces[f][2]]] * mm_per_unit;
                const Eigen::Vector3d area_normal = 0.5 * (b - a).cross(d - a);
                const double area = area_normal.norm();
                if (!(area > 0)) continue;
                const Eigen::Vector3d n = area_normal / area;
                const double h = std::sqrt(std::max({(b - a).squaredNorm(), (d - a).squaredNorm(), (d - b).squaredNorm()}));
                for (int c = 0; c < 3; ++c) {
                    const double jump = (flux[t][c] - flux[u][c]).dot(n);
                    sum += h / 24 * area * jump * jump;
                }
            }
            eta[t] = std::sqrt(sum);
        }
    });
    return eta;
}

}  // namespace waxwork
