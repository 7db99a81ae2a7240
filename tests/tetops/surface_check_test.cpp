#include "tetops/surface_check.h"
#include "tetops/test_surfaces.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace waxwork {
namespace {

using testing::combine;
using testing::make_cube_surface;

bool mentions(const std::vector<std::string>& lines, const std::string& text) {
    return std::any_of(lines.begin(), lines.end(), [&](const std::string& l) { return l.find(text) != std::string::npos; });
}

TEST(SurfaceCheck, CubeIsClean) {
    const SurfaceDefects d = find_surface_defects(make_cube_surface());
    EXPECT_TRUE(d.is_clean());
    EXPECT_TRUE(d.describe().empty());
    EXPECT_NEAR(d.signed_volume, 1.0, 1e-12);
    EXPECT_EQ(d.self_intersecting_pairs, 0u);  // neighbours sharing edges and vertices do not count
}

TEST(SurfaceCheck, OpenSurfaceReportsBoundaryEdges) {
    TriangleSurface s = make_cube_surface();
    s.triangles.pop_back();
    const SurfaceDefects d = find_surface_defects(s);
    EXPECT_EQ(d.boundary_edges, 3u);
    EXPECT_FALSE(d.is_clean());
    EXPECT_TRUE(mentions(d.describe(), "3 boundary edges"));
    // Safe repairs must not pretend to close it.
    repair_safe_defects(s);
    EXPECT_EQ(find_surface_defects(s).boundary_edges, 3u);
}

TEST(SurfaceCheck, EdgeSharedByFourTrianglesIsNonManifold) {
    // Two cubes sharing the edge x=1,y=1 (points merged by position).
    const TriangleSurface s = combine(make_cube_surface(), make_cube_surface({1, 1, 0}));
    const SurfaceDefects d = find_surface_defects(s);
    EXPECT_EQ(d.non_manifold_edges, 1u);
    EXPECT_TRUE(mentions(d.describe(), "1 non-manifold edge"));
}

TEST(SurfaceCheck, CubesTouchingAtACornerHaveAPinchedVertex) {
    TriangleSurface s = combine(make_cube_surface(), make_cube_surface({1, 1, 1}));
    const SurfaceDefects d = find_surface_defects(s);
    EXPECT_EQ(d.non_manifold_vertices, 1u);
    EXPECT_EQ(d.non_manifold_edges, 0u);
    EXPECT_EQ(d.boundary_edges, 0u);
    EXPECT_EQ(d.self_intersecting_pairs, 0u);  // touching at the shared corner only
    // The pinch is at (1,1,1): point 7 of the first cube (the second cube's copy is merged into it).
    EXPECT_EQ(d.first_non_manifold_vertex, 7);
    EXPECT_TRUE(mentions(d.describe(), "1 non-manifold vertex (pinched; vertex 7)"));
    // Not repairable safely.
    repair_safe_defects(s);
    EXPECT_EQ(find_surface_defects(s).non_manifold_vertices, 1u);
}

TEST(SurfaceCheck, OverlappingCubesSelfIntersect) {
    const TriangleSurface s = combine(make_cube_surface(), make_cube_surface({0.5, 0.25, 0.125}));
    const SurfaceDefects d = find_surface_defects(s);
    EXPECT_GT(d.self_intersecting_pairs, 0u);
    EXPECT_LT(d.first_self_intersecting_pair[0], d.first_self_intersecting_pair[1]);
    EXPECT_LT(d.first_self_intersecting_pair[0], 12);   // one face of each cube
    EXPECT_GE(d.first_self_intersecting_pair[1], 12);
    EXPECT_TRUE(mentions(d.describe(), "self-intersecting triangle pair"));
}

TEST(SurfaceCheck, CoplanarOverlapAcrossASharedEdgeCounts) {
    // A fold: triangle 1 lies on top of triangle 0, sharing edge 0-1 and on the same side of it.
    TriangleSurface s;
    s.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, 0.5, 0}};
    s.triangles = {{0, 1, 2}, {1, 0, 3}};
    EXPECT_EQ(find_surface_defects(s).self_intersecting_pairs, 1u);
    // Unfolded (other side of the edge) they only share the edge.
    s.points[3] = {0.2, -0.5, 0};
    EXPECT_EQ(find_surface_defects(s).self_intersecting_pairs, 0u);
}

TEST(SurfaceCheck, InwardCubeIsFlippedAndReported) {
    TriangleSurface s = make_cube_surface();
    for (auto& t : s.triangles) std::swap(t[1], t[2]);
    EXPECT_LT(find_surface_defects(s).signed_volume, 0.0);
    const auto repairs = repair_safe_defects(s);
    EXPECT_TRUE(mentions(repairs, "flipped all 12 triangles"));
    const SurfaceDefects d = find_surface_defects(s);
    EXPECT_TRUE(d.is_clean());
    EXPECT_NEAR(d.signed_volume, 1.0, 1e-12);
}

TEST(SurfaceCheck, OneFlippedTriangleIsReoriented) {
    TriangleSurface s = make_cube_surface();
    std::swap(s.triangles[5][1], s.triangles[5][2]);
    EXPECT_EQ(find_surface_defects(s).inconsistent_edges, 3u);
    const auto repairs = repair_safe_defects(s);
    EXPECT_TRUE(mentions(repairs, "reoriented 1 triangle"));
    EXPECT_TRUE(find_surface_defects(s).is_clean());
    EXPECT_EQ(s.triangles[5], (std::array<int32_t, 3>{1, 5, 4}));  // back as it was
}

