// Cutting and relaxation (TransCut Sec. 5): which tets go, what survives, and that relaxation keeps
// vertices on their side and tets above the 0.5 degree guard.
#include "base/error.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/quality.h"
#include "tetops/relaxation.h"
#include "tetops/test_meshes.h"
#include "tetops/tet_mesh.h"
#include "tetops/vertex_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace waxwork {
namespace {

using testing::make_cell_mesh;
using testing::make_cube_mesh;

bool all_cut_away(const TetMesh& mesh, const Tet& tet, const CuttingSurface& surface) {
    for (int32_t v : tet)
        if (!surface.cuts_away(mesh.positions[v])) return false;
    return true;
}

TEST(PlaneCut, RejectsBadPlanes) {
    EXPECT_THROW(PlaneCut(Eigen::Vector3d::Zero(), 1.0), InvalidArgumentError);
    EXPECT_THROW(PlaneCut(Eigen::Vector3d(std::nan(""), 0, 1), 0.0), InvalidArgumentError);
    EXPECT_THROW(PlaneCut(Eigen::Vector3d(0, 0, 1), std::numeric_limits<double>::infinity()), InvalidArgumentError);
    // Huge but finite components are a direction like any other (their squares overflow).
    const PlaneCut huge(Eigen::Vector3d(1e300, 0, 0), 0.5e300);
    EXPECT_DOUBLE_EQ(huge.side(Eigen::Vector3d(1, 0, 0)), 0.5);
    const PlaneCut plane(Eigen::Vector3d(0, 0, 2), 1.0);  // z > 0.5
    EXPECT_NEAR(plane.side(Eigen::Vector3d(0, 0, 1)), 0.5, 1e-15);
    EXPECT_FALSE(plane.cuts_away(Eigen::Vector3d(3, 3, 0.5)));  // on the plane: kept
}

TEST(CutPlane, RemovesExactlyTheTetsWithAllVerticesCutAway) {
    const TetMesh before = make_cube_mesh(7);
    TetMesh mesh = before;
    const PlaneCut plane(Eigen::Vector3d(1.0, 0.4, -0.3), 0.45);
    const CutResult result = remove_cut_away_tets(mesh, plane);

    EXPECT_NO_THROW(validate(mesh));  // also checks that no vertex is unreferenced
    ASSERT_EQ(result.new_to_old_tet.size(), mesh.tet_count());
    EXPECT_EQ(result.tets_removed + mesh.tet_count(), before.tet_count());
    EXPECT_EQ(result.vertices_removed + mesh.vertex_count(), before.vertex_count());
    EXPECT_GT(result.tets_removed, 0u);
    EXPECT_GT(mesh.tet_count(), 0u);

    std::vector<bool> survived(before.tet_count(), false);
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const int32_t old = result.new_to_old_tet[t];
        survived[old] = true;
        EXPECT_FALSE(all_cut_away(before, before.tets[old], plane)) << "tet " << old << " should be gone";
        EXPECT_EQ(mesh.original_ids[t], before.original_ids[old]);
        EXPECT_EQ(mesh.piece_ids[t], before.piece_ids[old]);
        for (int k = 0; k < 4; ++k) {
            const int32_t old_vertex = before.tets[old][k];
            EXPECT_EQ(mesh.tets[t][k], result.old_to_new_vertex[old_vertex]);
            EXPECT_EQ(mesh.positions[mesh.tets[t][k]], before.positions[old_vertex]);
        }
    }
    for (size_t t = 0; t < before.tet_count(); ++t)
        if (!survived[t]) { EXPECT_TRUE(all_cut_away(before, before.tets[t], plane)) << "tet " << t << " removed wrongly"; }
    // Survivors stay in their original order, so original ids stay ascending.
    EXPECT_TRUE(std::is_sorted(mesh.original_ids.begin(), mesh.original_ids.end()));
    // The map the other way: every vertex after has exactly the vertex before that maps to it.
    const std::vector<int32_t> new_to_old = inverse_vertex_map(result.old_to_new_vertex, mesh.vertex_count());
    ASSERT_EQ(new_to_old.size(), mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        ASSERT_GE(new_to_old[v], 0) << v;  // a removal cut makes no vertex
        EXPECT_EQ(result.old_to_new_vertex[static_cast<size_t>(new_to_old[v])], static_cast<int32_t>(v));
        EXPECT_EQ(mesh.positions[v], before.positions[static_cast<size_t>(new_to_old[v])]);
    }
    EXPECT_EQ(inverse_vertex_map(std::vector<int32_t>{-1, 1}, 3), (std::vector<int32_t>{-1, 1, -1}));
}

