// `waxwork edit` end to end under a virtual X server (xvfb-run): the editor opens a GLFW window with an
// OpenGL 4.5 core context (Mesa llvmpipe through GLX), loads and solves a scene on its worker threads,
// draws, saves a screenshot and exits cleanly; and its 3D view shows exactly what `waxwork render`
// (OSMesa) writes for the same scene.
#include "io/volume_file.h"
#include "support/exported_surface.h"
#include "tetops/connectivity.h"
#include "solver/material.h"
#include "tetops/test_meshes.h"
#include "editor_window_fixture.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>

namespace waxwork {
namespace {

using namespace testing;
namespace fs = std::filesystem;

class EditorWindow : public WindowTest {};

// Draws SCENE (a volume and render's options) with `waxwork render` and in the editor without panels
// (--hide-ui), as DIR/NAME_render.png and DIR/NAME_edit.png, and compares them. Both draw the same
// geometry with Mesa's llvmpipe (OSMesa for render, GLX under Xvfb for the window) through the same
// SurfaceRenderer and camera, so coverage and shading agree exactly. The radiance does not quite:
// render solves phi in one CG run, the editor converges it frame by frame (LiveScene), each stopping
// within the relative tolerance 1e-3, and the automatic exposure follows phi. A relative difference of
// 2e-3 moves an 8-bit sRGB value by under one step, so every channel may differ by at most 1 after
// rounding (2 allowed for the two roundings).
void expect_edit_shows_what_render_writes(const fs::path& dir, const std::string& scene, const std::string& name) {
    const fs::path rendered = dir / (name + "_render.png"), edited = dir / (name + "_edit.png");
    // At the editor's tolerance: render's default (1e-2) leaves up to 5 steps on a torus at 20 mm per unit.
    const auto render = run_waxwork("render " + scene + " --tol 1e-3 -o " + rendered.string());
    ASSERT_EQ(render.exit_code, 0) << name << ": " << render.err;
    const auto edit = run_under_xvfb("edit " + scene + " --hide-ui --frames 2 --screenshot " + edited.string());
    ASSERT_EQ(edit.exit_code, 0) << name << ": " << edit.err;
    const Image a = read_png(rendered), b = read_png(edited);
    ASSERT_EQ(a.width, b.width) << name;
    ASSERT_EQ(a.height, b.height) << name;
    EXPECT_LE(max_channel_difference(a, b), 2) << name;
    EXPECT_GT(mean_brightness(a, 0, 0, a.width, a.height), mean_brightness(a, 0, 0, 20, 20) + 5) << name;  // not empty
}

TEST_F(EditorWindow, OpensRendersSavesAScreenshotAndExits) {
    const fs::path dir = scratch_dir("editor_screenshot");
    const fs::path png = dir / "editor.png";
    const auto r = run_under_xvfb("edit " + kAssets + "/meshes/torus.obj --max-tets 12000 --width 800 --height 500 "
                                  "--screenshot " + png.string() + " --frames 3");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_TRUE(fs::exists(png));
    const Image image = read_png(png);
    EXPECT_EQ(image.width, 800);
    EXPECT_EQ(image.height, 500);
    // Not black, and the 3D view (between the tool palette on the left and the panels on the right)
    // holds a lit object brighter than its background.
    EXPECT_GT(mean_brightness(image, 0, 0, image.width, image.height), 30);
    const double centre = mean_brightness(image, 330, 220, 430, 280);
    const double corner = mean_brightness(image, 150, 440, 170, 460);
    EXPECT_GT(centre, corner + 150) << "centre " << centre << ", background " << corner;
}

TEST_F(EditorWindow, ViewWithoutPanelsEqualsWaxworkRender) {
    const fs::path dir = scratch_dir("editor_equals_render");
    const fs::path volume = dir / "torus.vtu";
    ASSERT_EQ(run_waxwork("mesh " + kAssets + "/meshes/torus.obj -o " + volume.string() + " --max-tets 12000").exit_code, 0);
    expect_edit_shows_what_render_writes(
        dir, volume.string() + " --width 320 --height 240 --view 0.3,0.8,0.6 --material skin1", "radiance");
}

// A volume opens at the scale it stores, a surface at the model's default, and --scale wins over both.
TEST_F(EditorWindow, OpensAtTheStoredScaleElseTheModelsElseTheGivenOne) {
    const fs::path dir = scratch_dir("editor_scale");
    const fs::path volume = dir / "torus.vtu";
    ASSERT_EQ(run_waxwork("mesh " + kAssets + "/meshes/torus.obj -o " + volume.string() + " --max-tets 12000 --scale 7")
                  .exit_code,
              0);
    const std::string window = " --hide-ui --width 160 --height 120 --frames 1 --screenshot " + (dir / "s.png").string();
    const auto stored = run_under_xvfb("edit " + volume.string() + window);
    ASSERT_EQ(stored.exit_code, 0) << stored.err;
    EXPECT_EQ(summary_of(stored)["mm_per_unit"], 7.0);
    const auto given = run_under_xvfb("edit " + volume.string() + " --scale 12" + window);
    ASSERT_EQ(given.exit_code, 0) << given.err;
    EXPECT_EQ(summary_of(given)["mm_per_unit"], 12.0);
    // torus.obj is 2.5 x 0.5 x 2.5 units: a 3.57-unit diagonal, 20 mm per unit.
    const auto surface = run_under_xvfb("edit " + kAssets + "/meshes/torus.obj --max-tets 12000" + window);
    ASSERT_EQ(surface.exit_code, 0) << surface.err;
    EXPECT_EQ(summary_of(surface)["mm_per_unit"], 20.0);
}

TEST_F(EditorWindow, EveryOptionalViewEqualsWaxworkRenderShow) {
    // The optional views (view_modes.h) are built by the same functions in both commands; the editor
    // builds them on its worker from the live scene. Same tolerance argument as above (the slice's
    // colours follow phi on a log scale, which moves them less than the radiance).
    const fs::path dir = scratch_dir("editor_views_equal_render");
    const fs::path volume = dir / "torus.vtu";
    ASSERT_EQ(run_waxwork("mesh " + kAssets + "/meshes/torus.obj -o " + volume.string() + " --max-tets 12000").exit_code, 0);
    for (const std::string show : {"materials", "quality", "quality --quality-interior --slice-normal 0,1,0", "wireframe",
                                   "slice --slice-normal 1,0,0.3 --slice-offset 0.2", "levels"}) {
        std::string name = show;
        for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
        expect_edit_shows_what_render_writes(
            dir, volume.string() + " --width 320 --height 240 --view 0.3,0.8,0.6 --show " + show, name);
    }
}

TEST(EditorWithoutDisplay, BadViewOptionsAreRefusedWithOneLine) {
    for (const std::string bad : {"--show normals", "--show slice --slice-offset -3", "--show slice --slice-normal 1,2"}) {
        const auto r = run_waxwork("edit " + kAssets + "/meshes/cube.obj --screenshot /dev/null " + bad);
        EXPECT_NE(r.exit_code, 0) << bad;
        EXPECT_EQ(testing::line_count(r.err), 1u) << bad << ": " << r.err;
        EXPECT_NE(r.err.find("slice"), std::string::npos) << r.err;  // names the option's domain
    }
}

// The crease angle decides which vertices are split and which light the solve integrates, so the
// editor must show what `waxwork render --crease-angle` writes whether the angle comes from the command
// line or from the View panel while the scene is open (a scripted slider change, solved on warm), and a
// saved session must keep it. The editor keeps the exposure of its first converged image, so after
// the change it is compared with render at that image's exposure.
TEST_F(EditorWindow, CreaseAngleFromTheCommandLineOrTheViewPanelEqualsWaxworkRender) {
    const fs::path dir = scratch_dir("editor_crease_angle");
    const fs::path cube = dir / "cube.vtu", volume = dir / "cut.vtu";
    ASSERT_EQ(run_waxwork("mesh " + kAssets + "/meshes/cube.obj -o " + cube.string() + " --max-tets 4000").exit_code, 0);
    ASSERT_EQ(run_waxwork("cut " + cube.string() + " -o " + volume.string() + " --plane=1,1,1,1.2 --exact").exit_code, 0);
    const std::string scene = volume.string() + " --width 240 --height 180";
    const fs::path folded = dir / "render40.png", smooth = dir / "render180.png", kept = dir / "render180_kept.png";
    const auto first = run_waxwork("render " + scene + " -o " + folded.string());
    ASSERT_EQ(first.exit_code, 0) << first.err;
    const double exposure40 = nlohmann::json::parse(first.out)["exposure"].get<double>();
    ASSERT_EQ(run_waxwork("render " + scene + " --crease-angle 180 -o " + smooth.string()).exit_code, 0);
    ASSERT_EQ(run_waxwork("render " + scene + " --crease-angle 180 --exposure " + std::to_string(exposure40) + " -o " +
                          kept.string())
                  .exit_code,
              0);
    const Image render40 = read_png(folded), render180 = read_png(smooth), render180_kept = read_png(kept);
    ASSERT_GT(max_channel_difference(render40, render180), 20) << "the angle should show on a cut cube";

    const fs::path from_option = dir / "option.png";
    const auto option = run_under_xvfb("edit " + scene + " --crease-angle 180 --hide-ui --frames 2 --screenshot " +
                                       from_option.string());
    ASSERT_EQ(option.exit_code, 0) << option.err;
    EXPECT_LE(max_channel_difference(read_png(from_option), render180), 2);

    const fs::path script = dir / "input.json", from_panel = dir / "panel.png";
    std::ofstream(script) << R"([{"event": "idle"}, {"event": "crease_angle", "degrees": 180}, {"event": "idle"},
                                {"event": "save_session", "file": "session.json"}, {"event": "idle"}])";
    const auto panel = run_under_xvfb("edit " + scene + " --hide-ui --input " + script.string() +
                                      " --frames 2 --screenshot " + from_panel.string());
    ASSERT_EQ(panel.exit_code, 0) << panel.err;
    EXPECT_LE(max_channel_difference(read_png(from_panel), render180_kept), 2);
    EXPECT_EQ(nlohmann::json::parse(testing::read_text(dir / "session.json"))["crease_angle"], 180.0);

