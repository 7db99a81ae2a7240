// The default mesh size rule (solver/mesh_resolution.h).
#include "base/error.h"
#include "solver/material.h"
#include "solver/mesh_resolution.h"
#include "tetops/box_mesh.h"
#include "tetops/icosphere.h"

#include <gtest/gtest.h>

#include <cmath>

namespace waxwork {
namespace {

TEST(MeshResolution, FollowsTheDiffusionLengthWithinTheDiagonalBounds) {
    const TriangleSurface ball = make_icosphere(2, 50.0);
    Eigen::Vector3d lo = ball.points.front(), hi = lo;
    for (const Eigen::Vector3d& p : ball.points) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    const double diagonal = (hi - lo).norm();  // about 170 mm: D / 150 < l_d / 2 < D / 25
    const TetMaterial marble = material_preset("marble");
    // At 1 mm per unit marble's blue diffusion length (3.95 mm) gives h_s = l_d / 2, inside the bounds.
    const MeshSizing sizing = default_mesh_sizing(ball, marble, 1.0);
    EXPECT_NEAR(sizing.surface_edge, 0.5 * smallest_diffusion_length_mm(marble), 1e-12);
    EXPECT_NEAR(sizing.max_edge, diagonal / 8, 1e-12);
    EXPECT_EQ(sizing.grading, 0.5);
    // At 1 um per unit the diffusion length is huge in model units: capped at D / 25.
    EXPECT_NEAR(default_mesh_sizing(ball, marble, 1e-3).surface_edge, diagonal / 25, 1e-12);
}

TEST(MeshResolution, SizeFactorScalesBothEdgeLengths) {
    const TriangleSurface ball = make_icosphere(2, 10.0);
    const TetMaterial marble = material_preset("marble");
    const MeshSizing base = default_mesh_sizing(ball, marble, 1.0);
    const MeshSizing finer = default_mesh_sizing(ball, marble, 1.0, {.size_factor = 0.5});
    EXPECT_DOUBLE_EQ(finer.surface_edge, 0.5 * base.surface_edge);
    EXPECT_DOUBLE_EQ(finer.max_edge, 0.5 * base.max_edge);
    EXPECT_EQ(finer.grading, base.grading);
    EXPECT_THROW(default_mesh_sizing(ball, marble, 1.0, {.size_factor = 0.0}), InvalidArgumentError);
    EXPECT_THROW(default_mesh_sizing(ball, marble, 1.0, {.size_factor = NAN}), InvalidArgumentError);
}

// The warning follows the light term of the rule (l_d / 2, within kResolutionTolerance), not its
// clamps: a mesh the D/150 cost floor allows is still flagged when its edges exceed the diffusion
// length, and a mesh the D/25 shape cap would refine is not.
TEST(MeshResolution, WarnsWhenSurfaceEdgesExceedTheDiffusionLength) {
    const TetMesh cube = make_box_mesh({4, 4, 4}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());  // edges 0.25
    const TetMaterial skin = material_preset("skin1");
    const double l_d = smallest_diffusion_length_mm(skin);
    // Surface edges: the cube's face edges (0.25) and face diagonals, so their mean is above 0.25.
    const ResolutionFit coarse = fit_to_resolution_rule(cube, {skin}, 100.0);
    EXPECT_GT(coarse.surface_edge_mm, 25.0);
    EXPECT_DOUBLE_EQ(coarse.diffusion_length_mm, l_d);
    EXPECT_NE(under_resolution_warning(coarse).find("under-resolves the light"), std::string::npos);
    // Scaled so the surface edge is just under and just over 1.5 x l_d / 2.
    const double at_limit = kResolutionTolerance * 0.5 * l_d / (coarse.surface_edge_mm / 100.0);
    EXPECT_EQ(under_resolution_warning(fit_to_resolution_rule(cube, {skin}, 0.99 * at_limit)), "");
    EXPECT_NE(under_resolution_warning(fit_to_resolution_rule(cube, {skin}, 1.01 * at_limit)), "");
    // The hardest of several materials decides.
    std::vector<TetMaterial> mixed(cube.tet_count(), material_preset("marble"));
    EXPECT_EQ(under_resolution_warning(fit_to_resolution_rule(cube, mixed, 1.01 * at_limit)), "");
    mixed[7] = skin;
    const ResolutionFit fit = fit_to_resolution_rule(cube, mixed, 1.01 * at_limit);
    EXPECT_DOUBLE_EQ(fit.diffusion_length_mm, l_d);
    EXPECT_NE(under_resolution_warning(fit).find("its most absorbing material"), std::string::npos);
    EXPECT_THROW(fit_to_resolution_rule(TetMesh{}, {skin}, 1.0), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
