// `waxwork run --backend gpu`: the same volume and, within the float solver's tolerance, the same
// images as the CPU backend; metrics.json names the backend.
#include "io/image_io.h"
#include "io/volume_file.h"
#include "scene/session.h"
#include "support/cli_run.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace waxwork {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using testing::run_waxwork;

// A paint, a cut and a partly converged frame: every kind of device update the live GPU solver does.
void write_session_file(const fs::path& dir) {
    write_volume(testing::make_cube_mesh(6), dir / "cube.vtu");
    std::ofstream(dir / "s.json") << R"({"input": {"volume": "cube.vtu"}, "scale": 10, "tolerance": 1e-5,
        "image": {"width": 96, "height": 72}, "steps": [
        {"render": "start.png"},
        {"op": "paint", "points": [[0.5, 0.5, 0.5]], "material": "ketchup", "sigma": 0.15},
        {"render": "painted.png"},
        {"op": "plane_cut", "normal": [1, 0.2, 0.1], "offset": 0.6},
        {"render": "cut.png"}, {"save": "cut.vtu"}]})";
}

Json read_metrics(const fs::path& path) {
    std::ifstream in(path);
    return Json::parse(in);
}

int max_channel_difference(const Image& a, const Image& b) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    int largest = 0;
    for (size_t i = 0; i < std::min(a.rgba.size(), b.rgba.size()); ++i)
        largest = std::max(largest, std::abs(int(a.rgba[i]) - int(b.rgba[i])));
    return largest;
}

TEST(SessionBackend, GpuRunGivesTheCpuRunsVolumeAndImages) {
    const fs::path dir = testing::scratch_dir("gpu");
    write_session_file(dir);
    const Session session = read_session(dir / "s.json");
    const SessionResult cpu = run_session(session, dir / "cpu");
    SessionRunOptions gpu_options;
    gpu_options.backend = LiveBackend::Gpu;
    const SessionResult gpu = run_session(session, dir / "gpu", gpu_options);
    EXPECT_EQ(gpu.solver_backend, LiveBackend::Gpu) << gpu.gpu_fallback_reason;
    EXPECT_TRUE(gpu.mesh == cpu.mesh);
    EXPECT_TRUE(read_volume(dir / "gpu" / "cut.vtu") == read_volume(dir / "cpu" / "cut.vtu"));
    for (const char* name : {"start.png", "painted.png", "cut.png"}) {
        const Image a = read_png(dir / "cpu" / name), b = read_png(dir / "gpu" / name);
        // phi to 1e-5 relative in float and double: at most a rounding step of 8-bit sRGB apart.
        EXPECT_LE(max_channel_difference(a, b), 2) << name;
    }
    EXPECT_EQ(read_metrics(dir / "gpu" / "metrics.json").at("solver_backend"), "gpu");
    EXPECT_EQ(read_metrics(dir / "cpu" / "metrics.json").at("solver_backend"), "cpu");
}

TEST(SessionBackend, AFailingGpuRunFallsBackAndSaysWhy) {
    const fs::path dir = testing::scratch_dir("fallback");
    write_session_file(dir);
    SessionRunOptions gpu_options;
    gpu_options.backend = LiveBackend::Gpu;
    setenv("WAXWORK_GPU_FORCE_FAIL", "cg_update", 1);
    const SessionResult result = run_session(read_session(dir / "s.json"), dir / "out", gpu_options);
    unsetenv("WAXWORK_GPU_FORCE_FAIL");
    EXPECT_EQ(result.solver_backend, LiveBackend::Cpu);
    EXPECT_NE(result.gpu_fallback_reason.find("cg_update"), std::string::npos) << result.gpu_fallback_reason;
    const Json metrics = read_metrics(dir / "out" / "metrics.json");
    EXPECT_EQ(metrics.at("solver_backend"), "cpu");
    EXPECT_EQ(metrics.at("gpu_fallback_reason").get<std::string>(), result.gpu_fallback_reason);
    EXPECT_TRUE(fs::exists(dir / "out" / "cut.png"));
}

// `waxwork run --method multires` (app/options/live_solver_options.cpp) runs the session with the paper's
// multires solver, on the CPU and on the GPU, and gives the images of the default method; an unknown
// method is refused.
TEST(SessionBackend, RunAcceptsTheMultiresMethod) {
    const fs::path dir = testing::scratch_dir("multires");
    write_session_file(dir);
    const auto jacobi = run_waxwork("run " + (dir / "s.json").string() + " -o " + (dir / "jacobi").string());
    ASSERT_EQ(jacobi.exit_code, 0) << jacobi.err;
    for (const std::string backend : {"cpu", "gpu"}) {
        const fs::path out = dir / backend;
        const auto run = run_waxwork("run " + (dir / "s.json").string() + " --method multires --backend " + backend +
                                     " -o " + out.string());
        ASSERT_EQ(run.exit_code, 0) << run.err;
        const Json metrics = read_metrics(out / "metrics.json");
        EXPECT_EQ(metrics.at("solver_method"), "multires");
        EXPECT_EQ(metrics.at("solver_backend"), backend) << metrics.dump();
        for (const char* name : {"start.png", "painted.png", "cut.png"})
            EXPECT_LE(max_channel_difference(read_png(dir / "jacobi" / name), read_png(out / name)), 2) << backend << name;
    }
    const auto bad = run_waxwork("run " + (dir / "s.json").string() + " --method gauss -o " + (dir / "bad").string());
    EXPECT_NE(bad.exit_code, 0);
    EXPECT_NE(bad.err.find("method"), std::string::npos) << bad.err;
}

// The run's first line and metrics.json give the volume as loaded, not as the first step left it.
TEST(SessionBackend, RunReportsTheInputAsLoaded) {
    const fs::path dir = testing::scratch_dir("input_tets");
    write_volume(testing::make_cube_mesh(6), dir / "cube.vtu");  // 1296 tets
    std::ofstream(dir / "s.json") << R"({"input": {"volume": "cube.vtu"}, "image": {"width": 32, "height": 24},
        "steps": [{"op": "plane_cut", "normal": [1, 0, 0], "offset": 0.5}, {"save": "cut.vtu"}]})";
    const auto run = run_waxwork("run " + (dir / "s.json").string() + " -o " + (dir / "out").string());
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_EQ(run.out.rfind("loaded the input in ", 0), 0u) << run.out;
    EXPECT_NE(run.out.substr(0, run.out.find('\n')).find("(1296 tets)"), std::string::npos) << run.out;
    EXPECT_EQ(read_metrics(dir / "out" / "metrics.json").at("input_tets"), 1296);
    EXPECT_LT(read_volume(dir / "out" / "cut.vtu").tet_count(), 1296u);
    EXPECT_EQ(run.err.find("warning"), std::string::npos) << run.err;
}

// A session that renders and saves nothing still runs, and says that only metrics.json comes of it.
TEST(SessionBackend, RunWarnsWhenTheSessionWritesNothing) {
    const fs::path dir = testing::scratch_dir("no_outputs");
    write_volume(testing::make_cube_mesh(4), dir / "cube.vtu");
    std::ofstream(dir / "s.json") << R"({"input": {"volume": "cube.vtu"},
        "steps": [{"op": "plane_cut", "normal": [1, 0, 0], "offset": 0.5}]})";
    const auto run = run_waxwork("run " + (dir / "s.json").string() + " -o " + (dir / "out").string());
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.err.find("s.json: warning: no render or save step"), std::string::npos) << run.err;
    EXPECT_TRUE(fs::exists(dir / "out" / "metrics.json"));
}

}  // namespace
}  // namespace waxwork