    const auto bad = run_waxwork("edit " + scene + " --crease-angle 200 --screenshot " + (dir / "bad.png").string());
    EXPECT_NE(bad.exit_code, 0);
    EXPECT_NE(bad.err.find("--crease-angle must be between 0 and 180 degrees"), std::string::npos) << bad.err;
}

TEST_F(EditorWindow, ReplayedSessionEqualsWaxworkRun) {
    // The editor replays a session's edits through Document and LiveScene on its worker; its converged
    // view must show what the headless `waxwork run` renders for the same session.
    const fs::path dir = scratch_dir("editor_session");
    const fs::path session = dir / "cut.json";
    std::ofstream(session) << R"({"input": {"surface": ")" << kAssets << R"(/meshes/torus.obj", "max_tets": 12000},
        "material": "marble", "scale": 10, "camera": {"eye_direction": [0.3, 0.8, 0.6]},
        "image": {"width": 320, "height": 240},
        "steps": [{"op": "plane_cut", "normal": [1, 0, 0.2], "offset": 0.3}, {"render": "cut.png"}]})";
    const auto run = run_waxwork("run " + session.string() + " -o " + (dir / "run").string());
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const fs::path edited = dir / "edit.png";
    const auto edit = run_under_xvfb("edit --session " + session.string() +
                                     " --hide-ui --width 320 --height 240 --frames 2 --screenshot " + edited.string());
    ASSERT_EQ(edit.exit_code, 0) << edit.err;
    const Image a = read_png(dir / "run" / "cut.png"), b = read_png(edited);
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    // Same tolerance argument as above: both converge phi to 1e-3 along different iteration paths.
    int max_difference = 0;
    for (size_t i = 0; i < a.rgba.size(); ++i) max_difference = std::max(max_difference, std::abs(a.rgba[i] - b.rgba[i]));
    EXPECT_LE(max_difference, 2);
}

// The mouse tools driven by scripted input (`--input`): a 400x300 view without panels looking at the
// cube [-1, 1]^3 from +z, so screen right is +x and screen up is +y, the centre pixel (200, 150)
// looks at the origin.
const std::string kCubeView = " --max-tets 6000 --view 0,0,1 --hide-ui --width 400 --height 300 ";

// World units per viewport pixel on the cube's front face (z = 1): the eye stands at frame_camera's
// framing distance (margin 1.1, bounding radius sqrt(3), vertical field of view 30 degrees, the
// narrower one at this aspect) and the view is 300 pixels high.
double units_per_pixel_at_front_face() {
    const double half_fov = 15 * std::numbers::pi / 180;
    const double distance = 1.1 * std::sqrt(3.0) / std::sin(half_fov);
    return 2 * (distance - 1) * std::tan(half_fov) / 300;
}

