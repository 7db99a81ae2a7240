// `waxwork edit` end to end under a virtual X server (xvfb-run): the editor opens a GLFW window with an
// OpenGL 4.5 core context (Mesa llvmpipe through GLX), loads and solves a scene on its worker threads,
// draws, saves a screenshot and exits cleanly; and its 3D view shows exactly what `waxwork render`
// (OSMesa) writes for the same scene.
#include "editor/cli_run.h"
#include "io/image_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace waxwork {
namespace {

using testing::run_waxwork;
using testing::scratch_dir;
namespace fs = std::filesystem;

const std::string kAssets = WAXWORK_ASSET_DIR;

bool have_xvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

// Runs waxwork under its own virtual display (-a: a free server number, so tests may run in parallel).
testing::CommandResult run_under_xvfb(const std::string& arguments) {
    return run_waxwork(arguments, "xvfb-run -a -s '-screen 0 1280x1024x24' ");
}

// Mean of r + g + b over a rectangle.
double mean_brightness(const Image& image, int x0, int y0, int x1, int y1) {
    double sum = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) sum += image.pixel(x, y)[0] + image.pixel(x, y)[1] + image.pixel(x, y)[2];
    return sum / ((x1 - x0) * static_cast<double>(y1 - y0));
}

class EditorWindow : public ::testing::Test {
protected:
    void SetUp() override {
        if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is not installed (setup.sh installs xvfb and xauth)";
    }
};

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
    const fs::path rendered = dir / "render.png", edited = dir / "edit.png";
    const std::string scene = volume.string() + " --width 320 --height 240 --view 0.3,0.8,0.6 --material skin1";
    const auto render = run_waxwork("render " + scene + " -o " + rendered.string());
    ASSERT_EQ(render.exit_code, 0) << render.err;
    const auto edit = run_under_xvfb("edit " + scene + " --hide-ui --frames 2 --screenshot " + edited.string());
    ASSERT_EQ(edit.exit_code, 0) << edit.err;
    // Both draw the same geometry with Mesa's llvmpipe (OSMesa for render, GLX under Xvfb for the
    // window) through the same SurfaceRenderer and camera, so coverage and shading agree exactly. The
    // radiance does not quite: render solves phi in one CG run, the editor converges it frame by frame
    // (LiveScene), each stopping within the relative tolerance 1e-3, and the automatic exposure follows
    // phi. A relative difference of 2e-3 moves an 8-bit sRGB value by under one step, so every
    // channel may differ by at most 1 after rounding (2 allowed for the two roundings).
    const Image a = read_png(rendered), b = read_png(edited);
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    int max_difference = 0;
    for (size_t i = 0; i < a.rgba.size(); ++i) max_difference = std::max(max_difference, std::abs(a.rgba[i] - b.rgba[i]));
    EXPECT_LE(max_difference, 2);
    EXPECT_GT(mean_brightness(a, 0, 0, a.width, a.height), mean_brightness(a, 0, 0, 20, 20) + 5);  // not empty
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
        const fs::path rendered = dir / (name + "_render.png"), edited = dir / (name + "_edit.png");
        const std::string scene = volume.string() + " --width 320 --height 240 --view 0.3,0.8,0.6 --show " + show;
        const auto render = run_waxwork("render " + scene + " -o " + rendered.string());
        ASSERT_EQ(render.exit_code, 0) << render.err;
        const auto edit = run_under_xvfb("edit " + scene + " --hide-ui --frames 2 --screenshot " + edited.string());
        ASSERT_EQ(edit.exit_code, 0) << edit.err;
        const Image a = read_png(rendered), b = read_png(edited);
        ASSERT_EQ(a.width, b.width);
        ASSERT_EQ(a.height, b.height);
        int max_difference = 0;
        for (size_t i = 0; i < a.rgba.size(); ++i) max_difference = std::max(max_difference, std::abs(a.rgba[i] - b.rgba[i]));
        EXPECT_LE(max_difference, 2) << name;
        EXPECT_GT(mean_brightness(a, 0, 0, a.width, a.height), mean_brightness(a, 0, 0, 20, 20) + 5) << name;
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

}  // namespace
}  // namespace waxwork