TEST(CutPlane, KeepsMaterialsAndTestsPiecesInWorldSpace) {
    TetMesh mesh = make_cube_mesh(4);
    mesh.materials.resize(mesh.tet_count());
    for (size_t t = 0; t < mesh.tet_count(); ++t) mesh.materials[t] = TetMaterial{{double(t), 0, 0}, {1, 1, 1}, 1.3};
    // The piece sits at x in [10, 11] in world space; a cut at x > 10.5 must act on rest x > 0.5.
    mesh.piece_transforms[0].translation = Eigen::Vector3d(10, 0, 0);
    const TetMesh before = mesh;
    const CutResult result = remove_cut_away_tets(mesh, PlaneCut(Eigen::Vector3d::UnitX(), 10.5));
    const PlaneCut rest_plane(Eigen::Vector3d::UnitX(), 0.5);
    EXPECT_GT(result.tets_removed, 0u);
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const int32_t old = result.new_to_old_tet[t];
        EXPECT_EQ(mesh.materials[t], before.materials[old]);
        EXPECT_FALSE(all_cut_away(before, before.tets[old], rest_plane));
    }
    for (size_t t = 0; t < before.tet_count(); ++t)
        if (std::find(result.new_to_old_tet.begin(), result.new_to_old_tet.end(), t) == result.new_to_old_tet.end()) {
            EXPECT_TRUE(all_cut_away(before, before.tets[t], rest_plane));
        }
    EXPECT_NO_THROW(validate(mesh));
}

TEST(CutPlane, PlaneOutsideRemovesNothing) {
    const TetMesh before = make_cube_mesh(3);
    TetMesh mesh = before;
    const CutResult result = remove_cut_away_tets(mesh, PlaneCut(Eigen::Vector3d(0, 0, 1), 1.0));  // z > 1
    EXPECT_EQ(result.tets_removed, 0u);
    EXPECT_EQ(result.vertices_removed, 0u);
    EXPECT_EQ(mesh, before);
}

TEST(CutPlane, RepeatedCutsUntilNothingIsLeft) {
    TetMesh mesh = make_cube_mesh(5);
    size_t previous = mesh.tet_count();
    for (double d = 0.9; d > -0.5; d -= 0.2) {
        const PlaneCut plane(Eigen::Vector3d(1, 1, 1), d * std::sqrt(3.0));
        remove_cut_away_tets(mesh, plane);
        EXPECT_LE(mesh.tet_count(), previous);
        previous = mesh.tet_count();
        EXPECT_NO_THROW(validate(mesh));
        const TetConnectivity connectivity = build_connectivity(mesh);
        const RelaxationReport report = relax_cut_vertices(mesh, connectivity, plane);
        EXPECT_NO_THROW(validate(mesh));
        if (mesh.tet_count() == 0) { EXPECT_EQ(report.min_dihedral_deg, 0); }
    }
    EXPECT_EQ(mesh.tet_count(), 0u);
    EXPECT_EQ(mesh.vertex_count(), 0u);
    // Cutting the empty mesh again is harmless.
    const CutResult again = remove_cut_away_tets(mesh, PlaneCut(Eigen::Vector3d::UnitX(), 0.0));
    EXPECT_EQ(again.tets_removed, 0u);
    EXPECT_NO_THROW(validate(mesh));
}