// DIR/session.json, saved by a script, records one edit, `op`, then a render and a save named after
// it; `waxwork run` replays it to `edited` and the image. Returns the session.
nlohmann::json expect_session_replays_one_step(const fs::path& dir, const std::string& op, const TetMesh& edited) {
    nlohmann::json session = nlohmann::json::parse(testing::read_text(dir / "session.json"));
    EXPECT_EQ(session["steps"].size(), 3u);
    if (session["steps"].size() != 3) return session;
    EXPECT_EQ(session["steps"][0]["op"], op);
    EXPECT_EQ(session["steps"][1]["render"], "session.png");
    EXPECT_EQ(session["steps"][2]["save"], "session.vtu");
    const auto run = run_waxwork("run " + (dir / "session.json").string() + " -o " + (dir / "run").string());
    EXPECT_EQ(run.exit_code, 0) << run.err;
    EXPECT_EQ(run.err.find("warning"), std::string::npos) << run.err;
    if (run.exit_code == 0) {
        EXPECT_TRUE(read_volume(dir / "run" / "session.vtu") == edited);
        EXPECT_TRUE(fs::exists(dir / "run" / "session.png"));
    }
    return session;
}

testing::CommandResult run_script(const fs::path& dir, const std::string& script, const std::string& extra = "") {
    const fs::path path = dir / "input.json";
    std::ofstream(path) << script;
    return run_under_xvfb("edit " + kAssets + "/meshes/cube.obj" + kCubeView + extra + " --input " + path.string() +
                          " --frames 2 --screenshot " + (dir / "shot.png").string());
}

// File > Save image writes the view as shown: with --hide-ui the view fills the window, so the saved
// PNG equals the screenshot; the JPEG has the view's size; with the panels shown it is the view alone.
TEST_F(EditorWindow, SaveImageWritesTheViewAsShown) {
    const fs::path dir = scratch_dir("editor_save_image");
    const auto r = run_script(dir, R"([{"event": "idle"}, {"event": "save_image", "file": "view.png"},
        {"event": "save_image", "file": "view.jpg"}, {"event": "idle"}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Image shot = read_png(dir / "shot.png"), saved = read_png(dir / "view.png");
    EXPECT_EQ(saved, shot);
    const Image jpeg = read_image(dir / "view.jpg");
    EXPECT_EQ(jpeg.width, 400);
    EXPECT_EQ(jpeg.height, 300);
    EXPECT_LE(std::abs(testing::mean_brightness(jpeg, 0, 0, 400, 300) - testing::mean_brightness(shot, 0, 0, 400, 300)), 3.0);

    const fs::path panels = scratch_dir("editor_save_image_panels");
    const fs::path script = panels / "input.json";
    std::ofstream(script) << R"([{"event": "idle"}, {"event": "save_image", "file": "view.png"}, {"event": "idle"}])";
    const auto p = run_under_xvfb("edit " + kAssets + "/meshes/cube.obj --max-tets 6000 --width 900 --height 600 --input " +
                                  script.string() + " --frames 2 --screenshot " + (panels / "shot.png").string());
    ASSERT_EQ(p.exit_code, 0) << p.err;
    const Image window = read_png(panels / "shot.png"), view = read_png(panels / "view.png");
    EXPECT_LT(view.width, window.width);
    EXPECT_LT(view.height, window.height);
    // The view's pixels are somewhere in the window: find its top-left corner by its first row.
    bool found = false;
    for (int y = 0; y + view.height <= window.height && !found; ++y)
        for (int x = 0; x + view.width <= window.width && !found; ++x) {
            bool same = true;
            for (int k = 0; k < view.width && same; k += 7)
                same = std::equal(view.pixel(k, view.height / 2), view.pixel(k, view.height / 2) + 4,
                                  window.pixel(x + k, y + view.height / 2));
            found = same && std::equal(view.pixel(0, 0), view.pixel(0, 0) + 4, window.pixel(x, y));
        }
    EXPECT_TRUE(found) << "the saved view is not a part of the window";
}

TEST_F(EditorWindow, CutStrokeCutsTheSideDrawnAndTheSessionReplaysIt) {
    const fs::path dir = scratch_dir("editor_cut_stroke");
    // A stroke cancelled with Esc first (it must cut nothing), then a stroke down the middle: going
    // down the screen its left is the screen's right, +x.
    const auto r = run_script(dir, R"([
        {"event": "tool", "tool": "cut"},
        {"frame": 2, "event": "press", "x": 200, "y": 20},
        {"event": "move", "x": 200, "y": 150},
        {"event": "key", "key": "Escape"},
        {"event": "release", "x": 200, "y": 280},
        {"event": "idle"},
        {"event": "save_volume", "file": "before.vtu"},
        {"event": "drag", "from": [200, 20], "to": [200, 280], "steps": 10},
        {"event": "idle"},
        {"event": "save_session", "file": "session.json"},
        {"event": "save_volume", "file": "after.vtu"},
        {"event": "idle"}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const TetMesh before = read_volume(dir / "before.vtu"), after = read_volume(dir / "after.vtu");
    EXPECT_LT(after.tet_count(), 0.7 * before.tet_count());
    EXPECT_GT(after.tet_count(), 0.3 * before.tet_count());
    double before_max_x = -1e9, after_max_x = -1e9, after_min_x = 1e9;
    for (const auto& p : before.positions) before_max_x = std::max(before_max_x, p.x());
    for (const auto& p : after.positions) after_max_x = std::max(after_max_x, p.x()), after_min_x = std::min(after_min_x, p.x());
    EXPECT_GT(before_max_x, 0.99);
    EXPECT_LT(after_max_x, 0.2) << "the +x half (right of the screen) should be gone";
    EXPECT_LT(after_min_x, -0.99);

    // The recorded session holds the current view and the stroke; `waxwork run` replays it to the
    // identical volume.
    const nlohmann::json session = expect_session_replays_one_step(dir, "stroke_cut", after);
    EXPECT_NEAR(session["camera"]["eye_direction"][2].get<double>(), 1.0, 1e-9);
    EXPECT_EQ(session["image"]["width"], 400);
}

// File > Snapshot records the view at that point of the edits; the saved session replays to the
// images the editor showed: the snapshot's after the cut (a second editor run stopped there), the
// final one after the paint stroke and the turn of the view.
TEST_F(EditorWindow, SnapshotsReplayToTheImagesTheEditorShowed) {
    const fs::path dir = scratch_dir("editor_snapshot");
    const std::string until_snapshot = R"([
        {"event": "tool", "tool": "cut"},
        {"frame": 2, "event": "drag", "from": [150, 20], "to": [260, 280], "steps": 10},
        {"event": "idle"},
        {"event": "drag", "from": [200, 150], "to": [150, 140], "steps": 5, "button": "right"},
        {"event": "idle"})";
    const auto shown = run_script(dir, until_snapshot + "]");
    ASSERT_EQ(shown.exit_code, 0) << shown.err;
    fs::rename(dir / "shot.png", dir / "at_snapshot.png");
    const auto edited = run_script(dir, until_snapshot + R"(,
        {"event": "snapshot"},
        {"event": "tool", "tool": "paint"},
        {"event": "drag", "from": [170, 150], "to": [230, 160], "steps": 6},
        {"event": "idle"},
        {"event": "drag", "from": [200, 150], "to": [240, 170], "steps": 5, "button": "right"},
        {"event": "idle"},
        {"event": "save_session", "file": "session.json"},
        {"event": "idle"}])");
    ASSERT_EQ(edited.exit_code, 0) << edited.err;
    const auto run = run_waxwork("run " + (dir / "session.json").string() + " -o " + (dir / "run").string());
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto expect_same = [&](const fs::path& editor_image, const fs::path& replayed) {
        const Image a = read_png(editor_image), b = read_png(replayed);
        ASSERT_EQ(a.width, b.width) << replayed;
        ASSERT_EQ(a.height, b.height) << replayed;
        // Both converge phi to the editor's tolerance along different iteration paths (see above).
        EXPECT_LE(max_channel_difference(a, b), 2) << replayed;
    };
    expect_same(dir / "at_snapshot.png", dir / "run" / "session_snapshot_1.png");
    expect_same(dir / "shot.png", dir / "run" / "session.png");
    EXPECT_GT(max_channel_difference(read_png(dir / "run" / "session_snapshot_1.png"), read_png(dir / "run" / "session.png")), 20);
}

