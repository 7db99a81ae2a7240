// Conforming local refinement by longest-edge bisection (tetops/refine.h): conformity, the boundary as a
// point set, volume, orientation, exact per-tet data, the angle guard, the budget, determinism and bad input.
#include "tetops/refine.h"

#include "base/error.h"
#include "base/progress.h"
#include "tetops/connectivity.h"
#include "tetops/fracture.h"
#include "tetops/icosphere.h"
#include "tetops/quality.h"
#include "tetops/sliver_maker.h"
#include "tetops/tetrahedralize.h"
#include "mesh_checks.h"
#include "test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>

namespace waxwork {
namespace {

// A cube mesh whose every tet has its own material, so that a child given another tet's is caught.
TetMesh painted_cube(int n) {
    TetMesh mesh = testing::make_cube_mesh(n);
    mesh.materials.resize(mesh.tet_count());
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        TetMaterial& m = mesh.materials[t];
        m.mua = {0.001 * static_cast<double>(t + 1), 0.002, 0.003};
        m.musp = {1.0, 1.0 + 1e-3 * static_cast<double>(t), 2.0};
        m.eta = 1.3;
    }
    return mesh;
}

Eigen::Vector3d centroid(const TetMesh& mesh, size_t t) {
    const Tet& tet = mesh.tets[t];
    return 0.25 * (mesh.positions[tet[0]] + mesh.positions[tet[1]] + mesh.positions[tet[2]] + mesh.positions[tet[3]]);
}

// The tets whose centroid lies within `radius` of `center`.
std::vector<int32_t> tets_near(const TetMesh& mesh, const Eigen::Vector3d& center, double radius) {
    std::vector<int32_t> marks;
    for (size_t t = 0; t < mesh.tet_count(); ++t)
        if ((centroid(mesh, t) - center).norm() < radius) marks.push_back(static_cast<int32_t>(t));
    return marks;
}

// Everything the header promises of a refinement of `before` into `after`.
void expect_refinement_of(const TetMesh& before, const TetMesh& after, const RefineResult& result) {
    ASSERT_EQ(result.new_to_old_tet.size(), after.tet_count());
    ASSERT_EQ(result.vertex_origins.size(), after.vertex_count());
    EXPECT_EQ(after.tet_count() - before.tet_count(), result.bisections);
    // Valid (positive orientation, no face in three tets, no overlap) and closed.
    const TetConnectivity c = testing::expect_valid_conforming(after);

    // Nested: old vertices unchanged, new ones at the midpoints of the edges they were made on, and no
    // tet has such an edge any more (no hanging vertex).
    for (size_t v = 0; v < before.vertex_count(); ++v) {
        ASSERT_EQ(after.positions[v], before.positions[v]) << v;
        ASSERT_TRUE(result.vertex_origins[v].is_vertex());
    }
    std::set<std::pair<int32_t, int32_t>> edges;
    for (const auto& e : c.edges) edges.insert({e[0], e[1]});
    for (size_t v = before.vertex_count(); v < after.vertex_count(); ++v) {
        const VertexOrigin& o = result.vertex_origins[v];
        ASSERT_FALSE(o.is_vertex());
        ASSERT_LT(o.a, static_cast<int32_t>(v));
        ASSERT_LT(o.b, static_cast<int32_t>(v));
        EXPECT_EQ(o.t, 0.5);
        EXPECT_EQ(after.positions[v], 0.5 * (after.positions[o.a] + after.positions[o.b]));
        EXPECT_FALSE(edges.count({std::min(o.a, o.b), std::max(o.a, o.b)})) << "hanging vertex " << v;
    }

    // Exact per-tet data, and the children of each tet fill it.
    std::vector<double> children(before.tet_count(), 0.0);
    for (size_t t = 0; t < after.tet_count(); ++t) {
        const int32_t parent = result.new_to_old_tet[t];
        ASSERT_GE(parent, 0);
        ASSERT_LT(static_cast<size_t>(parent), before.tet_count());
        if (before.has_materials()) {
            ASSERT_EQ(after.materials[t], before.materials[parent]) << t;
        }
        ASSERT_EQ(after.original_ids[t], before.original_ids[parent]);
        ASSERT_EQ(after.piece_ids[t], before.piece_ids[parent]);
        children[parent] += signed_volume(after, t);
    }
    for (size_t t = 0; t < before.tet_count(); ++t)
        EXPECT_NEAR(children[t], signed_volume(before, t), 1e-12 * signed_volume(before, t)) << t;
    EXPECT_NEAR(total_volume(after), total_volume(before), 1e-12 * total_volume(before));

    // The boundary as a point set: every boundary face after lies in a boundary face of its tet's
    // parent, and the boundary areas agree, so the two surfaces cover the same points.
    const TetConnectivity before_c = build_connectivity(before);
    std::vector<std::vector<int>> parent_faces(before.tet_count());
    for (const BoundaryFace& f : before_c.boundary_faces) parent_faces[f.tet].push_back(f.local_face);
    for (const BoundaryFace& f : c.boundary_faces) {
        const int32_t parent = result.new_to_old_tet[f.tet];
        bool inside = false;
        for (const int local : parent_faces[parent]) {
            const Tet& p = before.tets[parent];
            const Eigen::Vector3d& a = before.positions[p[kTetFaces[local][0]]];
            const Eigen::Vector3d n = (before.positions[p[kTetFaces[local][1]]] - a)
                                          .cross(before.positions[p[kTetFaces[local][2]]] - a)
                                          .normalized();
            bool in_plane = true;
            for (const int32_t v : f.vertices) in_plane = in_plane && std::abs((after.positions[v] - a).dot(n)) < 1e-12;
            inside = inside || in_plane;
        }
        EXPECT_TRUE(inside) << "boundary face of tet " << f.tet << " is not on its parent's boundary";
    }
    EXPECT_NEAR(testing::boundary_area(after, c), testing::boundary_area(before, before_c), 1e-12);

    // Quality: nothing under min(0.5 degrees, the parent's angle).
    EXPECT_EQ(testing::tets_under_parent_guard(after, before, [&](size_t t) { return result.new_to_old_tet[t]; }), 0u);
    EXPECT_EQ(result.min_dihedral_deg, mesh_min_dihedral_deg(after));
}

TEST(Refine, BisectsMarkedTetsConformingAndCarriesEveryTetsDataExactly) {
    const TetMesh before = painted_cube(4);
    TetMesh mesh = before;
    const std::vector<int32_t> marks = tets_near(mesh, Eigen::Vector3d(0.1, 0.2, 0.15), 0.3);
    ASSERT_FALSE(marks.empty());
    const RefineResult result = refine_tets(mesh, marks);
    EXPECT_EQ(result.marks, marks.size());
    EXPECT_EQ(result.marks_refined, marks.size());
    EXPECT_EQ(result.marks_skipped_guard, 0u);
    EXPECT_EQ(result.marks_skipped_budget, 0u);
    // Each mark adds at least one tet; the propagation may add more, but stays local.
    EXPECT_GE(result.bisections, marks.size());
    EXPECT_LT(mesh.tet_count(), 2 * before.tet_count());
    expect_refinement_of(before, mesh, result);
    // Every marked tet was split.
    for (const int32_t t : marks)
        EXPECT_EQ(std::count(result.new_to_old_tet.begin(), result.new_to_old_tet.end(), t) >= 2, true) << t;
}

TEST(Refine, KeepsTheMinimumAngleBoundedOverRepeatedLocalRefinement) {
    // Ten rounds towards one point of a cube, and of an unstructured TetGen ball: the children's shapes
    // stay in a bounded set, so the smallest angle levels off instead of halving every round.
    MeshingOptions meshing;
    meshing.sizing.target_tets = 600;
    for (const bool ball : {false, true}) {
        const TetMesh start = ball ? tetrahedralize(make_icosphere(1, 1.0), meshing).mesh : testing::make_cube_mesh(3);
        const Eigen::Vector3d target = ball ? Eigen::Vector3d(0.3, -0.2, 0.5) : Eigen::Vector3d(0.2, 0.3, 0.4);
        TetMesh mesh = start;
        const double start_angle = mesh_min_dihedral_deg(mesh);
        double radius = 0.5;
        for (int round = 0; round < 10; ++round) {
            const TetMesh before = mesh;
            const RefineResult result = refine_tets(mesh, tets_near(mesh, target, radius));
            EXPECT_EQ(result.marks_skipped_guard, 0u);
            EXPECT_EQ(testing::tets_under_parent_guard(mesh, before, [&](size_t t) { return result.new_to_old_tet[t]; }), 0u);
            radius *= 0.8;
        }
        EXPECT_NO_THROW(validate(mesh));
        EXPECT_GT(mesh.tet_count(), 4 * start.tet_count()) << (ball ? "ball" : "cube");
        const double angle = mesh_min_dihedral_deg(mesh);
        std::printf("[ refine ] %s: %zu -> %zu tets, min dihedral %.2f -> %.2f deg\n", ball ? "ball" : "cube",
                    start.tet_count(), mesh.tet_count(), start_angle, angle);
        EXPECT_GT(angle, 0.3 * start_angle) << (ball ? "ball" : "cube");
        EXPECT_NEAR(total_volume(mesh), total_volume(start), 1e-12 * total_volume(start));
    }
}

TEST(Refine, NeverCreatesATetUnderTheGuardAndUndoesAMarkWholeWhenItWould) {
    // Slivers under 0.5 degrees: their children may not fall under the parent's own angle.
    TetMesh slivered = testing::make_cube_mesh(8);
    const std::vector<int32_t> flat = flatten_into_slivers(slivered, build_connectivity(slivered), 8, 0.002);
    ASSERT_FALSE(flat.empty());
    ASSERT_LT(mesh_min_dihedral_deg(slivered), 0.5);
    {
        TetMesh mesh = slivered;
        std::vector<int32_t> all(mesh.tet_count());
        std::iota(all.begin(), all.end(), 0);
        const RefineResult result = refine_tets(mesh, all);
        EXPECT_EQ(testing::tets_under_parent_guard(mesh, slivered, [&](size_t t) { return result.new_to_old_tet[t]; }), 0u);
        EXPECT_NO_THROW(validate(mesh));
    }
    // A guard no bisection can meet: every mark is undone and the mesh is unchanged bit for bit.
    TetMesh mesh = painted_cube(3);
    const TetMesh before = mesh;
    RefineOptions options;
    options.guard_deg = 59;
    const RefineResult result = refine_tets(mesh, tets_near(mesh, Eigen::Vector3d(0.5, 0.5, 0.5), 0.4), options);
    EXPECT_GT(result.marks, 0u);
    EXPECT_EQ(result.marks_skipped_guard, result.marks);
    EXPECT_EQ(result.bisections, 0u);
    EXPECT_TRUE(mesh == before);
}

TEST(Refine, StopsAtTheBudgetWithAValidMesh) {
    const TetMesh before = painted_cube(4);
    std::vector<int32_t> all(before.tet_count());
    std::iota(all.begin(), all.end(), 0);
    for (const size_t budget : {before.tet_count(), before.tet_count() + 1, before.tet_count() + 37}) {
        TetMesh mesh = before;
        RefineOptions options;
        options.max_tets = budget;
        const RefineResult result = refine_tets(mesh, all, options);
        EXPECT_LE(mesh.tet_count(), budget);
        EXPECT_GT(result.marks_skipped_budget, 0u) << budget;
        EXPECT_EQ(result.marks_refined + result.marks_skipped_guard + result.marks_skipped_budget, result.marks);
        expect_refinement_of(before, mesh, result);
    }
}

TEST(Refine, IsDeterministicAndKeepsPiecesApart) {
    TetMesh broken = testing::make_cube_mesh(4);
    FractureOptions fracture;
    const std::vector<Eigen::Vector3d> seeds = {Eigen::Vector3d(0.2, 0.5, 0.5), Eigen::Vector3d(0.8, 0.5, 0.5)};
    fracture_voronoi(broken, seeds, fracture);
    const std::vector<int32_t> marks = tets_near(broken, Eigen::Vector3d(0.5, 0.5, 0.5), 0.3);
    TetMesh a = broken, b = broken;
    const RefineResult ra = refine_tets(a, marks);
    const RefineResult rb = refine_tets(b, marks);
    EXPECT_TRUE(a == b);
    EXPECT_EQ(ra.new_to_old_tet, rb.new_to_old_tet);
    EXPECT_EQ(ra.vertex_origins, rb.vertex_origins);
    expect_refinement_of(broken, a, ra);
    testing::expect_pieces_separate_and_connected(a, build_connectivity(a));
}

TEST(Refine, RefinesAroundPointsUntilTheTetsThereAreShortEnough) {
    const TetMesh before = painted_cube(3);
    TetMesh mesh = before;
    const std::vector<Eigen::Vector3d> points = {Eigen::Vector3d(0.3, 0.4, 0.5), Eigen::Vector3d(0.5, 0.4, 0.5)};
    const double radius = 0.2, edge = 0.06;
    const RefineResult result = refine_near_points(mesh, points, radius, edge);
    EXPECT_GT(result.bisections, 0u);
    EXPECT_EQ(result.marks_skipped_guard, 0u);
    expect_refinement_of(before, mesh, result);
    size_t reached = 0, far_and_long = 0;
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const Tet& tet = mesh.tets[t];
        double longest = 0;
        for (const auto& [i, j] : kTetEdges) longest = std::max(longest, (mesh.positions[tet[i]] - mesh.positions[tet[j]]).norm());
        const Eigen::Vector3d c = centroid(mesh, t);
        const bool near = (c - points[0]).norm() < radius || (c - points[1]).norm() < radius;
        if (near) {
            ++reached;
            EXPECT_LE(longest, edge) << t;
        } else if (longest > 2 * edge) {
            ++far_and_long;
        }
    }
    EXPECT_GT(reached, 100u);
    EXPECT_GT(far_and_long, 0u);  // local: the rest of the cube keeps its long edges
    TetMesh unchanged = before;
    EXPECT_THROW(refine_near_points(unchanged, {}, radius, edge), InvalidArgumentError);
    EXPECT_THROW(refine_near_points(unchanged, points, 0, edge), InvalidArgumentError);
    EXPECT_THROW(refine_near_points(unchanged, points, radius, std::numeric_limits<double>::quiet_NaN()),
                 InvalidArgumentError);
    EXPECT_TRUE(unchanged == before);
}

