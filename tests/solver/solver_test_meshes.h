// Meshes and analytic solutions shared by the solver tests.
#pragma once

#include "solver/material.h"
#include "tetops/connectivity.h"
#include "tetops/quality.h"
#include "tetops/tet_mesh.h"
#include "tetops/test_meshes.h"
#include "tetops/tetrahedralize.h"
#include "tetops/triangle_surface.h"

#include <cmath>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

namespace waxwork::test {

// n x n x n cubes of side h, each split into the six Kuhn tets (a conforming, all-good mesh:
// dihedral angles 45-90 degrees).
inline TetMesh make_cube_mesh(int n, double h = 1.0) {
    return testing::make_box_mesh(n, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(n * h));
}

// Moves `count` interior vertices of a cube mesh towards a face of their (convex) star, so that one tet
// per moved vertex becomes a cap-shaped sliver of relative height `flatness`; all tets stay positive.
inline std::vector<int32_t> make_slivers(TetMesh& mesh, const TetConnectivity& conn, int count, double flatness) {
    std::vector<int32_t> slivers;
    std::vector<uint8_t> touched(mesh.vertex_count(), 0);
    for (size_t v = 0; v < mesh.vertex_count() && static_cast<int>(slivers.size()) < count; v += 37) {
        if (conn.is_boundary_vertex[v] || touched[v]) continue;
        const int32_t t = conn.vertex_tets.row(v)[0];
        const Tet& tet = mesh.tets[t];
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (int32_t w : tet)
            if (w != static_cast<int32_t>(v)) centroid += mesh.positions[w] / 3.0;
        mesh.positions[v] = centroid + flatness * (mesh.positions[v] - centroid);
        for (int32_t w : conn.vertex_vertices.row(v)) touched[w] = 1;
        touched[v] = 1;
        slivers.push_back(t);
    }
    return slivers;
}

// Icosahedron subdivided `level` times, projected to the sphere of radius r, outward oriented.
inline TriangleSurface make_icosphere(int level, double r) {
    const double g = (1.0 + std::sqrt(5.0)) / 2.0;
    TriangleSurface s;
    s.points = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    s.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                   {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                   {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int l = 0; l < level; ++l) {
        std::map<std::pair<int32_t, int32_t>, int32_t> midpoints;
        auto mid = [&](int32_t a, int32_t b) {
            const auto key = std::minmax(a, b);
            auto it = midpoints.find(key);
            if (it != midpoints.end()) return it->second;
            s.points.push_back(0.5 * (s.points[a] + s.points[b]));
            const auto id = static_cast<int32_t>(s.points.size() - 1);
            midpoints.emplace(key, id);
            return id;
        };
        std::vector<std::array<int32_t, 3>> next;
        for (const auto& t : s.triangles) {
            const int32_t ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
            next.push_back({t[0], ab, ca});
            next.push_back({t[1], bc, ab});
            next.push_back({t[2], ca, bc});
            next.push_back({ab, bc, ca});
        }
        s.triangles = std::move(next);
    }
    for (auto& p : s.points) p = p.normalized() * r;
    return s;
}

inline TetMesh make_ball_mesh(int surface_level, size_t target_tets, double r = 10.0) {
    MeshingOptions options;
    options.sizing.target_tets = target_tets;
    return tetrahedralize(make_icosphere(surface_level, r), options).mesh;
}

// Modified spherical Bessel function of the first kind i_l(x) and its derivative.
inline double sph_bessel_i(int l, double x) {
    if (x < 1e-8) {
        double dfact = 1;
        for (int k = 1; k <= 2 * l + 1; k += 2) dfact *= k;
        return std::pow(x, l) / dfact;
    }
    return std::sqrt(std::numbers::pi / (2 * x)) * std::cyl_bessel_i(l + 0.5, x);
}
inline double sph_bessel_i_derivative(int l, double x) {
    if (l == 0) return sph_bessel_i(1, x);
    return sph_bessel_i(l - 1, x) - (l + 1) / x * sph_bessel_i(l, x);
}
inline std::vector<double> legendre(int lmax, double mu) {
    std::vector<double> p(lmax + 1);
    p[0] = 1;
    if (lmax > 0) p[1] = mu;
    for (int l = 2; l <= lmax; ++l) p[l] = ((2 * l - 1) * mu * p[l - 1] - (l - 1) * p[l - 2]) / l;
    return p;
}

// Exact fluence in a homogeneous ball (seeds README): phi(r, theta) = sum_l a_l i_l(sigma r) P_l(cos theta),
// a_l = (4 / (1 - F_dr)) q_l / (i_l(sigma R) + 2 A kappa sigma i_l'(sigma R)), for q(theta) = sum q_l P_l.
struct BallSolution {
    double radius, kappa, sigma;
    std::vector<double> a;
    BallSolution(double r, double mua, double musp, double eta, const std::vector<double>& q_l) : radius(r) {
        kappa = diffusion_coefficient(mua, musp);
        sigma = std::sqrt(mua / kappa);
        const double fdr = diffuse_fresnel_reflectance(eta), big_a = boundary_reflection_parameter(eta);
        for (size_t l = 0; l < q_l.size(); ++l) {
            const int li = static_cast<int>(l);
            a.push_back(4.0 / (1.0 - fdr) * q_l[l] /
                        (sph_bessel_i(li, sigma * r) + 2 * big_a * kappa * sigma * sph_bessel_i_derivative(li, sigma * r)));
        }
    }
    double operator()(const Eigen::Vector3d& p) const {
        const double r = p.norm();
        const double mu = r > 0 ? p.z() / r : 1.0;
        const auto pl = legendre(static_cast<int>(a.size()) - 1, mu);
        double phi = 0;
        for (size_t l = 0; l < a.size(); ++l) phi += a[l] * sph_bessel_i(static_cast<int>(l), sigma * r) * pl[l];
        return phi;
    }
};

// Legendre coefficients of q(mu) = max(mu, 0) F_t(mu, eta) (a directional light along -z), by
// composite Simpson on [0, 1] where q is smooth.
inline std::vector<double> directional_light_coefficients(int lmax, double eta) {
    const int n = 4000;
    std::vector<double> q(lmax + 1, 0.0);
    for (int k = 0; k <= n; ++k) {
        const double mu = static_cast<double>(k) / n;
        const double w = (k == 0 || k == n ? 1.0 : (k % 2 ? 4.0 : 2.0)) / (3.0 * n);
        const auto p = legendre(lmax, mu);
        const double value = mu * fresnel_transmittance(mu, eta);
        for (int l = 0; l <= lmax; ++l) q[l] += (2 * l + 1) / 2.0 * w * value * p[l];
    }
    return q;
}

inline double directional_light(const Eigen::Vector3d& p, double eta) {
    const double mu = p.z() / p.norm();
    return std::max(mu, 0.0) * fresnel_transmittance(mu, eta);
}

}  // namespace waxwork::test