// File > Export turntable writes the view circling the model into the folder named after the video:
// its first frame is the view itself, the others turn; then ffmpeg (a stand-in that records its
// arguments and writes its output) makes the video from those frames.
TEST_F(EditorWindow, ExportTurntableWritesTheOrbitStartingFromTheViewAndTheVideo) {
    const fs::path dir = scratch_dir("editor_turntable");
    const fs::path bin = dir / "bin";
    fs::create_directories(bin);
    {
        std::ofstream script(bin / "ffmpeg");
        script << "#!/bin/sh\necho \"$@\" > \"" << (dir / "ffmpeg_args").string() << "\"\n"
               << "for last in \"$@\"; do :; done\ntouch \"$last\"\n";
    }
    fs::permissions(bin / "ffmpeg", fs::perms::owner_all);
    std::ofstream(dir / "input.json") << R"([{"frame": 2, "event": "drag", "from": [200, 150], "to": [150, 120],
        "steps": 5, "button": "right"}, {"event": "idle"},
        {"event": "export_turntable", "file": "spin.mp4", "frames": 6}, {"event": "idle"}])";
    const auto r = run_under_xvfb("edit " + kAssets + "/meshes/cube.obj" + kCubeView + " --input " +
                                      (dir / "input.json").string() + " --frames 2 --screenshot " + (dir / "shot.png").string(),
                                  "PATH=" + bin.string() + ":$PATH ");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::vector<Image> frames;
    for (int i = 0; i < 6; ++i) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%04d.png", i);
        ASSERT_TRUE(fs::exists(dir / "spin" / name)) << name;
        frames.push_back(read_png(dir / "spin" / name));
        EXPECT_EQ(frames.back().width, 400);
        EXPECT_EQ(frames.back().height, 300);
    }
    EXPECT_LE(max_channel_difference(frames[0], read_png(dir / "shot.png")), 2);  // frame 0 is the view
    for (int i = 1; i < 6; ++i) EXPECT_GT(max_channel_difference(frames[i], frames[0]), 20) << i;
    EXPECT_TRUE(fs::exists(dir / "spin.mp4"));
    const std::string args = testing::read_text(dir / "ffmpeg_args");
    EXPECT_NE(args.find((dir / "spin" / "frame_%04d.png").string()), std::string::npos) << args;
}

