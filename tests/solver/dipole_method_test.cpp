// The dipole surface method (solver/methods/dipole.h) against closed forms, the exact ball and TransCut's
// own solve, and its documented failure cases: thin parts and concave regions.
#include "base/error.h"
#include "base/progress.h"
#include "solver/diffusion_matrix.h"
#include "solver/diffusion_solve.h"
#include "solver/material.h"
#include "solver/methods/dipole.h"
#include "solver/methods/dipole_profile.h"
#include "solver/reference/analytic_ball.h"
#include "solver_test_meshes.h"
#include "tetops/box_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

namespace waxwork {
namespace {

constexpr double kRadius = 10.0;  // mm
constexpr double kMua = 0.01, kMusp = 1.0, kEta = 1.3;
const TetMaterial kMaterial{{kMua, kMua, kMua}, {kMusp, kMusp, kMusp}, kEta};

struct Scene {
    TetMesh mesh;
    TetConnectivity conn;
    std::vector<TetMaterial> materials;
    std::vector<std::array<double, 3>> q;
    explicit Scene(TetMesh m, const TetMaterial& material = kMaterial) : mesh(std::move(m)) {
        conn = build_connectivity(mesh);
        materials.assign(mesh.tet_count(), material);
        q.assign(mesh.vertex_count(), {0, 0, 0});
    }
    MethodProblem problem(Progress* progress = nullptr) const { return {mesh, conn, materials, q, 1.0, progress}; }
};

// The uniformly lit Robin half-space: phi(z) = 4 q / ((1 - F_dr) (1 + 2 A D sigma)) exp(-sigma z).
double robin_half_space(double mua, double musp, double eta, double depth) {
    const double fdr = diffuse_fresnel_reflectance(eta), a = boundary_reflection_parameter(eta);
    const double d = diffusion_coefficient(mua, musp), sigma = effective_transport_coefficient(mua, musp);
    return 4 / ((1 - fdr) * (1 + 2 * a * d * sigma)) * std::exp(-sigma * depth);
}

// The dipole's own answer for the uniformly lit half-space: at the surface phi = 2 (A R_d + q) with the
// total reflectance R_d; below the real sources the fluence of a plane of dipoles,
// alpha' / (2 D sigma) exp(-sigma z) (exp(sigma z_r) - exp(-sigma z_v)).
double dipole_half_space_surface(double mua, double musp, double eta) {
    const DipoleProfile p(mua, musp, eta);
    return 2 * (boundary_reflection_parameter(eta) * p.total_reflectance() + 1);
}
double dipole_half_space_depth(double mua, double musp, double eta, double depth) {
    const DipoleProfile p(mua, musp, eta);
    const double s = p.sigma_tr();
    return p.reduced_albedo() / (2 * p.diffusion_coefficient() * s) * std::exp(-s * depth) *
           (std::exp(s * p.depth_real()) - std::exp(-s * p.height_virtual()));
}

TEST(DipoleProfile, IntegratesToTheClosedFormReflectance) {
    for (const TetMaterial& m : {kMaterial, material_preset("skimmilk"), material_preset("ketchup")}) {
        for (int c = 0; c < 3; ++c) {
            const DipoleProfile p(m.mua[c], m.musp[c], m.eta);
            EXPECT_NEAR(p.total_reflectance(), diffuse_reflectance(m)[c], 1e-12);
            // Midpoint rule on a log-spaced grid for the tail beyond r = 0.5 mm.
            double integral = 0;
            for (double r = 0.5; r < 400; r *= 1.0005) {
                const double r1 = r * 1.0005, mid = 0.5 * (r + r1);
                integral += p.reflectance(mid) * 2 * std::numbers::pi * mid * (r1 - r);
            }
            EXPECT_NEAR(integral, p.reflectance_tail(0.5) - p.reflectance_tail(400), 1e-5 * p.total_reflectance());
            const double rc = p.cutoff_radius(1e-3, 1e6);
            EXPECT_LE(p.reflectance_tail(rc), 1.0001e-3 * p.total_reflectance());
            EXPECT_LE(p.relative_fluence_tail(rc), 1.0001e-3);
            EXPECT_GT(std::max(p.reflectance_tail(0.99 * rc) / p.total_reflectance(), p.relative_fluence_tail(0.99 * rc)),
                      1e-3);
        }
    }
}

TEST(DipoleProfile, ConversionIsExactWithoutAbsorption) {
    // phi = 2 (A M + q) and the Robin half-space agree as mu_a -> 0 (all light comes back out); with
    // absorption they differ by the dipole's own approximation (printed; see the docs).
    EXPECT_NEAR(dipole_half_space_surface(1e-12, 1.0, kEta) / robin_half_space(1e-12, 1.0, kEta, 0), 1.0, 1e-5);
    for (double mua : {0.001, 0.01, 0.1}) {
        const double ratio = dipole_half_space_surface(mua, 1.0, kEta) / robin_half_space(mua, 1.0, kEta, 0);
        const double deep = dipole_half_space_depth(mua, 1.0, kEta, 10) / robin_half_space(mua, 1.0, kEta, 10);
        std::printf("mu_a %.3f: dipole / Robin half-space: surface %.4f, at depth %.4f\n", mua, ratio, deep);
        EXPECT_NEAR(ratio, 1.0, 0.1);
    }
}

// A box of `size` mm with cells of `cell` mm, lit uniformly (q = 1) on its top face z = size.z only.
Scene top_lit_box(const std::array<int, 3>& cells, const Eigen::Vector3d& size, const TetMaterial& material = kMaterial) {
    Scene scene(make_box_mesh(cells, Eigen::Vector3d::Zero(), size), material);
    for (int32_t v : scene.conn.boundary_vertices)
        if (scene.mesh.positions[v].z() > size.z() - 1e-9) scene.q[v] = {1, 1, 1};
    return scene;
}

TEST(DipoleMethod, MatchesTheHalfSpaceUnderUniformLight) {
    // 60 x 60 x 30 mm, 1 mm cells across the lit face: the centre is 30 mm (5 diffusion lengths) from
    // every other face, past the cut-off radius.
    const std::array<int, 3> cells{60, 60, 3};
    const Scene scene = top_lit_box(cells, {60, 60, 30});
    DipoleDiagnostics diagnostics;
    const MethodSolution s = solve_dipole(scene.problem(), {}, &diagnostics);
    const double surface = s.phi[box_vertex_index(cells, 30, 30, 3)][0];
    const double at_10 = s.phi[box_vertex_index(cells, 30, 30, 2)][0];
    const double at_20 = s.phi[box_vertex_index(cells, 30, 30, 1)][0];
    std::printf("half-space: cut-off %.1f mm, %zu pairs\n", diagnostics.cutoff_radius_mm, diagnostics.pairs);
    std::printf("surface phi %.4f: dipole closed form %.4f, Robin %.4f\n", surface,
                dipole_half_space_surface(kMua, kMusp, kEta), robin_half_space(kMua, kMusp, kEta, 0));
    std::printf("depth 10 mm %.4f: dipole %.4f, Robin %.4f; depth 20 mm %.4f: dipole %.4f, Robin %.4f\n", at_10,
                dipole_half_space_depth(kMua, kMusp, kEta, 10), robin_half_space(kMua, kMusp, kEta, 10), at_20,
                dipole_half_space_depth(kMua, kMusp, kEta, 20), robin_half_space(kMua, kMusp, kEta, 20));
    // The surface integral reproduces the dipole's closed form (the cut-off drops 0.1%)...
    EXPECT_NEAR(surface / dipole_half_space_surface(kMua, kMusp, kEta), 1.0, 0.01);
    EXPECT_NEAR(at_10 / dipole_half_space_depth(kMua, kMusp, kEta, 10), 1.0, 0.01);
    EXPECT_NEAR(at_20 / dipole_half_space_depth(kMua, kMusp, kEta, 20), 1.0, 0.01);
    // ...which is the Robin half-space up to the dipole's approximation.
    EXPECT_NEAR(surface / robin_half_space(kMua, kMusp, kEta, 0), 1.0, 0.05);
    EXPECT_NEAR(at_20 / robin_half_space(kMua, kMusp, kEta, 20), 1.0, 0.15);
    EXPECT_TRUE(s.warnings.empty());
    EXPECT_EQ(diagnostics.through_air_share, 0.0);
}

}  // namespace
}  // namespace waxwork
