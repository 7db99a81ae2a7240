#include "base/error.h"
#include "base/progress.h"
#include "io/volume_file.h"
#include "scene/document.h"
#include "solver/material.h"
#include "tetops/test_meshes.h"

#include "support/scratch_dir.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

namespace waxwork {
namespace {

TetMesh test_cube() { return testing::make_cube_mesh(6); }

PlaneCutOp plane_cut(double offset) {
    PlaneCutOp op;
    op.plane = {Eigen::Vector3d(1, 0.2, 0.1), offset};
    op.relax.iterations = 5;
    return op;
}

PaintOp paint_at(const Eigen::Vector3d& p) {
    PaintOp op;
    op.points = {p, p + Eigen::Vector3d(0.1, 0, 0)};
    op.material = material_preset("ketchup");
    op.sigma = 0.1;
    return op;
}

std::vector<EditOperation> material_and_geometry_ops() {
    StrokeCutOp stroke;
    stroke.stroke = {Eigen::Vector3d(0.5, 0.5, 5), Eigen::Vector3d(0, 0, -1),
                     {Eigen::Vector3d(0.2, -1, 4), Eigen::Vector3d(0.75, 2, 4)}, false};
    RelaxOp relax{PlaneSurface{Eigen::Vector3d(1, 0.2, 0.1), 0.55}, RelaxSettings{4, 0.3, 0.5}};
    PlaneCutOp exact = plane_cut(0.55);
    exact.exact = true;
    FractureOp scattered;
    scattered.pieces = 3;
    scattered.seed = 7;
    FractureOp seeded;
    seeded.seeds = {Eigen::Vector3d(0.2, 0.5, 0.5), Eigen::Vector3d(0.8, 0.5, 0.5)};
    seeded.exact = false;
    MovePieceOp move;
    move.transform.rotation = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()).toRotationMatrix();
    move.transform.translation = Eigen::Vector3d(0.3, 0, 0);
    // Drags of the side x = 0, pinned near the middle (first: a document given every kind in turn
    // deforms the whole cube before the cuts take parts of it away).
    DeformOp grab;
    grab.grab = Eigen::Vector3d(0, 0.5, 0.5);
    grab.radius = 0.4;
    grab.motion = HandleMotion::translation(Eigen::Vector3d(-0.15, 0.1, 0.05));
    grab.pins = {PinSphere{Eigen::Vector3d(0.3, 0.5, 0.5), 0.15}};
    grab.iterations = 4;
    grab.steps = 2;
    DeformOp twist = grab;
    twist.motion = HandleMotion::twist(Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(1, 0, 0), 0.6);
    RefineOp refine_marked;
    refine_marked.tets = {100, 0, 17, 40, 5, 17};
    RefineOp refine_near;
    refine_near.points = {Eigen::Vector3d(0.4, 0.5, 0.5), Eigen::Vector3d(0.5, 0.5, 0.5)};
    refine_near.radius = 0.2;
    refine_near.edge_length = 0.08;
    return {grab, twist, plane_cut(0.55), exact, stroke, relax, paint_at({0.3, 0.3, 0.3}),
            SetMaterialOp{material_preset("skin1"), std::nullopt}, SetMaterialOp{material_preset("marble"), 0},
            scattered, seeded, move, refine_marked, refine_near};
}

TEST(Document, LoadingWithoutMaterialsAssignsTheDefault) {
    const Document doc(test_cube(), material_preset("marble"));
    ASSERT_EQ(doc.mesh().materials.size(), doc.mesh().tet_count());
    EXPECT_EQ(doc.mesh().materials.front(), material_preset("marble"));
    EXPECT_GT(doc.min_dihedral_deg(), 0);
}

TEST(Document, ACutThatWouldRemoveEverythingIsRefusedAndChangesNothing) {
    for (const bool exact : {false, true}) {
        SCOPED_TRACE(exact ? "exact" : "remove and relax");
        Document doc(test_cube(), material_preset("marble"));
        const TetMesh before = doc.mesh();
        PlaneCutOp everything = plane_cut(-10);  // the whole cube is on the side n.x > -10
        everything.exact = exact;
        EXPECT_THROW(doc.apply(everything), InvalidArgumentError);
        EXPECT_EQ(doc.mesh(), before);
        EXPECT_FALSE(doc.can_undo());
        EXPECT_NO_THROW(doc.apply(plane_cut(0.55)));  // and the document still works
        EXPECT_LT(doc.mesh().tet_count(), before.tet_count());
    }
}

TEST(Document, UndoRestoresTheMeshBitForBitForEveryKind) {
    for (const EditOperation& op : material_and_geometry_ops()) {
        Document doc(test_cube(), material_preset("marble"));
        doc.apply(paint_at({0.6, 0.6, 0.6}));  // so the edit starts from a non-trivial state
        const TetMesh before = doc.mesh();
        const ChangeReport report = doc.apply(op);
        EXPECT_TRUE(report.anything_changed()) << report.name;
        EXPECT_FALSE(doc.mesh() == before) << report.name;
        const TetMesh after = doc.mesh();
        ASSERT_TRUE(doc.undo()) << report.name;
        EXPECT_TRUE(doc.mesh() == before) << report.name;
        ASSERT_TRUE(doc.redo()) << report.name;
        EXPECT_TRUE(doc.mesh() == after) << report.name;
        EXPECT_EQ(doc.history().size(), 2u);
    }
}

TEST(Document, DeformReportsTheMovedVerticesAndKeepsEverythingButPositions) {
    Document doc(test_cube(), material_preset("marble"));
    doc.apply(paint_at({0.1, 0.5, 0.5}));
    const TetMesh before = doc.mesh();
    const double min_angle_before = doc.min_dihedral_deg();
    DeformOp bend;
    bend.grab = Eigen::Vector3d(0, 0.5, 0.5);
    bend.radius = 0.5;
    bend.motion = HandleMotion::bend(Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(0, 0, 1), 0.4);
    bend.pins = {PinSphere{Eigen::Vector3d(1, 0.5, 0.5), 0.3}};
    const ChangeReport report = doc.apply(bend);
    EXPECT_TRUE(report.positions);
    EXPECT_FALSE(report.topology);
    ASSERT_FALSE(report.moved_vertices.empty());
    EXPECT_TRUE(std::is_sorted(report.moved_vertices.begin(), report.moved_vertices.end()));
    size_t moved = 0;
    for (size_t v = 0; v < before.vertex_count(); ++v) moved += doc.mesh().positions[v] != before.positions[v] ? 1 : 0;
    EXPECT_EQ(report.moved_vertices.size(), moved);
    EXPECT_EQ(doc.mesh().tets, before.tets);
    EXPECT_EQ(doc.mesh().materials, before.materials);  // painted materials move with their tets
    const DragReport& drag = std::get<DragReport>(report.result);
    EXPECT_EQ(drag.inverted_tets, 0u);
    EXPECT_GE(report.min_dihedral_deg, std::min(0.5, min_angle_before) - 1e-9);
    EXPECT_GT(drag.handle_vertices, 0u);
    EXPECT_GT(drag.pinned_vertices, 0u);
    const std::optional<ChangeReport> undone = doc.undo();
    ASSERT_TRUE(undone);
    EXPECT_EQ(undone->moved_vertices, report.moved_vertices);
    EXPECT_TRUE(doc.mesh() == before);
    // A grab that reaches no vertex is refused, names the operation and changes nothing.
    DeformOp nowhere = bend;
    nowhere.grab = Eigen::Vector3d(5, 5, 5);
    try {
        doc.apply(nowhere);
        ADD_FAILURE() << "no error";
    } catch (const InvalidArgumentError& e) {
        EXPECT_NE(std::string(e.what()).find("deform: no vertex lies within the handle"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(doc.mesh() == before);
    // A deform cancelled through its progress changes nothing either, and the next one works.
    Progress cancelled;
    cancelled.request_cancel();
    EXPECT_THROW(doc.apply(bend, &cancelled), CancelledError);
    EXPECT_TRUE(doc.mesh() == before);
    EXPECT_EQ(doc.history().size(), 1u);
    EXPECT_TRUE(doc.apply(bend).positions);
}

// A drag previewed frame by frame: no history until it ends; other edits wait; the commit equals
// applying the final operation to the document as it was before the drag, bit for bit (what a session
// replays); a cancel restores the volume.
TEST(Document, DeformPreviewsCommitWhatAReplayMakesAndCancelRestores) {
    Document doc(test_cube(), material_preset("marble"));
    const TetMesh before = doc.mesh();
    DeformOp op;
    op.grab = Eigen::Vector3d(1, 0.5, 0.5);
    op.radius = 0.4;
    op.pins = {PinSphere{Eigen::Vector3d(0, 0.5, 0.5), 0.3}};
    op.steps = 2;
    op.iterations = 6;
    for (int frame = 1; frame <= 3; ++frame) {
        op.motion = HandleMotion::translation(Eigen::Vector3d(0, 0.05 * frame, 0));
        const ChangeReport preview = doc.preview_deform(op, 2);
        EXPECT_TRUE(preview.positions) << frame;
        EXPECT_FALSE(preview.moved_vertices.empty()) << frame;
        EXPECT_TRUE(doc.previewing());
    }
    EXPECT_TRUE(doc.history().empty());
    EXPECT_FALSE(doc.can_undo());
    EXPECT_THROW(doc.apply(paint_at({0.5, 0.5, 0.5})), InvalidArgumentError);
    EXPECT_THROW(doc.undo(), InvalidArgumentError);
    DeformOp elsewhere = op;
    elsewhere.grab = Eigen::Vector3d(1, 0.4, 0.5);
    EXPECT_THROW(doc.preview_deform(elsewhere, 2), InvalidArgumentError);
    const TetMesh shown = doc.mesh();

    const ChangeReport committed = doc.commit_deform(op);
    EXPECT_FALSE(doc.previewing());
    ASSERT_EQ(doc.history().size(), 1u);
    EXPECT_TRUE(doc.history().front() == EditOperation(op));
    Document replay(test_cube(), material_preset("marble"));
    replay.apply(op);
    EXPECT_TRUE(doc.mesh() == replay.mesh());
    // The report names every vertex whose position differs from the last preview's.
    size_t differs = 0;
    for (size_t v = 0; v < shown.vertex_count(); ++v) differs += shown.positions[v] != doc.mesh().positions[v] ? 1 : 0;
    EXPECT_EQ(committed.moved_vertices.size(), differs);
    ASSERT_TRUE(doc.undo());
    EXPECT_TRUE(doc.mesh() == before);

    op.motion = HandleMotion::translation(Eigen::Vector3d(0, -0.1, 0));
    doc.preview_deform(op, 3);
    EXPECT_FALSE(doc.mesh() == before);
    const std::optional<ChangeReport> cancelled = doc.cancel_deform();
    ASSERT_TRUE(cancelled);
    EXPECT_FALSE(cancelled->moved_vertices.empty());
    EXPECT_TRUE(doc.mesh() == before);
    EXPECT_FALSE(doc.previewing());
    EXPECT_FALSE(doc.cancel_deform());
    EXPECT_THROW(doc.commit_deform(op), InvalidArgumentError);
}

TEST(Document, SaveAndReloadAfterEveryKindOfOperationIsIdentical) {
    const auto path = testing::scratch_dir("document_reload") / "reload.vtu";
    std::vector<EditOperation> ops = material_and_geometry_ops();
    ops.push_back(WeldOp{1e-9});
    // One document through every kind in turn (fracture, move and weld included), saved and reloaded
    // after each: pieces, transforms, materials and original ids survive bit for bit.
    Document doc(test_cube(), material_preset("marble"));
    for (const EditOperation& op : ops) {
        const ChangeReport report = doc.apply(op);
        write_volume(doc.mesh(), path);
        EXPECT_TRUE(read_volume(path) == doc.mesh()) << report.name;
    }
    std::filesystem::remove(path);
}

TEST(Document, FracturePullApartAndWeldUndoBitForBit) {
    Document doc(test_cube(), material_preset("marble"));
    FractureOp fracture;
    fracture.seeds = {Eigen::Vector3d(0.25, 0.5, 0.5), Eigen::Vector3d(0.75, 0.5, 0.5)};
    const ChangeReport broken = doc.apply(fracture);
    EXPECT_TRUE(broken.topology);
    ASSERT_EQ(doc.mesh().piece_transforms.size(), 2u);
    EXPECT_GT(broken.vertices_after, broken.vertices_before);  // crack vertices duplicated
    const TetMesh together = doc.mesh();

    MovePieceOp pull;
    pull.piece = 1;
    pull.transform.translation = Eigen::Vector3d(0.4, 0, 0);
    const size_t bytes_before_move = doc.undo_bytes();
    const ChangeReport moved = doc.apply(pull);
    EXPECT_TRUE(moved.piece_transforms);
    EXPECT_FALSE(moved.topology);
    EXPECT_LT(doc.undo_bytes() - bytes_before_move, 1024u);  // a move keeps only the old transform
    const TetMesh apart = doc.mesh();
    // Apart, nothing touches: the weld changes nothing. Back together, it merges the crack.
    const ChangeReport no_weld = doc.apply(WeldOp{1e-9});
    EXPECT_FALSE(no_weld.anything_changed());
    EXPECT_TRUE(doc.mesh() == apart);
    doc.undo();
    doc.undo();
    EXPECT_TRUE(doc.mesh() == together);
    const ChangeReport welded = doc.apply(WeldOp{1e-9});
    EXPECT_TRUE(welded.topology);
    EXPECT_EQ(doc.mesh().piece_transforms.size(), 1u);
    EXPECT_LT(welded.vertices_after, welded.vertices_before);
    doc.undo();
    EXPECT_TRUE(doc.mesh() == together);
    doc.undo();
    EXPECT_TRUE(doc.mesh() == Document(test_cube(), material_preset("marble")).mesh());
    EXPECT_THROW(doc.apply(MovePieceOp{5, RigidTransform{}}), InvalidArgumentError);
}

TEST(Document, ReportsWhatChanged) {
    Document doc(test_cube(), material_preset("marble"));
    const ChangeReport paint = doc.apply(paint_at({0.5, 0.5, 0.5}));
    EXPECT_FALSE(paint.topology);
    EXPECT_FALSE(paint.positions);
    ASSERT_FALSE(paint.changed_material_tets.empty());
    EXPECT_TRUE(std::is_sorted(paint.changed_material_tets.begin(), paint.changed_material_tets.end()));
    EXPECT_LT(paint.changed_material_tets.size(), doc.mesh().tet_count());
    for (size_t t = 0; t < doc.mesh().tet_count(); ++t) {
        const bool listed = std::binary_search(paint.changed_material_tets.begin(), paint.changed_material_tets.end(),
                                               static_cast<int32_t>(t));
        EXPECT_EQ(listed, !(doc.mesh().materials[t] == material_preset("marble"))) << t;
    }
    const ChangeReport cut = doc.apply(plane_cut(0.5));
    EXPECT_TRUE(cut.topology);
    EXPECT_LT(cut.tets_after, cut.tets_before);
    EXPECT_EQ(cut.tets_after, doc.mesh().tet_count());
    ASSERT_TRUE(cut.connectivity);
    EXPECT_EQ(cut.connectivity->vertex_tets.row_count(), doc.mesh().vertex_count());
    EXPECT_EQ(cut.old_to_new_vertex.size(), cut.vertices_before);
    EXPECT_GT(cut.min_dihedral_deg, 0.4);
}

// A cut, exact or not, reports where the vertices go, and undoing it reports the inverse: each kept
// vertex maps back to the vertex it was (same position, no relaxation here), vertices an exact cut
// made map to -1, and the map is one to one; fracture undoes without a map.
TEST(Document, CutsFracturesAndWeldsMapTheirVerticesBothWays) {
    for (const bool exact : {false, true}) {
        Document doc(test_cube(), material_preset("marble"));
        PlaneCutOp cut = plane_cut(0.55);
        cut.relax.iterations = 0;
        cut.exact = exact;
        const ChangeReport applied = doc.apply(cut);
        const TetMesh cut_mesh = doc.mesh();
        ASSERT_EQ(applied.old_to_new_vertex.size(), applied.vertices_before) << "exact " << exact;
        const ChangeReport undo = *doc.undo();
        ASSERT_EQ(undo.old_to_new_vertex.size(), cut_mesh.vertex_count()) << "exact " << exact;
        std::vector<uint8_t> hit(doc.mesh().vertex_count(), 0);
        int64_t kept = 0, made = 0;
        for (size_t w = 0; w < cut_mesh.vertex_count(); ++w) {
            const int32_t v = undo.old_to_new_vertex[w];
            if (v < 0) {
                ++made;
                continue;
            }
            ++kept;
            ASSERT_LT(static_cast<size_t>(v), doc.mesh().vertex_count());
            EXPECT_EQ(applied.old_to_new_vertex[static_cast<size_t>(v)], static_cast<int32_t>(w));  // the cut's map, inverted
            EXPECT_FALSE(hit[static_cast<size_t>(v)]) << "vertex " << v << " is mapped twice";
            hit[static_cast<size_t>(v)] = 1;
            if (!exact) {
                EXPECT_EQ(cut_mesh.positions[w], doc.mesh().positions[static_cast<size_t>(v)]) << w;
            }
        }
        EXPECT_GT(kept, 0);
        EXPECT_EQ(std::count_if(applied.old_to_new_vertex.begin(), applied.old_to_new_vertex.end(),
                                [](int32_t to) { return to >= 0; }),
                  kept);
        EXPECT_EQ(made > 0, exact);  // only an exact cut makes vertices (on crossed edges)
    }
    // A fracture keeps every vertex's index and appends crack copies and wall vertices.
    Document doc(test_cube(), material_preset("marble"));
    FractureOp fracture;
    fracture.pieces = 3;
    const ChangeReport applied = doc.apply(fracture);
    const size_t before = applied.vertices_before, after = doc.mesh().vertex_count();
    ASSERT_GT(after, before);
    ASSERT_EQ(applied.old_to_new_vertex.size(), before);
    ASSERT_EQ(applied.vertex_origins.size(), after);
    for (size_t v = 0; v < before; ++v) {
        EXPECT_EQ(applied.old_to_new_vertex[v], static_cast<int32_t>(v));
        EXPECT_TRUE(applied.vertex_origins[v] == VertexOrigin::vertex(static_cast<int32_t>(v))) << v;
    }
    for (size_t v = before; v < after; ++v) {
        EXPECT_LT(static_cast<size_t>(std::max(applied.vertex_origins[v].a, applied.vertex_origins[v].b)), v);
    }
    const ChangeReport undo = *doc.undo();
    ASSERT_EQ(undo.old_to_new_vertex.size(), after);
    for (size_t w = 0; w < after; ++w) EXPECT_EQ(undo.old_to_new_vertex[w], w < before ? static_cast<int32_t>(w) : -1);

    // Welding the pieces back merges the crack copies; undoing the weld maps the survivors back.
    doc.redo();
    const ChangeReport weld = doc.apply(WeldOp{1e-9});
    ASSERT_EQ(weld.old_to_new_vertex.size(), after);
    const size_t welded = doc.mesh().vertex_count();
    EXPECT_EQ(static_cast<size_t>(std::count(weld.old_to_new_vertex.begin(), weld.old_to_new_vertex.end(), -1)),
              after - welded);
    const ChangeReport unweld = *doc.undo();
    ASSERT_EQ(unweld.old_to_new_vertex.size(), welded);
    for (size_t w = 0; w < welded; ++w) {
        const int32_t v = unweld.old_to_new_vertex[w];
        ASSERT_GE(v, 0) << w;  // a weld makes no vertex
        EXPECT_EQ(weld.old_to_new_vertex[static_cast<size_t>(v)], static_cast<int32_t>(w));
    }
}

// Each operation's own counts come typed in ChangeReport::result (the command line's summaries read
// them), agreeing with the mesh and the details line; its arrays stay in the report's own fields.
TEST(Document, ReportsTheOperationsOwnCounts) {
    Document doc(test_cube(), material_preset("marble"));
    const ChangeReport cut = doc.apply(plane_cut(0.55));
    const auto& relaxed = std::get<RelaxedCutResult>(cut.result);
    EXPECT_EQ(relaxed.removal.tets_removed, cut.tets_before - cut.tets_after);
    EXPECT_GT(relaxed.relaxation.vertices_moved, 0u);
    EXPECT_EQ(relaxed.relaxation.min_dihedral_deg, cut.min_dihedral_deg);
    EXPECT_NE(cut.details.find(std::to_string(relaxed.removal.tets_removed) + " tets removed, " +
                               std::to_string(relaxed.relaxation.vertices_moved) + " vertices relaxed"),
              std::string::npos)
        << cut.details;
    EXPECT_TRUE(relaxed.removal.old_to_new_vertex.empty());
    EXPECT_EQ(cut.old_to_new_vertex.size(), cut.vertices_before);

    PlaneCutOp exact = plane_cut(0.3);
    exact.exact = true;
    const ChangeReport split = doc.apply(exact);
    const auto& exact_result = std::get<ExactCutResult>(split.result);
    EXPECT_GT(exact_result.tets_split, 0u);
    EXPECT_EQ(exact_result.tets_under_guard, split.tets_under_guard);
    EXPECT_EQ(exact_result.min_dihedral_deg, split.min_dihedral_deg);
    EXPECT_TRUE(exact_result.vertex_origins.empty());
    EXPECT_TRUE(exact_result.new_to_old_tet.empty());
    EXPECT_EQ(split.vertex_origins.size(), split.vertices_after);

    const ChangeReport relax = doc.apply(RelaxOp{PlaneSurface{Eigen::Vector3d(1, 0.2, 0.1), 0.2}, RelaxSettings{3, 0.3, 0.5}});
    EXPECT_LE(std::get<RelaxationReport>(relax.result).iterations, 3);

    const ChangeReport paint = doc.apply(paint_at({0.1, 0.5, 0.5}));
    const auto& painted = std::get<PaintResult>(paint.result);
    EXPECT_TRUE(painted.changed_tets.empty());
    EXPECT_TRUE(painted.weights.empty());
    EXPECT_FALSE(paint.changed_material_tets.empty());

    const ChangeReport set = doc.apply(SetMaterialOp{material_preset("skin1"), std::nullopt});
    EXPECT_TRUE(std::holds_alternative<std::monostate>(set.result));

    FractureOp fracture;
    fracture.pieces = 3;
    fracture.seed = 2;
    const ChangeReport broken = doc.apply(fracture);
    const FractureResult pieces = std::get<FractureResult>(broken.result);
    EXPECT_EQ(static_cast<size_t>(pieces.pieces_after), doc.mesh().piece_transforms.size());
    EXPECT_EQ(pieces.pieces_before, 1);
    EXPECT_TRUE(pieces.vertex_origins.empty());
    EXPECT_EQ(broken.vertex_origins.size(), broken.vertices_after);
    EXPECT_TRUE(std::holds_alternative<std::monostate>(doc.undo()->result));
    const FractureResult again = std::get<FractureResult>(doc.redo()->result);  // redo re-runs it
    EXPECT_EQ(again.pieces_after, pieces.pieces_after);
    EXPECT_EQ(again.vertices_duplicated, pieces.vertices_duplicated);

    const ChangeReport weld = doc.apply(WeldOp{1e-9});
    EXPECT_EQ(std::get<WeldResult>(weld.result).pieces_before, pieces.pieces_after);
    EXPECT_EQ(static_cast<size_t>(std::get<WeldResult>(weld.result).pieces_after), doc.mesh().piece_transforms.size());
    EXPECT_TRUE(std::get<WeldResult>(weld.result).old_to_new_vertex.empty());
}

// FractureOp::collapse is FractureOptions::collapse_swallowed_walls: off, every split the walls made stays.
TEST(Document, FractureWithoutCollapseKeepsEverySplit) {
    FractureOp collapsed;
    collapsed.pieces = 12;
    collapsed.seed = 3;
    FractureOp kept = collapsed;
    kept.collapse = false;
    Document a(testing::make_cube_mesh(8), material_preset("marble"));
    Document b(testing::make_cube_mesh(8), material_preset("marble"));
    const ChangeReport with = a.apply(collapsed), without = b.apply(kept);
    EXPECT_GT(std::get<FractureResult>(with.result).vertices_collapsed, 0u);
    EXPECT_EQ(std::get<FractureResult>(without.result).vertices_collapsed, 0u);
    EXPECT_LT(a.mesh().tet_count(), b.mesh().tet_count());
    EXPECT_EQ(a.mesh().piece_transforms.size(), b.mesh().piece_transforms.size());
}

// A U of 7 x 6 x 2 cells with a long arm (i = 0) and a short one (i = 6, two cells up): cutting its
// bridge away (y < 1.5) leaves the short arm as a fragment of 1/6 of the volume.
TetMesh u_with_a_short_arm() {
    return testing::make_cell_mesh(7, 6, 2, [](int i, int j, int) { return j == 0 || i == 0 || (i == 6 && j <= 1); });
}

PlaneCutOp cut_the_bridge() {
    PlaneCutOp op;
    op.plane = {-Eigen::Vector3d::UnitY(), -1.5};
    op.relax.iterations = 0;
    return op;
}

TEST(Document, ACutThatLeavesASpeckSaysSoInItsDetails) {
    // A cube of 1296 tets and, apart from it, a speck of 0.0125% of the volume; a cut of the cube
    // leaves the speck, and the details point at Remove fragments.
    Document doc(join_meshes(testing::make_cube_mesh(6), testing::make_cube_mesh(1, Eigen::Vector3d(-3, 0, 0), 0.05)),
                 material_preset("marble"));
    for (const bool exact : {false, true}) {
        PlaneCutOp cut = plane_cut(0.55);
        cut.exact = exact;
        const ChangeReport report = doc.apply(cut);
        EXPECT_NE(report.details.find("left 1 detached part under 0.1% of the volume (6 tets; Edit > Remove fragments"),
                  std::string::npos)
            << report.details;
        doc.undo();
    }
    // Without the speck, no such note.
    Document plain(test_cube(), material_preset("marble"));
    EXPECT_EQ(plain.apply(plane_cut(0.55)).details.find("detached"), std::string::npos);
}

TEST(Document, RemovingFragmentsDropsTheSpeckAndUndoesBitForBit) {
    Document doc(u_with_a_short_arm(), material_preset("marble"));
    doc.apply(cut_the_bridge());
    const TetMesh cut = doc.mesh();
    ASSERT_EQ(cut.tet_count(), 6u * 12u);

    // Under the arm's 1/6: nothing to remove, nothing changes.
    const ChangeReport none = doc.apply(RemoveFragmentsOp{0.1});
    EXPECT_FALSE(none.anything_changed());
    EXPECT_EQ(doc.mesh(), cut);
    EXPECT_NE(none.details.find("0 fragments removed"), std::string::npos) << none.details;

    const ChangeReport removed = doc.apply(RemoveFragmentsOp{0.2});
    EXPECT_TRUE(removed.topology);
    EXPECT_EQ(removed.tets_after, 6u * 10u);
    EXPECT_NE(removed.details.find("1 fragments removed (12 tets), 1 part kept"), std::string::npos)
        << removed.details;
    ASSERT_EQ(removed.old_to_new_vertex.size(), cut.vertex_count());
    for (size_t v = 0; v < cut.vertex_count(); ++v) {
        const int32_t w = removed.old_to_new_vertex[v];
        if (w >= 0) {
            EXPECT_EQ(doc.mesh().positions[static_cast<size_t>(w)], cut.positions[v]);
        } else {
            EXPECT_GT(cut.positions[v].x(), 5.0) << v;  // only the short arm's vertices go
        }
    }
    const TetMesh after = doc.mesh();
    ASSERT_TRUE(doc.undo());
    EXPECT_EQ(doc.mesh(), cut);
    ASSERT_TRUE(doc.redo());
    EXPECT_EQ(doc.mesh(), after);

    EXPECT_THROW(doc.apply(RemoveFragmentsOp{1.0}), InvalidArgumentError);
    EXPECT_EQ(doc.mesh(), after);
}

TEST(Document, LongUndoRedoSequencesRetraceTheSameStates) {
    Document doc(test_cube(), material_preset("marble"));
    std::vector<TetMesh> states = {doc.mesh()};
    const std::vector<EditOperation> ops = {paint_at({0.2, 0.2, 0.2}), plane_cut(0.7), paint_at({0.4, 0.5, 0.5}),
                                            plane_cut(0.5), SetMaterialOp{material_preset("skin1"), 0}};
    for (const auto& op : ops) {
        doc.apply(op);
        states.push_back(doc.mesh());
    }
    // Down to the start, up two, down one, up to the end.
    for (int i = static_cast<int>(ops.size()) - 1; i >= 0; --i) {
        ASSERT_TRUE(doc.undo());
        EXPECT_TRUE(doc.mesh() == states[i]) << i;
    }
    EXPECT_FALSE(doc.undo());
    EXPECT_TRUE(doc.history().empty());
    doc.redo();
    doc.redo();
    EXPECT_TRUE(doc.mesh() == states[2]);
    doc.undo();
    EXPECT_TRUE(doc.mesh() == states[1]);
    while (doc.redo()) {
    }
    EXPECT_TRUE(doc.mesh() == states.back());
    EXPECT_EQ(doc.history().size(), ops.size());
    // A new operation clears the redo stack.
    doc.undo();
    doc.undo();
    EXPECT_EQ(doc.redo_count(), 2u);
    doc.apply(paint_at({0.1, 0.1, 0.1}));
    EXPECT_EQ(doc.redo_count(), 0u);
    EXPECT_FALSE(doc.redo());
    EXPECT_EQ(doc.history().size(), ops.size() - 1);
}

TEST(Document, BudgetDropsTheOldestEntries) {
    // Measure one cut's snapshot, then allow about two of them.
    Document probe(test_cube(), material_preset("marble"));
    probe.apply(plane_cut(0.9));
    const size_t cut_bytes = probe.undo_bytes();
    ASSERT_GT(cut_bytes, probe.mesh().tet_count() * sizeof(Tet));

    Document doc(test_cube(), material_preset("marble"), cut_bytes * 2 + cut_bytes / 2);
    const TetMesh start = doc.mesh();
    doc.apply(plane_cut(0.9));
    const TetMesh after_first = doc.mesh();
    doc.apply(plane_cut(0.8));
    EXPECT_EQ(doc.evicted_undo_count(), 0u);
    const ChangeReport third = doc.apply(plane_cut(0.7));
    EXPECT_EQ(third.undo_entries_evicted, 1u);
    EXPECT_EQ(doc.evicted_undo_count(), 1u);
    EXPECT_LE(doc.undo_bytes(), doc.undo_budget_bytes());
    EXPECT_EQ(doc.undo_count(), 2u);
    ASSERT_TRUE(doc.undo());
    ASSERT_TRUE(doc.undo());
    EXPECT_TRUE(doc.mesh() == after_first);
    EXPECT_FALSE(doc.undo());  // the first cut's entry was dropped
    EXPECT_FALSE(doc.mesh() == start);
    EXPECT_EQ(doc.history().size(), 1u);  // the dropped edit is still part of the record

    // An entry larger than the whole budget is not kept.
    Document tiny(test_cube(), material_preset("marble"), 64);
    const ChangeReport r = tiny.apply(plane_cut(0.9));
    EXPECT_FALSE(r.undoable);
    EXPECT_FALSE(tiny.can_undo());
}

TEST(Document, PaintUndoDataIsACompactDelta) {
    Document doc(test_cube(), material_preset("marble"));
    const ChangeReport r = doc.apply(paint_at({0.5, 0.5, 0.5}));
    EXPECT_LT(doc.undo_bytes(), 1024 + r.changed_material_tets.size() * (sizeof(int32_t) + sizeof(TetMaterial)) * 2);
}

TEST(Document, AFailedOperationChangesNothing) {
    Document doc(test_cube(), material_preset("marble"));
    doc.apply(paint_at({0.5, 0.5, 0.5}));
    const TetMesh before = doc.mesh();
    StrokeCutOp behind;  // stroke points behind the eye: StrokeCut rejects them
    behind.stroke = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, -1),
                     {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 1)}, false};
    EXPECT_THROW(doc.apply(behind), InvalidArgumentError);
    PaintOp bad = paint_at({0.5, 0.5, 0.5});
    bad.sigma = 0;
    EXPECT_THROW(doc.apply(bad), InvalidArgumentError);
    EXPECT_THROW(doc.apply(SetMaterialOp{material_preset("marble"), 7}), InvalidArgumentError);
    PlaneCutOp exact = plane_cut(0.5);
    exact.relax.step = -1;
    EXPECT_THROW(doc.apply(exact), InvalidArgumentError);
    EXPECT_TRUE(doc.mesh() == before);
    EXPECT_EQ(doc.history().size(), 1u);
    EXPECT_EQ(doc.undo_count(), 1u);
}

}  // namespace
}  // namespace waxwork