// The View panel's background colour fills the view around the model (and so saved images).
TEST_F(EditorWindow, BackgroundColourFillsTheViewAroundTheModel) {
    const fs::path dir = scratch_dir("editor_background");
    const auto r = run_script(dir, R"([{"frame": 1, "event": "background", "background": "30,90,160"}, {"event": "idle"}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Image shot = read_png(dir / "shot.png");
    const uint8_t* corner = shot.pixel(5, 5);
    EXPECT_EQ(corner[0], 30);
    EXPECT_EQ(corner[1], 90);
    EXPECT_EQ(corner[2], 160);
    EXPECT_GT(mean_brightness(shot, 190, 140, 210, 160), 3 * 200);  // the lit cube in the middle
}

TEST_F(EditorWindow, PaintStrokeChangesTheMaterialWhereDrawn) {
    const fs::path dir = scratch_dir("editor_paint_stroke");
    // The object is skin; the brush paints ketchup (chosen as in the material panel) along the upper
    // part of the front face.
    const auto r = run_script(dir, R"([
        {"event": "tool", "tool": "paint"},
        {"event": "material", "material": "ketchup"},
        {"frame": 2, "event": "drag", "from": [150, 90], "to": [250, 90], "steps": 10},
        {"event": "idle"},
        {"event": "save_volume", "file": "painted.vtu"},
        {"event": "idle"}])", "--material skin1");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const TetMesh painted = read_volume(dir / "painted.vtu");
    ASSERT_TRUE(painted.has_materials());
    const TetMaterial skin = material_preset("skin1");
    // The stroke on the front face: from x = -50 px to +50 px of the centre, 60 px above it.
    const double u = units_per_pixel_at_front_face();
    const Eigen::Vector3d a(-50 * u, 60 * u, 1), b(50 * u, 60 * u, 1);
    // The brush's Gaussian (sigma 0.05 x the bounding radius) drops below PaintOp's cutoff weight 1e-3
    // at sqrt(2 ln 1000) sigma; tet centroids lie up to about an edge (0.25 here) from a painted point.
    const double reach = std::sqrt(2 * std::log(1000.0)) * 0.05 * std::sqrt(3.0) + 0.25;
    size_t changed = 0;
    for (size_t t = 0; t < painted.tet_count(); ++t) {
        if (painted.materials[t] == skin) continue;
        ++changed;
        // Blended towards ketchup, which absorbs green far more than skin (marble, the panel's default,
        // absorbs less): the brush took the scripted material.
        EXPECT_GT(painted.materials[t].mua[1], skin.mua[1]) << "tet " << t;
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (const int32_t v : painted.tets[t]) centroid += 0.25 * painted.positions[v];
        const double s = std::clamp((centroid - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
        EXPECT_LT((centroid - (a + s * (b - a))).norm(), reach) << "tet " << t << " painted away from the stroke";
    }
    EXPECT_GT(changed, 0u);
    EXPECT_LT(changed, painted.tet_count() / 4);
}

TEST_F(EditorWindow, PieceDragAfterFractureMovesThatPiece) {
    const fs::path dir = scratch_dir("editor_piece_drag");
    // A click with the Fracture tool breaks the cube into random pieces; dragging the piece under the
    // centre 100 px to the right moves it along +x.
    const auto r = run_script(dir, R"([
        {"event": "tool", "tool": "fracture"},
        {"frame": 2, "event": "press", "x": 200, "y": 150},
        {"event": "release", "x": 200, "y": 150},
        {"event": "idle"},
        {"event": "save_volume", "file": "fractured.vtu"},
        {"event": "tool", "tool": "move_piece"},
        {"event": "drag", "from": [200, 150], "to": [300, 150], "steps": 10},
        {"event": "idle"},
        {"event": "save_volume", "file": "moved.vtu"},
        {"event": "idle"}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const TetMesh fractured = read_volume(dir / "fractured.vtu"), moved = read_volume(dir / "moved.vtu");
    ASSERT_GT(fractured.piece_transforms.size(), 1u);
    ASSERT_EQ(moved.piece_transforms.size(), fractured.piece_transforms.size());
    EXPECT_EQ(moved.positions, fractured.positions);  // pieces move by their transforms
    int moved_pieces = 0;
    for (size_t i = 0; i < moved.piece_transforms.size(); ++i) {
        const Eigen::Vector3d shift = moved.piece_transforms[i].translation - fractured.piece_transforms[i].translation;
        if (shift.norm() == 0) continue;
        ++moved_pieces;
        // The grabbed point on the front face follows the cursor 100 px right, at its depth.
        EXPECT_NEAR(shift.x(), 100 * units_per_pixel_at_front_face(), 1e-3);
        EXPECT_NEAR(shift.y(), 0, 1e-6);
        EXPECT_NEAR(shift.z(), 0, 1e-6);
    }
    EXPECT_EQ(moved_pieces, 1);
}

// A pin on the left of the front face, then a grab on the right dragged 40 px up: the grabbed
// region follows the cursor while the pinned one stays, the tets are the same, the release is one
// edit, and the recorded session replays it to the identical volume.
TEST_F(EditorWindow, GrabDragDeformsAroundThePinsAndTheSessionReplaysIt) {
    const fs::path dir = scratch_dir("editor_grab");
    const auto r = run_script(dir, R"([
        {"frame": 2, "event": "save_volume", "file": "before.vtu"},
        {"event": "tool", "tool": "pin"},
        {"event": "press", "x": 125, "y": 150},
        {"event": "release", "x": 125, "y": 150},
        {"event": "tool", "tool": "grab"},
        {"event": "drag", "from": [275, 150], "to": [275, 110], "steps": 8},
        {"event": "idle"},
        {"event": "save_session", "file": "session.json"},
        {"event": "save_volume", "file": "after.vtu"},
        {"event": "idle"}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const TetMesh before = read_volume(dir / "before.vtu"), after = read_volume(dir / "after.vtu");
    ASSERT_EQ(after.tets, before.tets);
    const double up = 40 * units_per_pixel_at_front_face();
    const Eigen::Vector3d grabbed(85 * units_per_pixel_at_front_face(), 0, 1), pinned(-grabbed.x(), 0, 1);
    double handle_rise = 0;
    size_t near_pin = 0, moved_near_pin = 0;
    for (size_t v = 0; v < before.vertex_count(); ++v) {
        const Eigen::Vector3d& p = before.positions[v];
        if ((p - grabbed).norm() < 0.1) handle_rise = std::max(handle_rise, after.positions[v].y() - p.y());
        if ((p - pinned).norm() < 0.15) {
            ++near_pin;
            moved_near_pin += after.positions[v] != p ? 1 : 0;
        }
    }
    EXPECT_NEAR(handle_rise, up, 0.25 * up);
    EXPECT_GT(near_pin, 0u);
    EXPECT_EQ(moved_near_pin, 0u);
    expect_session_replays_one_step(dir, "deform", after);
}

TEST_F(EditorWindow, DraggedPieceIsShownMovedBeforeTheDocumentMovesIt) {
    // The screenshot of a drag still in progress (pressed, moved, not released) shows the piece where
    // the finished drag puts it: the same silhouette as after the release, out beyond the cube.
    const std::string fracture = R"([{"event": "tool", "tool": "fracture"},
        {"frame": 2, "event": "press", "x": 200, "y": 150}, {"event": "release", "x": 200, "y": 150},
        {"event": "idle"}, {"event": "tool", "tool": "move_piece"}, )";
    const fs::path dragging = scratch_dir("editor_piece_preview"), released = scratch_dir("editor_piece_released");
    auto r = run_script(dragging, fracture + R"({"event": "press", "x": 200, "y": 150},
        {"event": "move", "x": 250, "y": 150}, {"event": "move", "x": 300, "y": 150}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = run_script(released, fracture + R"({"event": "drag", "from": [200, 150], "to": [300, 150], "steps": 2},
        {"event": "idle"}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Image preview = read_png(dragging / "shot.png"), done = read_png(released / "shot.png");
    ASSERT_EQ(preview.width, done.width);
    ASSERT_EQ(preview.height, done.height);
    // Background: the corner's colour. The radiance differs (the document's move is solved again), the
    // coverage must not, but for antialiased edge pixels.
    const auto is_object = [](const Image& image, int x, int y) {
        for (int c = 0; c < 3; ++c)
            if (std::abs(image.pixel(x, y)[c] - image.pixel(0, 0)[c]) > 2) return true;
        return false;
    };
    int disagree = 0;
    for (int y = 0; y < preview.height; ++y)
        for (int x = 0; x < preview.width; ++x) disagree += is_object(preview, x, y) != is_object(done, x, y);
    EXPECT_LT(disagree, preview.width * preview.height / 100);
    // The cube spans 200 +- 1 / units_per_pixel pixels; the dragged piece reaches beyond.
    const int cube_edge = 200 + static_cast<int>(std::ceil(1 / units_per_pixel_at_front_face()));
    int beyond = 0;
    for (int x = cube_edge + 5; x < preview.width; ++x) beyond += is_object(preview, x, 150);
    EXPECT_GT(beyond, 20);
}

TEST_F(EditorWindow, ShortcutKeysSelectToolsAndUndo) {
    const fs::path dir = scratch_dir("editor_keys");
    // C selects the cut tool by its shortcut, Ctrl+Z undoes the cut: the volume is as loaded again.
    const auto r = run_script(dir, R"([
        {"frame": 2, "event": "save_volume", "file": "loaded.vtu"},
        {"event": "key", "key": "C"},
        {"event": "drag", "from": [200, 20], "to": [200, 280], "steps": 6},
        {"event": "idle"},
        {"event": "save_volume", "file": "cut.vtu"},
        {"event": "key", "key": "Z", "mods": ["ctrl"]},
        {"event": "idle"},
        {"event": "save_volume", "file": "undone.vtu"},
        {"event": "idle"}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const TetMesh loaded = read_volume(dir / "loaded.vtu");
    EXPECT_LT(read_volume(dir / "cut.vtu").tet_count(), loaded.tet_count());
    EXPECT_TRUE(read_volume(dir / "undone.vtu") == loaded);
}

TEST_F(EditorWindow, KeyDRemovesFragmentsUnderTheSizeSetAndUndoRestoresThem) {
    const fs::path dir = scratch_dir("editor_fragments");
    // A cube of 1296 tets and, apart from it, a speck of 6 tets and 0.0125% of the volume (under the
    // default 0.1%).
    const TetMesh volume = join_meshes(testing::make_cube_mesh(6, Eigen::Vector3d::Constant(-1), 2.0),
                                                testing::make_cube_mesh(1, Eigen::Vector3d(1.5, 0, 0), 0.1));
    write_volume(volume, dir / "speck.vtu");
    std::ofstream(dir / "input.json") << R"([
        {"frame": 2, "event": "key", "key": "D"},
        {"event": "idle"},
        {"event": "save_volume", "file": "removed.vtu"},
        {"event": "key", "key": "Z", "mods": ["ctrl"]},
        {"event": "idle"},
        {"event": "save_volume", "file": "undone.vtu"},
        {"event": "idle"}])";
    const auto r = run_under_xvfb("edit " + (dir / "speck.vtu").string() + kCubeView + " --input " +
                                  (dir / "input.json").string() + " --frames 2 --screenshot " +
                                  (dir / "shot.png").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const TetMesh removed = read_volume(dir / "removed.vtu");
    EXPECT_EQ(removed.tet_count(), 1296u);
    for (const Eigen::Vector3d& p : removed.positions) EXPECT_LE(p.x(), 1.0);
    EXPECT_EQ(read_volume(dir / "undone.vtu").tet_count(), volume.tet_count());
}

TEST_F(EditorWindow, LightDragZoomAndPanAreWhatASavedSessionRecords) {
    const fs::path dir = scratch_dir("editor_light_view");
    // The default key light turned by a trackball drag 60 px right of the centre, then two wheel
    // steps in and a 30 px pan to the right; the session saved afterwards holds that light and view.
    const auto r = run_script(dir, R"([
        {"event": "tool", "tool": "light"},
        {"frame": 2, "event": "drag", "from": [200, 150], "to": [260, 150], "steps": 6},
        {"event": "scroll", "x": 200, "y": 150, "dy": 2},
        {"event": "drag", "from": [200, 150], "to": [230, 150], "steps": 3, "button": "middle"},
        {"event": "idle"},
        {"event": "save_session", "file": "view.json"},
        {"event": "idle"}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json session = nlohmann::json::parse(testing::read_text(dir / "view.json"));
    // Trackball: the sphere point under the centre, +z, goes to the one under (260, 150): a turn of
    // asin(60 / 150) about +y (the sphere's radius is half the view's height).
    const double angle = std::asin(60.0 / 150.0);
    const Eigen::Vector3d key = Eigen::Vector3d(1, -1, -1).normalized();  // default_key_light
    const Eigen::Vector3d expected = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()) * key;
    ASSERT_EQ(session["lights"].size(), 1u);
    const auto& direction = session["lights"][0]["direction"];
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(direction[i].get<double>(), expected[i], 1e-9) << i;
    // Zoom: the framing distance times 0.85 per step, recorded as the margin.
    EXPECT_NEAR(session["camera"]["margin"].get<double>(), 1.1 * 0.85 * 0.85, 1e-9);
    // Pan: the target moves left by 30 px at the target's depth (the point under the cursor follows it).
    const double distance = 1.1 * 0.85 * 0.85 * std::sqrt(3.0) / std::sin(15 * std::numbers::pi / 180);
    const double shift = 30 * 2 * distance * std::tan(15 * std::numbers::pi / 180) / 300;
    const auto& offset = session["camera"]["target_offset"];
    EXPECT_NEAR(offset[0].get<double>(), -shift, 1e-9);
    EXPECT_NEAR(offset[1].get<double>(), 0, 1e-9);
    EXPECT_NEAR(offset[2].get<double>(), 0, 1e-9);
}

TEST(EditorWithoutDisplay, BadInputScriptsAreOneLineErrorsNamingTheEntry) {
    const fs::path dir = scratch_dir("editor_bad_script");
    const fs::path script = dir / "bad.json";
    std::ofstream(script) << R"([{"event": "tool", "tool": "cut"}, {"event": "press", "x": 3}])";
    const auto r = run_waxwork("edit " + kAssets + "/meshes/cube.obj --input " + script.string());
    EXPECT_NE(r.exit_code, 0);
    EXPECT_EQ(testing::line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(script.string() + ": entry 1 (press): missing field 'y'"), std::string::npos) << r.err;
}

TEST(EditorWithoutDisplay, FailsWithAOneLineError) {
    const auto r = run_waxwork("edit " + kAssets + "/meshes/cube.obj --screenshot /dev/null",
                               "env -u DISPLAY -u WAYLAND_DISPLAY ");
    EXPECT_NE(r.exit_code, 0);
    EXPECT_EQ(testing::line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("window"), std::string::npos) << r.err;
}

TEST(EditorWithoutDisplay, BadOptionsAreRefusedBeforeOpeningAWindow) {
    const auto r = run_waxwork("edit " + kAssets + "/meshes/cube.obj --frames 0");
    EXPECT_NE(r.exit_code, 0);
    EXPECT_EQ(testing::line_count(r.err), 1u) << r.err;
}

// The Paint tool draws its rings on the surface under the cursor, and only the Paint tool: the same
// cursor position with the Orbit tool shows none of the rings' blue.
TEST_F(EditorWindow, PaintToolDrawsTheBrushRingsUnderTheCursor) {
    const fs::path dir = scratch_dir("editor_brush_cursor");
    const auto blue_pixels = [&](const std::string& tool) {
        std::ofstream(dir / "input.json") << R"([{"event": "tool", "tool": ")" + tool + R"("},
            {"frame": 2, "event": "move", "x": 346, "y": 210}, {"event": "idle"}])";
        const fs::path png = dir / (tool + ".png");
        const auto r = run_under_xvfb("edit " + kAssets + "/meshes/cube.obj --max-tets 6000 --view 0,0,1 --width 900 "
                                      "--height 420 --input " + (dir / "input.json").string() + " --frames 2 --screenshot " +
                                      png.string());
        EXPECT_EQ(r.exit_code, 0) << r.err;
        if (r.exit_code != 0) return -1;
        const Image image = read_png(png);
        int count = 0;
        for (int y = 130; y < 290; ++y)
            for (int x = 266; x < 426; ++x) {
                const uint8_t* p = image.pixel(x, y);
                count += p[2] > 200 && p[1] > 150 && p[0] < 140;  // the rings' blue, not the grey marble
            }
        return count;
    };
    const int painting = blue_pixels("paint"), orbiting = blue_pixels("orbit");
    EXPECT_GT(painting, 100) << "no brush rings drawn";
    EXPECT_EQ(orbiting, 0);
}

// View > Render reference traces the view in the background while the window keeps drawing; Save
// writes live, reference and difference side by side with the numbers beside them.
TEST_F(EditorWindow, RenderReferenceTracesTheViewBesideTheLiveImage) {
    const fs::path dir = scratch_dir("editor_reference");
    const auto r = run_script(dir, R"([
        {"frame": 1, "event": "render_reference", "seconds": 3, "noise": 1, "size": 4},
        {"event": "idle"},
        {"event": "save_reference", "file": "reference.png"},
        {"event": "idle"}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json summary = summary_of(r);
    EXPECT_GT(summary["frames_while_tracing"].get<int>(), 10) << r.out;  // the window drew meanwhile
    const Image strip = read_png(dir / "reference.png");
    nlohmann::json numbers;
    std::ifstream(dir / "reference.json") >> numbers;
    // A quarter of the 400 x 300 view across, three images and two gaps.
    const int w = numbers["width"], h = numbers["height"];
    EXPECT_GT(w, 40);
    EXPECT_EQ(strip.width, 3 * w + 2 * 8);
    EXPECT_EQ(strip.height, h);
    EXPECT_EQ(numbers["stop_reason"], "seconds");  // 1 % noise is out of reach in 3 s
    EXPECT_GT(numbers["passes"].get<int>(), 0);
    EXPECT_GT(numbers["pixels_compared"].get<int>(), w * h / 10);
    EXPECT_GT(numbers["traced_over_live"].get<double>(), 0);
    // The cube is lit in the middle of the live and the traced image, and the difference map colours it.
    const int cx = w / 2, cy = h / 2;
    const auto brightness = [&](int x0) { return mean_brightness(strip, x0 + cx - 2, cy - 2, x0 + cx + 2, cy + 2); };
    const double background = 38 + 40 + 46;
    EXPECT_GT(brightness(0), background + 30);
    EXPECT_GT(brightness(w + 8), background + 30);
    EXPECT_NE(brightness(2 * (w + 8)), background);
}

// Cancel in the Reference window stops a long trace (without it the script's wait for idle would
// last the trace's hour, past the test's time-out) and leaves nothing to save.
TEST_F(EditorWindow, CancelledReferenceStopsAndLeavesNothingToSave) {
    const fs::path dir = scratch_dir("editor_reference_cancel");
    const auto cancelled = run_script(dir, R"([
        {"frame": 1, "event": "render_reference", "seconds": 3600, "noise": 0.1},
        {"frame": 10, "event": "cancel_reference"},
        {"event": "idle"}])");
    ASSERT_EQ(cancelled.exit_code, 0) << cancelled.err;
    EXPECT_GT(summary_of(cancelled)["frames_while_tracing"].get<int>(), 0) << cancelled.out;  // it did start
    // Saving with no reference is an error (screenshot mode exits with it) and writes nothing.
    const auto saved = run_script(dir, R"([{"event": "save_reference", "file": "reference.png"}])");
    EXPECT_NE(saved.exit_code, 0);
    EXPECT_NE(saved.err.find("no reference rendered yet"), std::string::npos) << saved.err;
    EXPECT_FALSE(fs::exists(dir / "reference.png"));
}

TEST_F(EditorWindow, FileExportWritesTheCutSurfaceWithItsLight) {
    const fs::path dir = scratch_dir("editor_export");
    const auto r = run_script(dir, R"([
        {"event": "tool", "tool": "cut"},
        {"frame": 2, "event": "drag", "from": [200, 20], "to": [200, 280], "steps": 10},
        {"event": "idle"},
        {"event": "save_volume", "file": "cut.vtu"},
        {"event": "export_surface", "file": "cut.ply"},
        {"event": "export_surface", "file": "cut.stl"},
        {"event": "idle"}])");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const TetMesh cut = read_volume(dir / "cut.vtu");
    const TetConnectivity connectivity = build_connectivity(cut);
    const double volume = total_volume(cut);
    for (const char* name : {"cut.ply", "cut.stl"}) {
        const ReadSurface s = read_exported(dir / name);
        EXPECT_EQ(s.triangles.size(), connectivity.boundary_faces.size()) << name;
        EXPECT_TRUE(closed_and_oriented(s)) << name;
        EXPECT_NEAR(enclosed_volume(s), volume, 1e-6 * volume) << name;
    }
    // PLY holds the light: lit and shadowed sides differ; STL holds none.
    const ReadSurface ply = read_exported(dir / "cut.ply");
    ASSERT_EQ(ply.colours.size(), ply.positions.size());
    std::set<std::array<uint8_t, 3>> distinct(ply.colours.begin(), ply.colours.end());
    EXPECT_GT(distinct.size(), 20u);
}

}  // namespace
}  // namespace waxwork