TEST(Refine, RefusesBadInputWithAClearError) {
    TetMesh mesh = testing::make_cube_mesh(2);
    const TetMesh before = mesh;
    const auto expect_error = [&](std::vector<int32_t> marks, RefineOptions options, const std::string& words) {
        try {
            refine_tets(mesh, marks, options);
            ADD_FAILURE() << "no error for " << words;
        } catch (const InvalidArgumentError& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
        EXPECT_TRUE(mesh == before);
    };
    expect_error({0, static_cast<int32_t>(mesh.tet_count())}, {}, "out of range");
    expect_error({-1}, {}, "out of range");
    RefineOptions nan_guard;
    nan_guard.guard_deg = std::numeric_limits<double>::quiet_NaN();
    expect_error({0}, nan_guard, "guard");
    RefineOptions absurd;
    absurd.max_tets = size_t{1} << 40;
    expect_error({0}, absurd, "budget");
    RefineOptions too_small;
    too_small.max_tets = mesh.tet_count() - 1;
    expect_error({0}, too_small, "below");
}

TEST(Refine, StopsBetweenMarksWhenCancelled) {
    TetMesh mesh = testing::make_cube_mesh(3);
    std::vector<int32_t> all(mesh.tet_count());
    std::iota(all.begin(), all.end(), 0);
    Progress progress;
    progress.request_cancel();
    EXPECT_THROW(refine_tets(mesh, all, {}, &progress), CancelledError);
    EXPECT_NO_THROW(validate(mesh));
}

}  // namespace
}  // namespace waxwork
