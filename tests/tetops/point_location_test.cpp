#include "tetops/point_location.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>

namespace waxwork {
namespace {

// Points inside, on the boundary and outside a unit cube, and far away along its diagonal, where the
// barycentric sub-volumes round to anything (a light at 1e8 must not count as inside).
TEST(PointInsideVolume, FarPointsAreOutsideWhateverTheRounding) {
    const TetMesh cube = testing::make_cube_mesh(3);
    EXPECT_TRUE(point_inside_volume(cube, Eigen::Vector3d(0.5, 0.5, 0.5)));
    EXPECT_TRUE(point_inside_volume(cube, Eigen::Vector3d(0.2, 0.9, 0.4)));
    EXPECT_TRUE(point_inside_volume(cube, Eigen::Vector3d(1.0, 0.5, 0.5)));  // on a face
    EXPECT_FALSE(point_inside_volume(cube, Eigen::Vector3d(1.01, 0.5, 0.5)));
    for (const double far : {3e7, 1e8, 1e15, 1e100})
        for (const Eigen::Vector3d& direction : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, -1, 1),
                                                Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1.1, 0.9)})
            EXPECT_FALSE(point_inside_volume(cube, far * direction)) << far << " " << direction.transpose();
}

}  // namespace
}  // namespace waxwork
