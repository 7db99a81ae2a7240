// `waxwork cut`, `fracture` and `paint` edit through Document (scene/document.h), as the editor and
// sessions do: each command writes bit for bit the volume Document::apply makes of the same input with
// the operation its options stand for, and its summary carries that operation's own counts
// (ChangeReport::result). A command that applied the tetops algorithms itself, or mapped an option
// to a different operation field, would drift from the editor and the sessions and fail here.
#include "io/volume_file.h"
#include "scene/document.h"
#include "solver/material.h"
#include "support/cli_run.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace waxwork {
namespace {

using testing::run_waxwork;
using testing::scratch_dir;
namespace fs = std::filesystem;

// The cube with a different material on every few tets, so a command that lost or reordered them shows.
TetMesh cube_with_materials() {
    TetMesh mesh = testing::make_cube_mesh(6);
    const std::vector<std::string> names = material_preset_names();
    for (size_t t = 0; t < mesh.tet_count(); ++t) mesh.materials.push_back(material_preset(names[(t / 7) % names.size()]));
    return mesh;
}

struct Applied {
    TetMesh mesh;
    std::vector<ChangeReport> reports;
};

// What the editor and sessions make of `input` with `ops`; a volume without materials is compared
// without them (the command writes none it was not given).
Applied apply_in_document(const TetMesh& input, const std::vector<EditOperation>& ops, bool write_base = false,
                          const TetMaterial& base = TetMaterial{}) {
    Document document(input, base);
    Applied applied;
    for (const EditOperation& op : ops) applied.reports.push_back(document.apply(op));
    applied.mesh = document.mesh();
    if (!input.has_materials() && !write_base) applied.mesh.materials.clear();
    return applied;
}

// Runs `waxwork ARGS` on `input` (written to DIR/in.vtu) and returns the volume it wrote and its summary.
std::pair<TetMesh, nlohmann::json> run_on(const fs::path& dir, const TetMesh& input, const std::string& command,
                                          const std::string& args) {
    const fs::path in = dir / "in.vtu", out = dir / "out.vtu";
    write_volume(input, in);
    fs::remove(out);
    const auto r = run_waxwork(command + " " + in.string() + " -o " + out.string() + " " + args);
    EXPECT_EQ(r.exit_code, 0) << command << " " << args << ": " << r.err;
    if (r.exit_code != 0) return {};
    return {read_volume(out), nlohmann::json::parse(r.out)};
}

PlaneCutOp plane_cut(const Eigen::Vector3d& normal, double offset) {
    PlaneCutOp op;
    op.plane = {normal, offset};
    return op;
}

TEST(EditCommands, CutWritesWhatTheDocumentMakes) {
    const auto dir = scratch_dir("edit_commands_cut");
    const Eigen::Vector3d normal(1, 0.2, 0.1);
    PlaneCutOp relaxed = plane_cut(normal, 0.55);
    relaxed.relax.iterations = 4;
    PlaneCutOp unguarded = plane_cut(normal, 0.55);
    unguarded.relax.iterations = 30;
    unguarded.relax.guard_deg = 0;
    PlaneCutOp exact = plane_cut(normal, 0.55);
    exact.exact = true;
    const std::vector<std::pair<std::string, PlaneCutOp>> cases = {
        {"--plane=1,0.2,0.1,0.55 --relax 4", relaxed},
        {"--plane=1,0.2,0.1,0.55 --relax 30 --no-guard", unguarded},
        {"--plane=1,0.2,0.1,0.55 --exact", exact},
    };
    for (const TetMesh& input : {testing::make_cube_mesh(6), cube_with_materials()}) {
        for (const auto& [args, op] : cases) {
            SCOPED_TRACE(args + (input.has_materials() ? " (materials)" : ""));
            const auto [written, summary] = run_on(dir, input, "cut", args);
            const Applied expected = apply_in_document(input, {op});
            EXPECT_TRUE(written == expected.mesh);
            EXPECT_EQ(written.has_materials(), input.has_materials());
            const ChangeReport& report = expected.reports.front();
            EXPECT_EQ(summary["tets_after"], report.tets_after);
            EXPECT_EQ(summary["min_dihedral_deg"], report.min_dihedral_deg);
            if (op.exact) {
                const auto& cut = std::get<ExactCutResult>(report.result);
                EXPECT_EQ(summary["tets_split"], cut.tets_split);
                EXPECT_EQ(summary["vertices_snapped"], cut.vertices_snapped);
                EXPECT_EQ(summary["vertices_added"], cut.vertices_added);
                EXPECT_EQ(summary["vertices_smoothed"], cut.vertices_smoothed);
                EXPECT_GT(cut.tets_split, 0u);
            } else {
                const auto& cut = std::get<RelaxedCutResult>(report.result);
                EXPECT_EQ(summary["tets_removed"], cut.removal.tets_removed);
                EXPECT_EQ(summary["relax_iterations"], cut.relaxation.iterations);
                EXPECT_EQ(summary["vertices_moved"], cut.relaxation.vertices_moved);
                EXPECT_EQ(summary["moves_rejected"], cut.relaxation.moves_rejected);
                EXPECT_EQ(summary["guard_deg"], op.relax.guard_deg);
                EXPECT_GT(cut.relaxation.vertices_moved, 0u);
            }
        }
    }
}

TEST(EditCommands, CutThenRemoveFragmentsWritesWhatTheDocumentMakes) {
    const auto dir = scratch_dir("edit_commands_fragments");
    // A U whose bridge the cut removes (as CutCommand.RemoveFragmentsDropsTheShortArmACutLeavesOfAU).
    const TetMesh u = testing::make_cell_mesh(7, 6, 2, [](int i, int j, int) { return j == 0 || i == 0 || (i == 6 && j <= 1); });
    for (const bool exact : {false, true}) {
        SCOPED_TRACE(exact ? "exact" : "relax");
        PlaneCutOp cut = plane_cut(Eigen::Vector3d(0, -1, 0), -1.5);
        cut.exact = exact;
        const auto [written, summary] =
            run_on(dir, u, "cut", std::string("--plane=0,-1,0,-1.5 --remove-fragments 0.2") + (exact ? " --exact" : ""));
        const Applied expected = apply_in_document(u, {cut, RemoveFragmentsOp{0.2}});
        EXPECT_TRUE(written == expected.mesh);
        const auto& removal = std::get<FragmentRemoval>(expected.reports.back().result);
        EXPECT_EQ(removal.fragments_removed, 1u);
        EXPECT_EQ(summary["fragments_removed"], removal.fragments_removed);
        EXPECT_EQ(summary["fragment_tets_removed"], removal.removed.tets_removed);
        EXPECT_EQ(summary["components"], removal.parts_kept);
    }
}

TEST(EditCommands, FractureWritesWhatTheDocumentMakes) {
    const auto dir = scratch_dir("edit_commands_fracture");
    FractureOp fracture;
    fracture.pieces = 5;
    fracture.seed = 3;
    FractureOp faces = fracture;
    faces.exact = false;
    faces.min_piece_tets = 3;
    faces.seed = 1;  // the command's default seed
    FractureOp kept = fracture;
    kept.pieces = 12;
    kept.collapse = false;
    const std::vector<std::pair<std::string, FractureOp>> cases = {
        {"--pieces 5 --seed 3", fracture},
        {"--pieces 5 --no-exact --min-piece-tets 3", faces},
        {"--pieces 12 --seed 3 --no-collapse", kept},
    };
    for (const TetMesh& input : {testing::make_cube_mesh(6), cube_with_materials()}) {
        for (const auto& [args, op] : cases) {
            SCOPED_TRACE(args + (input.has_materials() ? " (materials)" : ""));
            const auto [written, summary] = run_on(dir, input, "fracture", args);
            const Applied expected = apply_in_document(input, {op});
            EXPECT_TRUE(written == expected.mesh);
            EXPECT_EQ(written.has_materials(), input.has_materials());
            const auto& result = std::get<FractureResult>(expected.reports.front().result);
            EXPECT_EQ(summary["pieces_before"], result.pieces_before);
            EXPECT_EQ(summary["pieces"], result.pieces_after);
            EXPECT_EQ(summary["tets_split"], result.tets_split);
            EXPECT_EQ(summary["vertices_collapsed"], result.vertices_collapsed);
            EXPECT_EQ(summary["vertices_duplicated"], result.vertices_duplicated);
            EXPECT_EQ(summary["tets_under_guard"], result.tets_under_guard);
            EXPECT_EQ(summary["min_dihedral_deg"], result.min_dihedral_deg);
            EXPECT_GT(result.pieces_after, 1);
        }
    }
}

TEST(EditCommands, PaintWritesWhatTheDocumentMakes) {
    const auto dir = scratch_dir("edit_commands_paint");
    PaintOp op;
    op.points = {Eigen::Vector3d(0.3, 0.3, 0.3), Eigen::Vector3d(0.5, 0.4, 0.5)};
    op.material = material_preset("ketchup");
    op.sigma = 0.1;
    for (const TetMesh& input : {testing::make_cube_mesh(6), cube_with_materials()}) {
        SCOPED_TRACE(input.has_materials() ? "materials" : "no materials");
        const auto [written, summary] =
            run_on(dir, input, "paint", "--at '0.3,0.3,0.3;0.5,0.4,0.5' --material ketchup --sigma 0.1 --base skin1");
        // Without materials the volume starts from --base, and the painted volume keeps them.
        const Applied expected = apply_in_document(input, {op}, /*write_base=*/true, material_preset("skin1"));
        EXPECT_TRUE(written == expected.mesh);
        EXPECT_TRUE(written.has_materials());
        const ChangeReport& report = expected.reports.front();
        EXPECT_GT(report.changed_material_tets.size(), 0u);
        EXPECT_EQ(summary["tets_changed"], report.changed_material_tets.size());
        EXPECT_EQ(summary["stroke_points"], 2);
    }
}

}  // namespace
}  // namespace waxwork
