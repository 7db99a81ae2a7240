// `waxwork edit --backend gpu` under a virtual X server: the live solve runs on the GPU path in a hidden
// window's context shared with the editor's window (editor/window_gl_context.h), and the view equals the
// CPU backend's; a failing GPU falls back to the CPU and says so.
#include "editor_window_fixture.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>

namespace waxwork {
namespace {

using namespace testing;
namespace fs = std::filesystem;

class EditorGpuWindow : public WindowTest {};

TEST_F(EditorGpuWindow, GpuBackendShowsWhatTheCpuBackendShows) {
    const fs::path dir = scratch_dir("editor_gpu");
    const std::string scene = kAssets + "/meshes/torus.obj --max-tets 12000 --width 320 --height 240 --hide-ui "
                                        "--view 0.3,0.8,0.6 --frames 2 --screenshot ";
    const auto cpu = run_under_xvfb("edit " + scene + (dir / "cpu.png").string() + " --backend cpu");
    ASSERT_EQ(cpu.exit_code, 0) << cpu.err;
    const auto gpu = run_under_xvfb("edit " + scene + (dir / "gpu.png").string() + " --backend gpu");
    ASSERT_EQ(gpu.exit_code, 0) << gpu.err;
    EXPECT_EQ(summary_of(cpu).value("solver_backend", ""), "cpu");
    const nlohmann::json s = summary_of(gpu);
    EXPECT_EQ(s.value("solver_backend", ""), "gpu") << s.value("gpu_fallback_reason", "");
    EXPECT_EQ(s.value("gpu_fallback_reason", "?"), "");
    // The view drew E from the solver's buffer in the shared context, not from a CPU copy.
    EXPECT_TRUE(s.value("view_reads_device_radiance", false));
    EXPECT_FALSE(summary_of(cpu).value("view_reads_device_radiance", true));
    const Image a = read_png(dir / "cpu.png"), b = read_png(dir / "gpu.png");
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    // Both converge phi to the editor's tolerance 1e-3 (float on the GPU, double on the CPU) along
    // different iteration paths: under one 8-bit step apart after exposure, as in editor_window_test,
    // plus one for the float solve.
    EXPECT_LE(max_channel_difference(a, b), 3);
}

TEST_F(EditorGpuWindow, AFailingGpuFallsBackAndReportsWhy) {
    const fs::path dir = scratch_dir("editor_gpu_fallback");
    const auto r = run_under_xvfb("edit " + kAssets + "/meshes/torus.obj --max-tets 12000 --width 320 --height 240 "
                                  "--frames 1 --backend gpu --screenshot " + (dir / "fallback.png").string(),
                                  "env WAXWORK_GPU_FORCE_FAIL=1 ");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json s = summary_of(r);
    EXPECT_EQ(s.value("solver_backend", ""), "cpu");
    EXPECT_FALSE(s.value("view_reads_device_radiance", true));
    EXPECT_NE(s.value("gpu_fallback_reason", "").find("WAXWORK_GPU_FORCE_FAIL"), std::string::npos)
        << s.value("gpu_fallback_reason", "");
}

}  // namespace
}  // namespace waxwork