TEST(CutPlane, RequireTetsLeftRefusesOnlyACutThatEmptiedTheMesh) {
    TetMesh mesh = make_cube_mesh(3);
    const size_t before = mesh.tet_count();
    remove_cut_away_tets(mesh, PlaneCut(Eigen::Vector3d::UnitX(), 0.5));  // half is left
    EXPECT_NO_THROW(require_tets_left_by_cut(mesh, before));
    remove_cut_away_tets(mesh, PlaneCut(Eigen::Vector3d::UnitX(), -1.0));  // nothing is left
    ASSERT_EQ(mesh.tet_count(), 0u);
    try {
        require_tets_left_by_cut(mesh, before);
        ADD_FAILURE() << "an emptied mesh passed";
    } catch (const InvalidArgumentError& e) {
        EXPECT_NE(std::string(e.what()).find("removes all " + std::to_string(before) + " tets"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(require_tets_left_by_cut(mesh, 0));  // it was empty before: nothing was lost
}

TEST(CutPlane, CutThroughAUShapeLeavesTwoComponents) {
    // A U standing on the xy plane: a base row of cells and two pillars at x = 0 and x = 4.
    TetMesh mesh = make_cell_mesh(5, 4, 1, [](int i, int j, int) { return j == 0 || i == 0 || i == 4; });
    EXPECT_EQ(build_connectivity(mesh).component_count, 1);
    const PlaneCut below(Eigen::Vector3d(0, -1, 0), -1.5);  // removes y < 1.5: the base
    const CutResult result = remove_cut_away_tets(mesh, below);
    EXPECT_EQ(result.tets_removed, 5u * 6u);
    const TetConnectivity connectivity = build_connectivity(mesh);
    EXPECT_EQ(connectivity.component_count, 2);
    const std::vector<Eigen::Vector3d> cut_positions = mesh.positions;
    const RelaxationReport report = relax_cut_vertices(mesh, connectivity, below, {.max_iterations = 200});
    EXPECT_GT(report.vertices_moved, 0u);
    EXPECT_GE(report.min_dihedral_deg, 0.5);
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        if (below.cuts_away(cut_positions[v])) {
            EXPECT_GE(below.side(mesh.positions[v]), 0.0) << "vertex " << v << " crossed the plane";
        } else {
            EXPECT_EQ(mesh.positions[v], cut_positions[v]);
        }
    }
    EXPECT_EQ(build_connectivity(mesh).component_count, 2);
    EXPECT_NO_THROW(validate(mesh));
}

TEST(StrokeCut, LeftOfTheStrokeIsCutAway) {
    // Eye above the unit square looking down -z: screen x is world x, screen up is world y.
    const Eigen::Vector3d eye(0.5, 0.5, 5), view(0, 0, -1);
    // Rightwards then downwards: left of "right" is up (+y), left of "down" is right (+x).
    const std::vector<Eigen::Vector3d> stroke = {{0.0, 0.5, 4}, {0.5, 0.5, 4}, {0.5, 0.0, 4}};
    const StrokeCut cut(eye, view, stroke);
    EXPECT_TRUE(cut.cuts_away({0.2, 0.9, 0.5}));
    EXPECT_TRUE(cut.cuts_away({0.9, 0.9, 0.5}));  // the corner's wedge
    EXPECT_TRUE(cut.cuts_away({0.9, 0.1, 0.5}));
    EXPECT_FALSE(cut.cuts_away({0.1, 0.1, 0.5}));
    EXPECT_TRUE(cut.cuts_away({-3.0, 0.6, 0.5}));  // beyond the stroke's end: the end segment extends
    EXPECT_FALSE(cut.cuts_away({0.5, 0.5, 6}));    // behind the eye
    const StrokeCut flipped(eye, view, stroke, true);
    EXPECT_FALSE(flipped.cuts_away({0.9, 0.9, 0.5}));
    EXPECT_TRUE(flipped.cuts_away({0.1, 0.1, 0.5}));
    EXPECT_THROW(StrokeCut(eye, view, {{0.0, 0.5, 4}}), InvalidArgumentError);
    EXPECT_THROW(StrokeCut(eye, view, {{0.0, 0.5, 4}, {0.0, 0.5, 6}}), InvalidArgumentError);  // behind eye
}

TEST(StrokeCut, CutAndRelaxKeepVerticesOnTheirSide) {
    TetMesh mesh = make_cube_mesh(8);
    const StrokeCut cut(Eigen::Vector3d(0.5, 0.5, 5), Eigen::Vector3d(0, 0, -1),
                        {{0.0, 0.43, 4}, {0.47, 0.43, 4}, {0.47, 0.0, 4}});
    const TetMesh before = mesh;
    const CutResult result = remove_cut_away_tets(mesh, cut);
    for (size_t t = 0; t < mesh.tet_count(); ++t)
        EXPECT_FALSE(all_cut_away(before, before.tets[result.new_to_old_tet[t]], cut));
    std::vector<double> side_before;
    for (const Eigen::Vector3d& p : mesh.positions) side_before.push_back(cut.side(p));
    const RelaxationReport report = relax_cut_vertices(mesh, build_connectivity(mesh), cut, {.max_iterations = 100});
    EXPECT_GT(report.vertices_moved, 0u);
    for (size_t v = 0; v < mesh.vertex_count(); ++v)
        if (side_before[v] > 0) { EXPECT_GE(cut.side(mesh.positions[v]), 0.0); }
    EXPECT_NO_THROW(validate(mesh));
}

// Relaxation onto a plane just beyond a layer of grid vertices: the relaxed vertices flatten the tets
// between that layer and the plane, the situation of the paper's Fig. 9(a).
struct FlatteningCase {
    TetMesh mesh;
    PlaneCut plane{Eigen::Vector3d::UnitX(), 0.5 + 1e-4};
};

FlatteningCase make_flattening_case() {
    FlatteningCase c{make_cube_mesh(8)};
    remove_cut_away_tets(c.mesh, c.plane);
    return c;
}

TEST(Relaxation, WithoutTheGuardTetsGetFlatterThanHalfADegree) {
    FlatteningCase c = make_flattening_case();
    const RelaxationReport report =
        relax_cut_vertices(c.mesh, build_connectivity(c.mesh), c.plane, {.max_iterations = 1000, .min_dihedral_guard_deg = 0});
    EXPECT_LT(report.min_dihedral_deg, 0.5);
    EXPECT_LT(report.iterations, 1000);  // stops once every vertex has landed
    EXPECT_GT(report.vertices_on_surface, 0u);
    // Flat but never inverted.
    for (size_t t = 0; t < c.mesh.tet_count(); ++t) EXPECT_GT(signed_volume(c.mesh, t), 0);
}

TEST(Relaxation, GuardKeepsEveryDihedralAngleAboveHalfADegree) {
    FlatteningCase c = make_flattening_case();
    const TetMesh before = c.mesh;
    const RelaxationReport report =
        relax_cut_vertices(c.mesh, build_connectivity(c.mesh), c.plane, {.max_iterations = 1000});
    EXPECT_GT(report.movable_vertices, 0u);
    EXPECT_GT(report.vertices_moved, 0u);
    EXPECT_GT(report.moves_rejected, 0u);  // the guard did have to act
    EXPECT_LT(report.iterations, 1000);
    EXPECT_GE(report.min_dihedral_deg, 0.5);
    const std::vector<double> angles = min_dihedral_angles_deg(c.mesh);
    EXPECT_GE(*std::min_element(angles.begin(), angles.end()), 0.5);
    EXPECT_DOUBLE_EQ(*std::min_element(angles.begin(), angles.end()), report.min_dihedral_deg);
    for (size_t v = 0; v < c.mesh.vertex_count(); ++v) {
        const double side = c.plane.side(before.positions[v]);
        if (side > 0) {
            EXPECT_GE(c.plane.side(c.mesh.positions[v]), 0.0) << "vertex " << v << " crossed the plane";
        } else {
            EXPECT_EQ(c.mesh.positions[v], before.positions[v]) << "kept-side vertex " << v << " moved";
        }
    }
    EXPECT_NO_THROW(validate(c.mesh));
}

TEST(Relaxation, IsDeterministicAndRespectsTheIterationLimit) {
    FlatteningCase a = make_flattening_case();
    FlatteningCase b = make_flattening_case();
    const TetConnectivity connectivity = build_connectivity(a.mesh);
    const RelaxationReport ra = relax_cut_vertices(a.mesh, connectivity, a.plane, {.max_iterations = 3});
    const RelaxationReport rb = relax_cut_vertices(b.mesh, connectivity, b.plane, {.max_iterations = 3});
    EXPECT_EQ(ra.iterations, 3);
    EXPECT_EQ(a.mesh.positions, b.mesh.positions);
    EXPECT_EQ(ra.moves_accepted, rb.moves_accepted);
    FlatteningCase c = make_flattening_case();
    const RelaxationReport none = relax_cut_vertices(c.mesh, connectivity, c.plane, {.max_iterations = 0});
    EXPECT_EQ(none.iterations, 0);
    EXPECT_EQ(none.vertices_moved, 0u);
}

TEST(Relaxation, RejectsBadOptions) {
    FlatteningCase c = make_flattening_case();
    const TetConnectivity connectivity = build_connectivity(c.mesh);
    EXPECT_THROW(relax_cut_vertices(c.mesh, connectivity, c.plane, {.step = 0}), InvalidArgumentError);
    EXPECT_THROW(relax_cut_vertices(c.mesh, connectivity, c.plane, {.min_dihedral_guard_deg = -1}),
                 InvalidArgumentError);
    EXPECT_THROW(relax_cut_vertices(c.mesh, build_connectivity(make_cube_mesh(2)), c.plane), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