TEST(SurfaceCheck, DuplicateAndUnreferencedVerticesAreRemoved) {
    // Every triangle gets its own three points (as in STL), plus two stray points.
    const TriangleSurface cube = make_cube_surface();
    TriangleSurface s;
    for (const auto& t : cube.triangles) {
        const auto base = static_cast<int32_t>(s.points.size());
        for (int32_t i : t) s.points.push_back(cube.points[i]);
        s.triangles.push_back({base, base + 1, base + 2});
    }
    s.points.push_back({5, 5, 5});
    s.points.push_back({6, 6, 6});
    const SurfaceDefects before = find_surface_defects(s);
    EXPECT_EQ(before.duplicate_points, 36u - 8u);
    EXPECT_EQ(before.unreferenced_points, 2u);
    EXPECT_TRUE(before.describe().empty());  // nothing that the safe repairs cannot fix
    EXPECT_FALSE(before.is_clean());

    const TriangleSurface input = s;
    SurfaceIndexMap origin;
    const auto repairs = repair_safe_defects(s, &origin);
    EXPECT_TRUE(mentions(repairs, "merged 28 duplicate vertices"));
    EXPECT_TRUE(mentions(repairs, "removed 2 unreferenced vertices"));
    EXPECT_EQ(s.points.size(), 8u);
    EXPECT_EQ(s.triangles.size(), 12u);
    EXPECT_TRUE(find_surface_defects(s).is_clean());
    ASSERT_EQ(origin.points.size(), 8u);
    ASSERT_EQ(origin.triangles.size(), 12u);
    // Each remaining point is the first copy of its position in the input; each triangle is itself.
    for (size_t i = 0; i < 8; ++i) {
        EXPECT_EQ(s.points[i], input.points[origin.points[i]]);
        EXPECT_LT(origin.points[i], 36);  // never one of the stray points
    }
    for (size_t t = 0; t < 12; ++t) {
        EXPECT_EQ(origin.triangles[t], static_cast<int32_t>(t));
        for (int k = 0; k < 3; ++k)
            EXPECT_EQ(s.points[s.triangles[t][k]], input.points[input.triangles[t][k]]);
    }
}

TEST(SurfaceCheck, DegenerateTrianglesAreDroppedOnlyWhenSafe) {
    TriangleSurface s = make_cube_surface();
    s.triangles.push_back({0, 0, 1});  // repeats a vertex: always safe to drop
    auto repairs = repair_safe_defects(s);
    EXPECT_TRUE(mentions(repairs, "dropped 1 triangle repeating a vertex"));
    EXPECT_TRUE(find_surface_defects(s).is_clean());

    // A tetrahedron whose bottom face is split at the midpoint M of edge AB, with the T-junction
    // closed by the collinear triangle (A, M, B): removing it would open the surface, so it stays.
    TriangleSurface t;
    t.points = {{0, 0, 0}, {2, 0, 0}, {1, 2, 0}, {1, 1, 2}, {1, 0, 0}};  // A B C D M
    t.triangles = {{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 2, 4}, {4, 2, 1}, {0, 4, 1}};
    EXPECT_EQ(find_surface_defects(t).boundary_edges, 0u);
    const SurfaceDefects d = find_surface_defects(t);
    EXPECT_EQ(d.zero_area_triangles, 1u);
    repairs = repair_safe_defects(t);
    EXPECT_FALSE(mentions(repairs, "zero-area"));
    EXPECT_TRUE(mentions(find_surface_defects(t).describe(), "1 zero-area triangle (first: face 5)"));
}

TEST(SurfaceCheck, NonFiniteCoordinatesAreReported) {
    TriangleSurface s = make_cube_surface();
    s.points[3].y() = std::numeric_limits<double>::quiet_NaN();
    const SurfaceDefects d = find_surface_defects(s);
    EXPECT_EQ(d.non_finite_points, 1u);
    EXPECT_EQ(d.first_non_finite_point, 3);
    EXPECT_TRUE(mentions(d.describe(), "non-finite coordinates (first: vertex 3)"));
}

TEST(SurfaceCheck, InvalidIndicesAreReportedNotFollowed) {
    TriangleSurface s = make_cube_surface();
    s.triangles[2][1] = 99;
    const SurfaceDefects d = find_surface_defects(s);
    EXPECT_EQ(d.invalid_indices, 1u);
    EXPECT_EQ(d.first_invalid_triangle, 2);
    repair_safe_defects(s);  // must not crash on the invalid triangle
    EXPECT_EQ(find_surface_defects(s).invalid_indices, 1u);
}

TEST(SurfaceCheck, HoleFillingIsOptInAndRevalidates) {
    TriangleSurface s = make_cube_surface();
    s.triangles.erase(s.triangles.begin(), s.triangles.begin() + 2);  // remove the bottom face
    EXPECT_TRUE(repair_hard_defects(s, {}).empty());                   // nothing asked, nothing done
    EXPECT_EQ(find_surface_defects(s).boundary_edges, 4u);

    const auto repairs = repair_hard_defects(s, {.fill_holes = true, .autorefine = false});
    EXPECT_TRUE(mentions(repairs, "filled 1 hole"));
    const SurfaceDefects d = find_surface_defects(s);
    EXPECT_TRUE(d.describe().empty()) << d.describe().front();
    EXPECT_GT(d.signed_volume, 0.5);
}

TEST(SurfaceCheck, HardRepairsRefuseNonManifoldInput) {
    TriangleSurface s = combine(make_cube_surface(), make_cube_surface({1, 1, 1}));
    const auto repairs = repair_hard_defects(s, {.fill_holes = true, .autorefine = true});
    EXPECT_TRUE(mentions(repairs, "not attempted"));
    EXPECT_EQ(find_surface_defects(s).non_manifold_vertices, 1u);
}

}  // namespace
}  // namespace waxwork