namespace waxwork {
namespace {

using namespace testing;
namespace fs = std::filesystem;

class EditorLoading : public WindowTest {};

// `edit VOLUME --input SCRIPT` with the panels shown (the status bar's progress and Cancel, the error
// dialog's repair buttons are drawn), screenshot mode so that it ends when the script has.
CommandResult edit_with_script(const fs::path& dir, const fs::path& volume, const std::string& script,
                               const std::string& options) {
    std::ofstream(dir / "input.json") << script;
    return run_under_xvfb("edit " + volume.string() + " " + options + " --width 640 --height 400 --input " +
                          (dir / "input.json").string() + " --frames 2 --screenshot " + (dir / "shot.png").string());
}

// Cancel in the status bar stops a slow meshing (CGAL's refinement polls the cancel flag) and leaves
// the document that was open before as it was: nothing of the surface is installed, whenever during
// the load the cancel arrives (the load checks it between stages and once more before installing).
TEST_F(EditorLoading, CancelledMeshingLeavesTheOpenDocumentUntouched) {
    const fs::path dir = scratch_dir("editor_cancel_loading");
    const TetMesh cube = make_cube_mesh(3);
    write_volume(cube, dir / "cube.vtu");
    // The torus at 1.5 million tets takes CGAL far longer than the frame between the two events.
    const auto r = edit_with_script(dir, dir / "cube.vtu", R"([
        {"frame": 1, "event": "save_volume", "file": "before.vtu"},
        {"event": "idle"},
        {"event": "open", "file": ")" + kAssets + R"(/meshes/torus.obj"},
        {"event": "cancel_task"},
        {"event": "idle"},
        {"event": "save_volume", "file": "after.vtu"},
        {"event": "idle"}])",
                                    "--mesher cgal --max-tets 1500000");
    ASSERT_EQ(r.exit_code, 0) << r.err;  // a cancelled load is no error
    const TetMesh before = read_volume(dir / "before.vtu");
    EXPECT_EQ(before.tet_count(), cube.tet_count());
    EXPECT_TRUE(read_volume(dir / "after.vtu") == before);
    const nlohmann::json summary = summary_of(r);
    EXPECT_EQ(summary["tets"], cube.tet_count());
}

