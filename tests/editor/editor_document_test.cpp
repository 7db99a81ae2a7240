// Document safety and the start screen, end to end under a virtual X server: the unsaved-changes
// dialog before quitting, the recovery copy a killed run leaves and the next run recovers, the start
// screen's examples; and the recent-files list's rules.
#include "io/volume_file.h"
#include "scene/recent_files.h"
#include "scene/recovery_files.h"
#include "editor_window_fixture.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace waxwork {
namespace {

using namespace testing;
namespace fs = std::filesystem;

class EditorDocument : public WindowTest {};

// Runs `waxwork edit [FILE]` with `script`, its state (recent files, recovery) in DIR/state.
CommandResult edit_with_state(const fs::path& dir, const std::string& file, const std::string& script,
                              const std::string& options = "--hide-ui --width 400 --height 300") {
    std::ofstream(dir / "input.json") << script;
    return run_under_xvfb("edit " + file + " " + options + " --input " + (dir / "input.json").string() +
                              " --frames 2 --screenshot " + (dir / "shot.png").string(),
                          "WAXWORK_STATE_DIR=" + (dir / "state").string() + " ");
}

const std::string kCube = kAssets + "/meshes/cube.obj --max-tets 6000 --view 0,0,1";
// A stroke down the middle of the cube cuts its +x half away (as in editor_window_test.cpp).
const std::string kCut = R"({"event": "tool", "tool": "cut"},
    {"frame": 2, "event": "drag", "from": [200, 20], "to": [200, 280], "steps": 10},
    {"event": "idle"},)";

size_t recovery_folders(const fs::path& state) {
    size_t n = 0;
    std::error_code error;
    for (fs::directory_iterator it(state / "recovery", error), end; !error && it != end; it.increment(error)) ++n;
    return n;
}

// Ctrl+Q and the close button ask first when there are unsaved edits; Cancel keeps the window running
// with the edits, Save writes them and then quits, and nothing queued after the quit runs.
TEST_F(EditorDocument, QuitWithUnsavedEditsAsksAndSaveKeepsThem) {
    const fs::path dir = scratch_dir("editor_quit_prompt");
    const auto r = edit_with_state(dir, kCube, "[" + kCut + R"(
        {"event": "key", "key": "Q", "mods": ["ctrl"]},
        {"event": "dialog", "button": "cancel"},
        {"event": "close_window"},
        {"event": "dialog", "button": "cancel"},
        {"event": "quit"},
        {"event": "dialog", "button": "save", "file": "saved.json"},
        {"event": "idle"},
        {"event": "save_volume", "file": "after_quit.vtu"},
        {"event": "idle"}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_TRUE(fs::exists(dir / "saved.json")) << "the dialog's Save should write the session before quitting";
    EXPECT_FALSE(fs::exists(dir / "after_quit.vtu")) << "the window should have closed after saving";
    EXPECT_FALSE(fs::exists(dir / "shot.png"));
    EXPECT_EQ(summary_of(r)["modified"], false);
    EXPECT_EQ(summary_of(r)["title"], "Waxwork - cube.obj");
    // The saved session replays to the cut volume.
    const auto run = run_waxwork("run " + (dir / "saved.json").string() + " -o " + (dir / "run").string());
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const TetMesh replayed = read_volume(dir / "run" / "saved.vtu");
    const auto whole = run_waxwork("mesh " + kAssets + "/meshes/cube.obj --max-tets 6000 -o " + (dir / "whole.vtu").string());
    ASSERT_EQ(whole.exit_code, 0) << whole.err;
    EXPECT_LT(replayed.tet_count(), 0.7 * read_volume(dir / "whole.vtu").tet_count());
    // Recent files: the session saved is the first.
    const RecentFiles recent = read_recent_files(dir / "state" / "recent.json");
    ASSERT_FALSE(recent.files.empty());
    EXPECT_EQ(recent.files.front(), dir / "saved.json");
    EXPECT_EQ(recent.output_folder, dir);
    EXPECT_EQ(recovery_folders(dir / "state"), 0u) << "a clean exit leaves no recovery copy";
}

// Discard quits without writing; an unmodified document quits at once, without a dialog to answer.
TEST_F(EditorDocument, DiscardQuitsWithoutSavingAndAnUnmodifiedDocumentQuitsAtOnce) {
    const fs::path dir = scratch_dir("editor_quit_discard");
    const auto discarded = edit_with_state(dir, kCube, "[" + kCut + R"(
        {"event": "quit"},
        {"event": "dialog", "button": "discard"},
        {"event": "save_volume", "file": "after_quit.vtu"},
        {"event": "idle"}])");
    ASSERT_EQ(discarded.exit_code, 0) << discarded.err;
    EXPECT_EQ(summary_of(discarded)["modified"], true);
    EXPECT_EQ(summary_of(discarded)["title"], "Waxwork - cube.obj *");
    EXPECT_FALSE(fs::exists(dir / "after_quit.vtu"));
    const auto unmodified = edit_with_state(dir, kCube, R"([{"frame": 1, "event": "quit"},
        {"event": "save_volume", "file": "after_quit.vtu"}, {"event": "idle"}])");
    ASSERT_EQ(unmodified.exit_code, 0) << unmodified.err;
    EXPECT_FALSE(fs::exists(dir / "after_quit.vtu"));
    // Answering a dialog nobody shows is an error.
    const auto unasked = edit_with_state(dir, kCube, R"([{"frame": 1, "event": "dialog", "button": "save"}, {"event": "idle"}])");
    EXPECT_NE(unasked.exit_code, 0);
    EXPECT_NE(unasked.err.find("no unsaved-changes dialog"), std::string::npos) << unasked.err;
}

