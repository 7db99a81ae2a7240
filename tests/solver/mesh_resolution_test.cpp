// The default mesh size rule (solver/mesh_resolution.h).
#include "base/error.h"
#include "solver/material.h"
#include "solver/mesh_resolution.h"
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

}  // namespace
}  // namespace waxwork