// A box without its top face: refused as open; its error dialog offers filling the hole and wrapping.
// A needle (10 x 0.05 x 0.05): the default wrap (alpha a hundredth of the diagonal) of anything
// bulkier has hundreds of thousands of triangles, more than TetGen meshes in a test's time.
fs::path write_open_box(const fs::path& dir) {
    const fs::path path = dir / "open_box.obj";
    std::ofstream out(path);
    for (int k = 0; k < 8; ++k)
        out << "v " << 10 * (k & 1) << " " << 0.05 * ((k >> 1) & 1) << " " << 0.05 * ((k >> 2) & 1) << "\n";
    // Outward triangles of the box (vertex k at the corner (k&1, k>>1&1, k>>2&1)), the two of z = top left out.
    const int faces[10][3] = {{0, 2, 1}, {1, 2, 3}, {0, 1, 4}, {1, 5, 4}, {2, 6, 3},
                              {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (const auto& f : faces) out << "f " << f[0] + 1 << " " << f[1] + 1 << " " << f[2] + 1 << "\n";
    return path;
}

// The editor opens what the command line opens: a refused surface's dialog reopens it with the
// repair chosen (as `mesh --fill-holes` / `--repair wrap`), and left unanswered the refusal is still
// the run's one-line error.
TEST_F(EditorLoading, RefusedSurfaceReopensWithTheRepairChosenInItsDialog) {
    const fs::path dir = scratch_dir("editor_repair_dialog");
    const fs::path box = write_open_box(dir);
    write_volume(make_cube_mesh(2), dir / "cube.vtu");
    const std::string meshing = "--max-tets 30000";
    const auto r = edit_with_script(dir, dir / "cube.vtu", R"([
        {"frame": 1, "event": "open", "file": "open_box.obj"},
        {"event": "idle"},
        {"event": "repair", "repair": "fill_holes"},
        {"event": "idle"},
        {"event": "save_volume", "file": "filled.vtu"},
        {"event": "open", "file": "open_box.obj"},
        {"event": "idle"},
        {"event": "repair", "repair": "wrap"},
        {"event": "idle"},
        {"event": "save_volume", "file": "wrapped.vtu"},
        {"event": "idle"}])",
                                    meshing);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const std::string repair : {"fill-holes", "repair wrap"}) {
        const std::string name = repair == "fill-holes" ? "filled" : "wrapped";
        const fs::path cli = dir / (name + "_cli.vtu");
        const auto mesh = run_waxwork("mesh " + box.string() + " --" + repair + " " + meshing + " -o " + cli.string());
        ASSERT_EQ(mesh.exit_code, 0) << mesh.err;
        const TetMesh edited = read_volume(dir / (name + ".vtu")), expected = read_volume(cli);
        EXPECT_GT(edited.tet_count(), 0u) << name;
        EXPECT_EQ(edited.tet_count(), expected.tet_count()) << name;
        EXPECT_EQ(edited.vertex_count(), expected.vertex_count()) << name;
    }
    EXPECT_EQ(summary_of(r)["tets"], read_volume(dir / "wrapped.vtu").tet_count());  // the document open last

    // Not answered (the script ends first, or there is none): the refusal fails the run as before.
    const auto unanswered = edit_with_script(dir, dir / "cube.vtu", R"([{"frame": 1, "event": "open", "file": "open_box.obj"}])",
                                             meshing);
    EXPECT_NE(unanswered.exit_code, 0);
    EXPECT_NE(unanswered.err.find("boundary edges"), std::string::npos) << unanswered.err;
    EXPECT_EQ(line_count(unanswered.err), 1u) << unanswered.err;
    // A repair the dialog does not offer is an error naming the ones it does.
    const auto wrong = edit_with_script(dir, dir / "cube.vtu", R"([
        {"frame": 1, "event": "open", "file": "open_box.obj"}, {"event": "idle"},
        {"event": "repair", "repair": "autorefine"}, {"event": "idle"}])",
                                        meshing);
    EXPECT_NE(wrong.exit_code, 0);
    EXPECT_NE(wrong.err.find("offered: fill_holes, wrap"), std::string::npos) << wrong.err;
}

}  // namespace
}  // namespace waxwork