// A run killed after its autosave leaves its recovery copy (the cut volume, and a session that
// replays to it); the next run offers it and Recover opens the edited volume exactly as it was.
TEST_F(EditorDocument, AutosavedVolumeIsRecoveredAfterAKill) {
    const fs::path dir = scratch_dir("editor_recovery");
    const auto killed = edit_with_state(dir, kCube, "[" + kCut + R"(
        {"event": "autosave"},
        {"event": "idle"},
        {"event": "kill"},
        {"event": "save_volume", "file": "not_reached.vtu"}])");
    EXPECT_NE(killed.exit_code, 0) << "the run should have been killed";
    EXPECT_FALSE(fs::exists(dir / "not_reached.vtu"));
    const std::vector<RecoveryFiles> left = abandoned_recovery_files(dir / "state");
    ASSERT_EQ(left.size(), 1u) << killed.err;
    EXPECT_EQ(recovered_source(left.front()), kAssets + "/meshes/cube.obj");
    const TetMesh expected = read_volume(left.front().volume());
    const auto whole = run_waxwork("mesh " + kAssets + "/meshes/cube.obj --max-tets 6000 -o " + (dir / "whole.vtu").string());
    ASSERT_EQ(whole.exit_code, 0) << whole.err;
    EXPECT_LT(expected.tet_count(), 0.7 * read_volume(dir / "whole.vtu").tet_count()) << "the copy should hold the cut";
    const auto replay = run_waxwork("run " + left.front().session().string() + " -o " + (dir / "replay").string());
    ASSERT_EQ(replay.exit_code, 0) << replay.err;
    EXPECT_TRUE(read_volume(dir / "replay" / "session.vtu") == expected);

    const auto recovered = edit_with_state(dir, "", R"([{"event": "recover"}, {"event": "idle"},
        {"event": "save_volume", "file": "recovered.vtu"}, {"event": "idle"}])");
    ASSERT_EQ(recovered.exit_code, 0) << recovered.err;
    EXPECT_TRUE(read_volume(dir / "recovered.vtu") == expected);
    EXPECT_EQ(summary_of(recovered)["tets"], expected.tet_count());
    EXPECT_EQ(recovery_folders(dir / "state"), 0u) << "recovered, then saved and a clean exit: nothing left to offer";

    // A copy that a save made stale is removed even when the run dies afterwards.
    const auto saved = edit_with_state(dir, kCube, "[" + kCut + R"(
        {"event": "autosave"}, {"event": "idle"},
        {"event": "save_volume", "file": "saved.vtu"}, {"event": "idle"}, {"event": "kill"}])");
    ASSERT_TRUE(fs::exists(dir / "saved.vtu")) << saved.err;
    EXPECT_EQ(recovery_folders(dir / "state"), 0u);

    // Nothing left: Recover is an error.
    const auto nothing = edit_with_state(dir, "", R"([{"event": "recover"}, {"event": "idle"}])");
    EXPECT_NE(nothing.exit_code, 0);
    EXPECT_NE(nothing.err.find("no recovery files"), std::string::npos) << nothing.err;
}

// The copy is written on its own once edits have stayed unsaved for --autosave seconds, and not
// without edits. Each scripted frame lasts at least 20 ms, so frame 200 comes 4 s or more after the
// start: well past the 1 s interval.
TEST_F(EditorDocument, AutosaveCopiesUnsavedEditsAfterTheInterval) {
    const fs::path dir = scratch_dir("editor_autosave_interval");
    const std::string options = "--hide-ui --width 400 --height 300 --autosave 1";
    const auto edited = edit_with_state(dir, kCube, "[" + kCut + R"( {"frame": 200, "event": "kill"}])", options);
    EXPECT_NE(edited.exit_code, 0);
    EXPECT_EQ(abandoned_recovery_files(dir / "state").size(), 1u) << edited.err;
    fs::remove_all(dir / "state");
    const auto untouched = edit_with_state(dir, kCube, R"([{"frame": 200, "event": "kill"}])", options);
    EXPECT_NE(untouched.exit_code, 0);
    EXPECT_EQ(recovery_folders(dir / "state"), 0u) << untouched.err;
}

