// The generated reference geometry: Kuhn boxes and icospheres.
#include "base/error.h"
#include "tetops/box_mesh.h"
#include "tetops/icosphere.h"
#include "tetops/quality.h"

#include <gtest/gtest.h>

namespace waxwork {
namespace {

TEST(BoxMesh, AnisotropicBoxIsValidAndFillsItsVolume) {
    const std::array<int, 3> cells{4, 3, 1};
    const TetMesh mesh = make_box_mesh(cells, Eigen::Vector3d(-1, 0, 2), Eigen::Vector3d(3, 6, 2.5));
    validate(mesh);
    EXPECT_EQ(mesh.tet_count(), 4u * 3u * 1u * 6u);
    EXPECT_EQ(mesh.vertex_count(), 5u * 4u * 2u);
    EXPECT_NEAR(total_volume(mesh), 4.0 * 6.0 * 0.5, 1e-12);
    EXPECT_TRUE(mesh.positions[box_vertex_index(cells, 4, 3, 1)].isApprox(Eigen::Vector3d(3, 6, 2.5)));
    EXPECT_TRUE(mesh.positions[box_vertex_index(cells, 2, 0, 1)].isApprox(Eigen::Vector3d(1, 0, 2.5)));
}

TEST(BoxMesh, RefinedBoxKeepsTheCoarseVertices) {
    const TetMesh coarse = make_box_mesh({2, 2, 2}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
    const TetMesh fine = make_box_mesh({4, 4, 4}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
    for (int k = 0; k <= 2; ++k)
        for (int j = 0; j <= 2; ++j)
            for (int i = 0; i <= 2; ++i)
                EXPECT_EQ(coarse.positions[box_vertex_index({2, 2, 2}, i, j, k)],
                          fine.positions[box_vertex_index({4, 4, 4}, 2 * i, 2 * j, 2 * k)]);
}

TEST(BoxMesh, CubicCellsHaveGoodAngles) {
    const QualityReport quality = measure_quality(make_box_mesh({3, 3, 3}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()));
    EXPECT_NEAR(quality.min_dihedral_deg, 45.0, 1e-9);
    EXPECT_NEAR(quality.max_dihedral_deg, 90.0, 1e-9);
}

TEST(BoxMesh, RejectsBadArguments) {
    EXPECT_THROW(make_box_mesh({0, 1, 1}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()), InvalidArgumentError);
    EXPECT_THROW(make_box_mesh({1, 1, 1}, Eigen::Vector3d::Ones(), Eigen::Vector3d::Ones()), InvalidArgumentError);
    EXPECT_THROW(make_box_mesh({1, 1, 1}, Eigen::Vector3d::Zero(), Eigen::Vector3d(1, NAN, 1)), InvalidArgumentError);
    EXPECT_THROW(make_box_mesh({2000, 2000, 2000}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()),
                 InvalidArgumentError);
}

TEST(Icosphere, CountsRadiusAndOrientation) {
    const TriangleSurface sphere = make_icosphere(2, 3.0);
    EXPECT_EQ(sphere.triangles.size(), 20u * 16u);
    EXPECT_EQ(sphere.points.size(), 162u);  // V = F / 2 + 2 for a closed genus-0 triangle mesh
    for (const auto& p : sphere.points) EXPECT_NEAR(p.norm(), 3.0, 1e-12);
    for (const auto& t : sphere.triangles) {  // outward: the normal points away from the centre
        const Eigen::Vector3d& a = sphere.points[t[0]];
        const Eigen::Vector3d n = (sphere.points[t[1]] - a).cross(sphere.points[t[2]] - a);
        EXPECT_GT(n.dot(a), 0);
    }
    EXPECT_THROW(make_icosphere(-1, 1.0), InvalidArgumentError);
    EXPECT_THROW(make_icosphere(2, 0.0), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
