#include "solver/material.h"
#include "solver/radiance.h"
#include "solver_test_meshes.h"

#include <gtest/gtest.h>

#include <numbers>

namespace waxwork {
namespace {

TEST(Radiance, FactorFollowsEq3WithTheBoundarysOneOverEtaSquared) {
    const double eta = 1.3, fdr = diffuse_fresnel_reflectance(eta), a = boundary_reflection_parameter(eta);
    const double phi = 5.0, q = 0.7;
    const double expected = ((1 + 1 / a) * phi - 4 * q / (1 + fdr)) / (4 * std::numbers::pi) / (eta * eta);
    EXPECT_NEAR(exitant_radiance_factor(phi, q, eta), expected, 1e-15);
    EXPECT_NEAR(exitant_radiance(phi, q, eta, 0.6), fresnel_transmittance(0.6, eta) * expected, 1e-15);
    EXPECT_EQ(exitant_radiance(phi, q, eta, 0.0), 0.0);  // grazing: no transmission
}

TEST(Radiance, NegativeValuesAreClampedOnlyWhenAsked) {
    EXPECT_EQ(exitant_radiance_factor(0.0, 1.0, 1.3), 0.0);
    EXPECT_LT(exitant_radiance_factor(0.0, 1.0, 1.3, false), 0.0);
}

TEST(Radiance, PerVertexFactorsOnTheBoundaryOnly) {
    TetMesh mesh = test::make_cube_mesh(3);
    const auto conn = build_connectivity(mesh);
    std::vector<TetMaterial> mats(mesh.tet_count(), material_preset("skin1"));
    std::vector<std::array<double, 3>> phi(mesh.vertex_count(), {3, 2, 1}), q(mesh.vertex_count(), {0.1, 0.1, 0.1});
    const auto e = exitant_radiance_factors(mesh, conn, mats, phi, q);
    for (size_t v = 0; v < mesh.vertex_count(); ++v)
        for (int c = 0; c < 3; ++c) {
            if (conn.is_boundary_vertex[v])
                EXPECT_NEAR(e[v][c], exitant_radiance_factor(phi[v][c], q[v][c], 1.3), 1e-6);
            else
                EXPECT_EQ(e[v][c], 0.f);
        }
    const auto eta = boundary_vertex_eta(mesh, conn, mats);
    EXPECT_DOUBLE_EQ(eta[conn.boundary_vertices[0]], 1.3);
}

}  // namespace
}  // namespace waxwork
