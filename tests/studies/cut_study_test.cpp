// Both cut modes on one mesh (bench/studies/cut_study.h): the exact cut's cross-section lies on the plane,
// remove + relax approaches it.
#include "bench/studies/cut_study.h"

#include "tetops/test_meshes.h"

#include <gtest/gtest.h>

namespace waxwork {
namespace {

TEST(CutStudy, ExactCrossSectionLiesOnThePlaneRelaxedOneNearIt) {
    const TetMesh cube = testing::make_cube_mesh(8);
    const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 0.3, 0.2).normalized();
    const std::vector<CutModeResult> results = compare_cut_modes(cube, PlaneCut(normal, normal.dot(Eigen::Vector3d(0.53, 0.5, 0.5))));
    ASSERT_EQ(results.size(), 2u);
    const CutModeResult& relaxed = results[0];
    const CutModeResult& exact = results[1];
    EXPECT_EQ(relaxed.mode, "remove+relax");
    EXPECT_EQ(exact.mode, "exact");
    ASSERT_FALSE(exact.distances_per_edge.empty());
    ASSERT_FALSE(relaxed.distances_per_edge.empty());
    EXPECT_LT(exact.max_distance_per_edge(), 1e-12);
    EXPECT_GT(relaxed.max_distance_per_edge(), exact.max_distance_per_edge());
    EXPECT_LT(relaxed.max_distance_per_edge(), 1.0);  // within one edge length of the plane
    EXPECT_TRUE(std::is_sorted(exact.distances_per_edge.begin(), exact.distances_per_edge.end()));
    for (const CutModeResult& r : results) {
        EXPECT_GT(r.worst_dihedral_deg(), 0.0) << r.mode;
        EXPECT_EQ(r.min_dihedral_deg.size(), r.tets_after) << r.mode;
        EXPECT_LE(r.tets_below(5.0), r.tets_after) << r.mode;
        EXPECT_LT(r.tets_after, cube.tet_count() + cube.tet_count()) << r.mode;
    }
    EXPECT_EQ(to_json(results)[1]["mode"], "exact");
    // The cube's tets are far above 0.5 degrees: the exact cut's worst angle is under 0.5 exactly when
    // it reports tets under the guard.
    EXPECT_EQ(to_json(results)[1]["tets_under_guard"], exact.tets_under_guard);
    EXPECT_EQ(exact.tets_under_guard == 0, exact.worst_dihedral_deg() >= 0.5);
    EXPECT_FALSE(to_json(results)[0].contains("tets_under_guard"));
}

}  // namespace
}  // namespace waxwork