// With no file the start screen shows; its example opens meshed, at the scale the model's size
// suggests and seen from its front (spot.obj faces -z), and joins the recent files.
TEST_F(EditorDocument, StartScreenExampleOpensAndMeshesTheModel) {
    const fs::path dir = scratch_dir("editor_start_screen");
    const auto start = run_under_xvfb("edit --width 800 --height 500 --frames 2 --screenshot " + (dir / "start.png").string(),
                                      "WAXWORK_STATE_DIR=" + (dir / "state").string() + " ");
    ASSERT_EQ(start.exit_code, 0) << start.err;
    const Image image = read_png(dir / "start.png");
    // The start panel in the middle of the empty view: brighter text and buttons on the dark background.
    EXPECT_GT(mean_brightness(image, 300, 150, 500, 350), mean_brightness(image, 150, 440, 170, 460) + 10);

    const auto r = edit_with_state(dir, "", R"([{"event": "open_example", "name": "spot"}, {"event": "idle"},
        {"event": "save_session", "file": "spot.json"}, {"event": "idle"}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json summary = summary_of(r);
    EXPECT_GT(summary["tets"].get<size_t>(), 5000u);
    EXPECT_EQ(summary["mm_per_unit"], 30.0);  // `waxwork mesh spot.obj` chooses the same
    std::ifstream in(dir / "spot.json");
    const nlohmann::json session = nlohmann::json::parse(in);
    const auto& eye = session["camera"]["eye_direction"];
    EXPECT_LT(eye[2].get<double>(), 0) << "spot faces -z: the first view looks at its front from -z";
    EXPECT_LT(eye[0].get<double>(), 0);
    const RecentFiles recent = read_recent_files(dir / "state" / "recent.json");
    ASSERT_EQ(recent.files.size(), 2u);
    EXPECT_EQ(recent.files[0], dir / "spot.json");
    EXPECT_EQ(recent.files[1].filename(), "spot.obj");

    const auto unknown = edit_with_state(dir, "", R"([{"event": "open_example", "name": "teapot"}, {"event": "idle"}])");
    EXPECT_NE(unknown.exit_code, 0);
    EXPECT_NE(unknown.err.find("spot"), std::string::npos) << unknown.err;  // names the examples there are
}

TEST(RecentFiles, MostRecentFirstWithoutDuplicatesAtMostTen) {
    RecentFiles recent;
    for (int i = 0; i < 12; ++i) remember_file(recent, "/models/m" + std::to_string(i) + ".obj");
    ASSERT_EQ(recent.files.size(), RecentFiles::kMaxFiles);
    EXPECT_EQ(recent.files.front(), "/models/m11.obj");
    EXPECT_EQ(recent.files.back(), "/models/m2.obj");
    remember_file(recent, "/models/./m5.obj");
    EXPECT_EQ(recent.files.front(), "/models/m5.obj");
    EXPECT_EQ(recent.files.size(), RecentFiles::kMaxFiles);
    EXPECT_EQ(std::count(recent.files.begin(), recent.files.end(), fs::path("/models/m5.obj")), 1);
}

TEST(RecentFiles, ReadingDropsMissingFilesAndSurvivesABrokenList) {
    const fs::path dir = scratch_dir("recent_files");
    std::ofstream(dir / "a.obj") << "v 0 0 0\n";
    std::ofstream(dir / "b.vtu") << "x";
    RecentFiles recent;
    remember_file(recent, dir / "a.obj");
    remember_file(recent, dir / "gone.obj");
    remember_file(recent, dir / "b.vtu");
    recent.output_folder = dir;
    write_recent_files(dir / "state" / "recent.json", recent);
    const RecentFiles read = read_recent_files(dir / "state" / "recent.json");
    ASSERT_EQ(read.files.size(), 2u);
    EXPECT_EQ(read.files[0], dir / "b.vtu");
    EXPECT_EQ(read.files[1], dir / "a.obj");
    EXPECT_EQ(read.output_folder, dir);
    std::ofstream(dir / "broken.json") << "{\"files\": [1, ";
    EXPECT_TRUE(read_recent_files(dir / "broken.json").files.empty());
    EXPECT_TRUE(read_recent_files(dir / "missing.json").files.empty());
}

TEST(RecentFiles, StateDirectoryFollowsTheEnvironment) {
    const char* saved = std::getenv("WAXWORK_STATE_DIR");
    const std::string kept = saved ? saved : "";
    ::setenv("WAXWORK_STATE_DIR", "/tmp/waxwork-own", 1);
    EXPECT_EQ(state_directory(), "/tmp/waxwork-own");
    ::unsetenv("WAXWORK_STATE_DIR");
    ::setenv("XDG_STATE_HOME", "/tmp/xdg-state", 1);
    EXPECT_EQ(state_directory(), "/tmp/xdg-state/waxwork");
    ::unsetenv("XDG_STATE_HOME");
    if (const char* home = std::getenv("HOME")) {
        EXPECT_EQ(state_directory(), fs::path(home) / ".local/state/waxwork");
    }
    if (saved) ::setenv("WAXWORK_STATE_DIR", kept.c_str(), 1);
}

}  // namespace
}  // namespace waxwork
