// `waxwork deform`: drags the grabbed body, moves only positions, keeps every tet valid (shortening
// absurd steps and saying so), writes what it reports, and refuses bad options in one line.
#include "io/volume_file.h"
#include "support/cli_run.h"
#include "support/scratch_dir.h"
#include "tetops/box_mesh.h"
#include "tetops/quality.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <string>

namespace waxwork {
namespace {

using testing::line_count;
using testing::run_waxwork;
using testing::scratch_dir;
namespace fs = std::filesystem;

// A 4 x 1 x 1 bar with a material per tet, so the test sees materials stay with their tets.
TetMesh painted_bar() {
    TetMesh bar = make_box_mesh({16, 4, 4}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 1, 1));
    for (size_t t = 0; t < bar.tet_count(); ++t) {
        TetMaterial m;
        m.mua = {0.001 * static_cast<double>(t % 7), 0.01, 0.01};
        m.musp = {1, 1, 1};
        m.eta = 1.3;
        bar.materials.push_back(m);
    }
    return bar;
}

TEST(DeformCommand, DragsTheEndAndKeepsEverythingButPositions) {
    const auto dir = scratch_dir("deform_command");
    const TetMesh bar = painted_bar();
    write_volume(bar, dir / "in.vtu");
    const auto r = run_waxwork("deform " + (dir / "in.vtu").string() + " -o " + (dir / "out.vtu").string() +
                               " --grab 4,0.5,0.5 --radius 1 --move 0,0.8,0.3 --pin 0,0.5,0.5:0.6 --iterations 8 --steps 4");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_EQ(line_count(r.out), 1u);
    const nlohmann::json summary = nlohmann::json::parse(r.out);
    const TetMesh out = read_volume(dir / "out.vtu");
    EXPECT_EQ(out.tets, bar.tets);
    EXPECT_EQ(out.materials, bar.materials);
    EXPECT_EQ(out.original_ids, bar.original_ids);
    EXPECT_EQ(summary["tets"], bar.tet_count());
    EXPECT_EQ(summary["inverted_tets"], 0);
    EXPECT_EQ(summary["step_shortened"], false);
    EXPECT_EQ(summary["handle_error"], 0.0);
    EXPECT_GT(summary["moved_vertices"].get<int>(), 0);
    EXPECT_GT(summary["pinned_vertices"].get<int>(), 0);
    EXPECT_DOUBLE_EQ(summary["volume_after"].get<double>(), total_volume(out));
    EXPECT_DOUBLE_EQ(summary["min_dihedral_deg"].get<double>(), mesh_min_dihedral_deg(out));
    // The grabbed end moved by the full move at its centre's nearest vertex, the pinned end not at all.
    const int32_t end = box_vertex_index({16, 4, 4}, 16, 2, 2), start = box_vertex_index({16, 4, 4}, 0, 2, 2);
    EXPECT_GT((out.positions[end] - bar.positions[end]).norm(), 0.8);
    EXPECT_EQ(out.positions[start], bar.positions[start]);
}

TEST(DeformCommand, AbsurdMoveIsShortenedAndInvertsNothing) {
    const auto dir = scratch_dir("deform_command_absurd");
    write_volume(painted_bar(), dir / "in.vtu");
    const auto r = run_waxwork("deform " + (dir / "in.vtu").string() + " -o " + (dir / "out.vtu").string() +
                               " --grab 4,0.5,0.5 --radius 1 --move -60,40,0 --pin 0,0.5,0.5:1 --steps 1 --iterations 3");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json summary = nlohmann::json::parse(r.out);
    EXPECT_EQ(summary["step_shortened"], true);
    EXPECT_EQ(summary["inverted_tets"], 0);
    EXPECT_GE(summary["min_dihedral_deg"].get<double>(), 0.5 - 1e-9);
    const TetMesh out = read_volume(dir / "out.vtu");
    for (size_t t = 0; t < out.tet_count(); ++t) ASSERT_GT(signed_volume(out, t), 0) << t;
}

// Bend turns the grabbed end about the elbow axis, Twist about the bar's own axis; both keep every tet.
TEST(DeformCommand, BendsAndTwistsAboutTheGivenAxis) {
    const auto dir = scratch_dir("deform_command_bend");
    const TetMesh bar = painted_bar();
    write_volume(bar, dir / "in.vtu");
    const int32_t end = box_vertex_index({16, 4, 4}, 16, 2, 2);  // (4, 0.5, 0.5), the handle's centre
    for (const std::string motion : {"--bend 2,0.5,0.5:0,0,1:45", "--twist 0,0.5,0.5:1,0,0:10"}) {
        const auto r = run_waxwork("deform " + (dir / "in.vtu").string() + " -o " + (dir / "out.vtu").string() +
                                   " --grab 4,0.5,0.5 --radius 1 " + motion + " --pin 0,0.5,0.5:0.6 --steps 4");
        ASSERT_EQ(r.exit_code, 0) << motion << ": " << r.err;
        const nlohmann::json summary = nlohmann::json::parse(r.out);
        EXPECT_EQ(summary["tool"], motion.substr(2, 4) == "bend" ? "bend" : "twist") << motion;
        EXPECT_EQ(summary["inverted_tets"], 0) << motion;
        EXPECT_EQ(summary["step_shortened"], false) << motion;
        const TetMesh out = read_volume(dir / "out.vtu");
        EXPECT_EQ(out.materials, bar.materials);
        if (motion.substr(2, 4) == "bend") {
            // The handle's centre (weight 1) turned 45 degrees about z through (2, 0.5): to (2 + sqrt 2, 0.5 + sqrt 2).
            EXPECT_LT((out.positions[end] - Eigen::Vector3d(2 + std::sqrt(2.0), 0.5 + std::sqrt(2.0), 0.5)).norm(), 1e-9);
        } else {
            // On the axis: a twist leaves it in place, while the corners of the end turn.
            EXPECT_LT((out.positions[end] - bar.positions[end]).norm(), 1e-9);
            const int32_t corner = box_vertex_index({16, 4, 4}, 16, 1, 1);
            EXPECT_GT((out.positions[corner] - bar.positions[corner]).norm(), 0.05);
        }
    }
}

TEST(DeformCommand, BadInputIsAOneLineErrorNamingTheOption) {
    const auto dir = scratch_dir("deform_command_errors");
    write_volume(painted_bar(), dir / "in.vtu");
    const std::string base = "deform " + (dir / "in.vtu").string() + " -o " + (dir / "out.vtu").string() + " ";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"--grab 4,0.5,nan --radius 1 --move 0,1,0", "--grab"},
        {"--grab 4,0.5,0.5 --radius 0 --move 0,1,0", "--radius"},
        {"--grab 4,0.5,0.5 --radius -2 --move 0,1,0", "--radius"},
        {"--grab 4,0.5,0.5 --radius 1 --move 0,1", "--move"},
        {"--grab 40,0.5,0.5 --radius 1 --move 0,1,0", "no vertex lies within the handle"},
        {"--grab 4,0.5,0.5 --radius 1 --move 0,1,0 --pin 2,0.5,0.5:100", "every vertex of the handle is pinned"},
        {"--grab 4,0.5,0.5 --radius 1 --move 0,1,0 --pin 2,0.5,0.5", "--pin"},
        {"--grab 4,0.5,0.5 --radius 1 --move 0,1,0 --iterations 0", "--iterations"},
        {"--grab 4,0.5,0.5 --radius 1", "exactly one of --move, --bend and --twist"},
        {"--grab 4,0.5,0.5 --radius 1 --move 0,1,0 --bend 2,0.5,0.5:0,0,1:30", "exactly one of"},
        {"--grab 4,0.5,0.5 --radius 1 --bend 2,0.5,0.5:0,0,0:30", "--bend: the axis direction must not be zero"},
        {"--grab 4,0.5,0.5 --radius 1 --twist 2,0.5,0.5:1,0,0", "--twist"},
    };
    for (const auto& [args, expected] : cases) {
        const auto r = run_waxwork(base + args);
        EXPECT_NE(r.exit_code, 0) << args;
        EXPECT_EQ(line_count(r.err), 1u) << args << ": " << r.err;
        EXPECT_NE(r.err.find(expected), std::string::npos) << args << ": " << r.err;
        EXPECT_FALSE(fs::exists(dir / "out.vtu")) << args;
    }
}

}  // namespace
}  // namespace waxwork
