// The exact local Delaunay check (tetops/delaunay_check.h) on a flipped pair and on cospherical grids.
#include "tetops/delaunay_check.h"

#include "base/error.h"
#include "tetops/connectivity.h"
#include "test_meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

namespace waxwork {
namespace {

// A flat bipyramid over the triangle (a, b, c) with apexes d above and e below: two tets sharing abc
// (not Delaunay: e lies inside the circumsphere of abcd) or three tets around the edge de (Delaunay).
TetMesh bipyramid(bool three_tets) {
    TetMesh mesh;
    const double s = std::sqrt(3.0) / 2;
    mesh.positions = {{1, 0, 0}, {-0.5, s, 0}, {-0.5, -s, 0}, {0, 0, 0.2}, {0, 0, -0.2}};
    if (three_tets)
        mesh.tets = {{3, 4, 0, 1}, {3, 4, 1, 2}, {3, 4, 2, 0}};
    else
        mesh.tets = {{0, 1, 2, 3}, {0, 1, 2, 4}};
    for (Tet& t : mesh.tets) {
        const auto& p = mesh.positions;
        if ((p[t[1]] - p[t[0]]).dot((p[t[2]] - p[t[0]]).cross(p[t[3]] - p[t[0]])) < 0) std::swap(t[2], t[3]);
    }
    mesh.piece_ids.assign(mesh.tets.size(), 0);
    mesh.original_ids.resize(mesh.tets.size());
    for (size_t t = 0; t < mesh.tets.size(); ++t) mesh.original_ids[t] = static_cast<int32_t>(t);
    mesh.piece_transforms.resize(1);
    return mesh;
}

TEST(DelaunayCheck, FindsTheFlippedPair) {
    const TetMesh two = bipyramid(false);
    const DelaunayCheck bad = check_local_delaunay(two, build_connectivity(two));
    EXPECT_EQ(bad.interior_faces, 1u);
    EXPECT_EQ(bad.non_delaunay_faces, 1u);
    EXPECT_FALSE(bad.locally_delaunay());
    const TetMesh three = bipyramid(true);
    const DelaunayCheck good = check_local_delaunay(three, build_connectivity(three));
    EXPECT_EQ(good.interior_faces, 3u);
    EXPECT_TRUE(good.locally_delaunay());
}

TEST(DelaunayCheck, CosphericalGridIsDelaunay) {
    // Every cube of the six-tet grid has its eight corners on one sphere: the in-sphere determinant is
    // exactly zero, which only an exact predicate reports as such.
    const TetMesh mesh = testing::make_box_mesh(3, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.3));
    const DelaunayCheck check = check_local_delaunay(mesh, build_connectivity(mesh));
    EXPECT_GT(check.interior_faces, 0u);
    EXPECT_TRUE(check.locally_delaunay());
}

TEST(DelaunayCheck, RejectsForeignConnectivity) {
    const TetMesh two = bipyramid(false), three = bipyramid(true);
    EXPECT_THROW(check_local_delaunay(two, build_connectivity(three)), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
