#include "io/surface_reader.h"
#include "tetops/icosphere.h"
#include "tetops/size_field.h"

#include <Eigen/Core>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

namespace waxwork {
namespace {

// The torus of the assets: tube radius 0.25 around a circle of radius 1 in the xz-plane, so its
// hole (and the space around it) is outside, which a wrong parity or a nearest-triangle test gets wrong.
TEST(SurfaceDistance, ContainsExactlyThePointsInsideATorus) {
    const TriangleSurface torus = read_surface_file(std::filesystem::path(WAXWORK_ASSET_DIR) / "meshes" / "torus.obj");
    const SurfaceDistance distance(torus);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> coordinate(-1.4, 1.4);
    int inside = 0;
    int outside = 0;
    for (int i = 0; i < 4000; ++i) {
        const Eigen::Vector3d p(coordinate(random), coordinate(random) * 0.25, coordinate(random));
        const double tube_distance = std::hypot(std::hypot(p.x(), p.z()) - 1.0, p.y());
        // The 4,608 triangles stay within 0.01 of the ideal torus; closer points may go either way.
        if (std::abs(tube_distance - 0.25) < 0.02) continue;
        const bool expected = tube_distance < 0.25;
        ASSERT_EQ(distance.contains(p), expected) << p.transpose();
        (expected ? inside : outside) += 1;
    }
    EXPECT_GT(inside, 200);
    EXPECT_GT(outside, 200);
    EXPECT_FALSE(distance.contains(Eigen::Vector3d::Zero()));  // the centre of the hole
}

// Points on the axes of a sphere with vertices on the axes, where a ray cast along an axis would pass
// through a vertex and be counted once per triangle around it.
TEST(SurfaceDistance, ContainsPointsOnTheAxesOfASphere) {
    const TriangleSurface sphere = make_icosphere(3, 1.0);
    const SurfaceDistance distance(sphere);
    for (const double t : {-0.9, -0.5, 0.0, 0.3, 0.95}) {
        EXPECT_TRUE(distance.contains(Eigen::Vector3d(t, 0, 0)));
        EXPECT_TRUE(distance.contains(Eigen::Vector3d(0, t, 0)));
        EXPECT_TRUE(distance.contains(Eigen::Vector3d(0, 0, t)));
    }
    for (const double t : {-3.0, -1.05, 1.05, 2.0}) {
        EXPECT_FALSE(distance.contains(Eigen::Vector3d(t, 0, 0)));
        EXPECT_FALSE(distance.contains(Eigen::Vector3d(0, t, 0)));
        EXPECT_FALSE(distance.contains(Eigen::Vector3d(0, 0, t)));
    }
    EXPECT_NEAR(distance(Eigen::Vector3d::Zero()), 1.0, 0.02);
}

}  // namespace
}  // namespace waxwork
