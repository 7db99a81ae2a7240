// Frame budgets in milliseconds in the live editor: LiveScene/LiveSolver frames on a
// fake clock, the GPU's predicted iteration counts, sessions' "frame_ms", and `--frame-ms` on the
// command line. No real clock is timed here (bench/live_solver_bench.cpp measures frame times).
#include "base/error.h"
#include "io/image_io.h"
#include "io/volume_file.h"
#include "multires/multires_test_systems.h"
#include "scene/live_scene.h"
#include "scene/live_solver.h"
#include "scene/live_test_scene.h"
#include "scene/session.h"
#include "solver/material.h"
#include "support/cli_run.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>

namespace waxwork {
namespace {

namespace fs = std::filesystem;
using testing::key_lighting;

// Advances `step` ms at every read (the first read returns 0).
MillisecondClock fake_clock(double step) {
    return [now = std::make_shared<double>(0.0), step] {
        const double t = *now;
        *now += step;
        return t;
    };
}

struct Config {
    LiveMethod method;
    LiveBackend backend;
    const char* name;
};
const Config kCpuConfigs[] = {
    {LiveMethod::JacobiCg, LiveBackend::Cpu, "cpu jacobi"},
    {LiveMethod::MultigridCg, LiveBackend::Cpu, "cpu mgcg"},
    {LiveMethod::Multires, LiveBackend::Cpu, "cpu multires"},
};
const Config kGpuConfigs[] = {
    {LiveMethod::JacobiCg, LiveBackend::Gpu, "gpu cg"},
    {LiveMethod::Multires, LiveBackend::Gpu, "gpu multires"},
};
// The GPU multigrid CG reads back every CG step anyway: it checks the deadline between V-cycles as the
// CPU methods do instead of predicting an iteration count.
const Config kGpuMultigrid = {LiveMethod::MultigridCg, LiveBackend::Gpu, "gpu mgcg"};

LiveSceneOptions scene_options(const Config& config, MillisecondClock clock = {}) {
    LiveSceneOptions o;
    o.mm_per_unit = 10;  // a 1 cm marble cube, as in live_solver_test.cpp
    o.relative_tolerance = config.backend == LiveBackend::Gpu ? 1e-6 : 1e-9;
    o.method = config.method;
    o.backend = config.backend;
    o.clock = std::move(clock);
    return o;
}

// max |a - b| / max |b| over vertices and channels.
double relative_difference(const std::vector<std::array<double, 3>>& a, const std::vector<std::array<double, 3>>& b) {
    double largest = 0, difference = 0;
    for (size_t v = 0; v < a.size(); ++v)
        for (int c = 0; c < 3; ++c) {
            largest = std::max(largest, std::abs(b[v][c]));
            difference = std::max(difference, std::abs(a[v][c] - b[v][c]));
        }
    return difference / largest;
}

TEST(LiveFrameBudget, AnIterationOnlyBudgetEqualsTheIntBudget) {
    const TetMesh mesh = testing::make_cube_mesh(6);
    Document doc(mesh, material_preset("marble"));
    std::vector<Config> configs(std::begin(kCpuConfigs), std::end(kCpuConfigs));
    configs.insert(configs.end(), std::begin(kGpuConfigs), std::end(kGpuConfigs));
    configs.push_back(kGpuMultigrid);
    for (const Config& config : configs) {
        LiveScene counted(doc.mesh(), key_lighting(), scene_options(config));
        LiveScene budgeted(doc.mesh(), key_lighting(), scene_options(config, fake_clock(1)));
        for (const int iterations : {4, 1, 7}) {
            const FrameReport a = counted.step(iterations);
            const FrameReport b = budgeted.step(FrameBudget::iterations(iterations));
            EXPECT_EQ(a.iterations, b.iterations) << config.name;
            EXPECT_EQ(a.estimated_relative_error, b.estimated_relative_error) << config.name;
        }
        EXPECT_EQ(counted.backend(), budgeted.backend()) << config.name;
        EXPECT_TRUE(counted.phi() == budgeted.phi()) << config.name << ": not bit-identical";
    }
}

TEST(LiveFrameBudget, TimedFramesConvergeOnEveryCpuMethod) {
    // 2197 vertices: above the hierarchy's 1000-vertex floor, so multigrid and multires have coarse levels
    // (on a single level multigrid CG's V-cycle is an exact solve and one frame would be enough).
    const TetMesh mesh = testing::make_cube_mesh(12);
    Document doc(mesh, material_preset("marble"));
    LiveScene exact(doc.mesh(), key_lighting(), scene_options(kCpuConfigs[0]));
    exact.converge();
    const auto reference = exact.phi();
    const double budget_ms = 3, step_ms = 1;  // a few clock reads per frame
    std::vector<Config> configs(std::begin(kCpuConfigs), std::end(kCpuConfigs));
    configs.push_back(kGpuMultigrid);
    for (const Config& config : configs) {
        LiveScene scene(doc.mesh(), key_lighting(), scene_options(config, fake_clock(step_ms)));
        const FrameReport first = scene.step(FrameBudget::milliseconds(budget_ms));
        // Every channel made progress, and the frame stopped: each iteration (or V-cycle) after a
        // channel's first costs a clock read.
        for (int c = 0; c < 3; ++c) {
            EXPECT_GE(first.iterations[static_cast<size_t>(c)], 1) << config.name;
            EXPECT_LE(first.iterations[static_cast<size_t>(c)], static_cast<int>(budget_ms / step_ms) + 1)
                << config.name;
        }
        const double first_difference = relative_difference(scene.phi(), reference);
        EXPECT_GT(first_difference, 0.01) << config.name << ": one frame was enough, the test says nothing";
        int frames = 1;
        for (; frames < 500 && relative_difference(scene.phi(), reference) >= 0.01; ++frames)
            scene.step(FrameBudget::milliseconds(budget_ms));
        EXPECT_LT(relative_difference(scene.phi(), reference), 0.01) << config.name << " after " << frames << " frames";
        EXPECT_GT(frames, 1) << config.name;
    }
}

TEST(LiveFrameBudget, GpuTurnsTheTimeBudgetIntoPredictedIterations) {
    const auto s = testing::make_test_system(10);
    // A timed GPU frame reads the clock for its deadline, then before and after the device work.
    const double step_ms = 1;
    for (const Config& config : kGpuConfigs) {
        LiveSolverOptions options;
        options.method = config.method;
        options.backend = config.backend;
        options.clock = fake_clock(step_ms);
        LiveSolver solver(options);
        solver.matrix_rebuilt(s.mesh, s.matrix);
        std::array<std::vector<double>, 3> phi;
        for (auto& p : phi) p.assign(s.matrix.size(), 0.0);
        const FrameBudget budget = FrameBudget::milliseconds(3);
        const double tolerance = 1e-6;
        auto frame = [&] {
            const auto channels = solver.iterate(s.matrix, s.b, phi, budget, tolerance, {});
            return std::max({channels[0].iterations, channels[1].iterations, channels[2].iterations});
        };
        // First frame: nothing measured yet, the default count; it uploads the matrix (and multires runs
        // its coarse pass), so it is not measured either.
        EXPECT_EQ(frame(), IterationTimePredictor::kDefaultFirstFrameIterations) << config.name;
        if (solver.backend() != LiveBackend::Gpu) GTEST_SKIP() << "no GPU here: " << solver.gpu_fallback_reason();
        EXPECT_FALSE(solver.gpu_iteration_time().milliseconds_per_iteration()) << config.name;
        // Second frame: still the default, now measured (1 ms between the reads around 10 iterations).
        EXPECT_EQ(frame(), IterationTimePredictor::kDefaultFirstFrameIterations) << config.name;
        ASSERT_TRUE(solver.gpu_iteration_time().milliseconds_per_iteration()) << config.name;
        const double per_iteration = step_ms / IterationTimePredictor::kDefaultFirstFrameIterations;
        EXPECT_DOUBLE_EQ(*solver.gpu_iteration_time().milliseconds_per_iteration(), per_iteration);
        // Third frame: as many as fit in the budget at that cost.
        const int predicted = solver.gpu_iteration_time().iterations_for(budget);
        EXPECT_EQ(predicted, static_cast<int>(std::floor(3 / per_iteration + 1e-9)));
        EXPECT_EQ(frame(), predicted) << config.name;
        // Iteration-budgeted frames are measured as well: 4 iterations in 1 ms move the average.
        const double before = *solver.gpu_iteration_time().milliseconds_per_iteration();
        const auto counted = solver.iterate(s.matrix, s.b, phi, 4, tolerance, {});
        EXPECT_EQ(counted[0].iterations, 4) << config.name;
        EXPECT_GT(*solver.gpu_iteration_time().milliseconds_per_iteration(), before) << config.name;
    }
}

TEST(LiveFrameBudget, InvalidBudgetsAreRejected) {
    Document doc(testing::make_cube_mesh(3), material_preset("marble"));
    LiveScene scene(doc.mesh(), key_lighting(), scene_options(kCpuConfigs[0]));
    for (const FrameBudget& bad : {FrameBudget{0, 0}, FrameBudget{-1, 0}, FrameBudget{0, std::nan("")},
                                   FrameBudget{0, -5}}) {
        EXPECT_THROW(scene.step(bad), InvalidArgumentError);
    }
}

std::string session_error(const fs::path& dir, const std::string& frame_ms) {
    const fs::path path = dir / "bad.json";
    std::ofstream(path) << R"({"input": {"volume": "v.vtu"}, "frame_ms": )" << frame_ms << R"(, "steps": []})";
    try {
        read_session(path);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(SessionFrameBudget, FrameMsRoundTripsAndIsOptional) {
    const fs::path dir = testing::scratch_dir("round_trip");
    std::ofstream(dir / "s.json") << R"({"input": {"volume": "v.vtu"}, "frame_iterations": 6, "frame_ms": 7.5,
                                         "steps": [{"render": "a.png", "frames": 2}]})";
    const Session session = read_session(dir / "s.json");
    ASSERT_TRUE(session.frame_ms);
    EXPECT_EQ(*session.frame_ms, 7.5);
    EXPECT_EQ(session.frame_iterations, 6);
    write_session(dir / "again.json", session);
    const Session again = read_session(dir / "again.json");
    ASSERT_TRUE(again.frame_ms);
    EXPECT_EQ(*again.frame_ms, 7.5);
    EXPECT_EQ(session_to_json(again).dump(), session_to_json(session).dump());
    const FrameBudget budget = session_frame_budget(again);
    EXPECT_EQ(budget.max_milliseconds, 7.5);
    EXPECT_FALSE(budget.limits_iterations());
    SessionRunOptions run;
    run.frame_ms = 3;  // `run --frame-ms` wins over the file's
    EXPECT_EQ(session_frame_budget(again, run).max_milliseconds, 3);

    // Absent: the iteration budget, as before, and nothing written.
    Session plain = again;
    plain.frame_ms.reset();
    EXPECT_FALSE(session_to_json(plain).contains("frame_ms"));
    EXPECT_FALSE(parse_session(session_to_json(plain), dir, "plain").frame_ms);
    const FrameBudget iterations = session_frame_budget(plain);
    EXPECT_EQ(iterations.max_iterations, 6);
    EXPECT_FALSE(iterations.limits_time());
}

TEST(SessionFrameBudget, BadFrameMsNamesTheFileAndField) {
    const fs::path dir = testing::scratch_dir("errors");
    for (const std::string bad : {"-1", "0", "\"fast\"", "1e9", "null"}) {
        const std::string e = session_error(dir, bad);
        EXPECT_NE(e.find("bad.json: field 'frame_ms'"), std::string::npos) << bad << ": " << e;
    }
}

TEST(SessionFrameBudget, RunReplaysWithATimeBudget) {
    const fs::path dir = testing::scratch_dir("run");
    write_volume(testing::make_cube_mesh(4), dir / "cube.vtu");
    std::ofstream(dir / "s.json") << R"({"input": {"volume": "cube.vtu"}, "frame_ms": 5, "scale": 10,
        "lights": [{"direction": [1, -0.8, -0.5]}], "steps": [{"render": "a.png", "frames": 2}, {"render": "b.png"}]})";
    const SessionResult result = run_session(read_session(dir / "s.json"), dir / "out");
    ASSERT_EQ(result.steps.size(), 2u);
    EXPECT_GE(result.steps[0].solver_iterations, 2 * 3);  // at least one iteration per channel and frame
    EXPECT_TRUE(fs::exists(dir / "out" / "a.png"));
    EXPECT_TRUE(fs::exists(dir / "out" / "b.png"));
    std::ifstream metrics_file(dir / "out" / "metrics.json");
    const nlohmann::json metrics = nlohmann::json::parse(metrics_file);
    EXPECT_EQ(metrics.at("frame_ms"), 5.0);
}

TEST(CliFrameBudget, BadFrameMsIsAOneLineError) {
    using waxwork::testing::line_count;
    using waxwork::testing::run_waxwork;
    const fs::path dir = testing::scratch_dir("cli");
    write_volume(testing::make_cube_mesh(3), dir / "cube.vtu");
    std::ofstream(dir / "s.json")
        << R"({"input": {"volume": "cube.vtu"}, "steps": [{"render": "a.png", "frames": 1}]})";
    const std::string run = "run " + (dir / "s.json").string() + " -o " + (dir / "out").string();
    const std::string edit = "edit " + (dir / "cube.vtu").string() + " --screenshot " + (dir / "x.png").string();
    for (const std::string& command : {run, edit}) {
        for (const std::string bad : {" --frame-ms -1", " --frame-ms nan", " --frame-ms abc", " --frame-ms 0",
                                      " --frame-ms=-1"}) {
            const auto r = run_waxwork(command + bad);
            EXPECT_NE(r.exit_code, 0) << bad;
            EXPECT_EQ(line_count(r.err), 1u) << bad << ": " << r.err;
            EXPECT_NE(r.err.find("--frame-ms"), std::string::npos) << r.err;
        }
        const std::string name = command.substr(0, command.find(' '));
        const auto help = run_waxwork(name + " --help");
        EXPECT_NE(help.out.find("--frame-ms"), std::string::npos) << name;
        EXPECT_NE(help.out.find("milliseconds"), std::string::npos) << name;
    }
    EXPECT_FALSE(fs::exists(dir / "out"));  // refused before running
    const auto plain = run_waxwork(run);
    ASSERT_EQ(plain.exit_code, 0) << plain.err;
    EXPECT_TRUE(nlohmann::json::parse(std::ifstream(dir / "out" / "metrics.json")).at("frame_ms").is_null());
    const auto good = run_waxwork(run + " --frame-ms 5");
    ASSERT_EQ(good.exit_code, 0) << good.err;
    EXPECT_TRUE(fs::exists(dir / "out" / "a.png"));
    EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir / "out" / "metrics.json")).at("frame_ms"), 5.0);
}

// The editor with `--frame-ms` solves in timed ticks and, once converged, shows what the iteration
// budget shows (both converge to the same tolerance: the pictures agree to rounding).
TEST(CliFrameBudget, EditorWithATimeBudgetConvergesToTheSamePicture) {
    if (!waxwork::testing::have_xvfb()) GTEST_SKIP() << "xvfb-run is not installed";
    const fs::path dir = testing::scratch_dir("editor");
    write_volume(testing::make_cube_mesh(6), dir / "cube.vtu");
    const std::string common = "edit " + (dir / "cube.vtu").string() + " --hide-ui --width 320 --height 240 --frames 1";
    const auto iterations =
        waxwork::testing::run_under_xvfb(common + " --screenshot " + (dir / "iterations.png").string());
    ASSERT_EQ(iterations.exit_code, 0) << iterations.err;
    const auto timed =
        waxwork::testing::run_under_xvfb(common + " --frame-ms 2 --screenshot " + (dir / "timed.png").string());
    ASSERT_EQ(timed.exit_code, 0) << timed.err;
    const Image a = read_png(dir / "iterations.png"), b = read_png(dir / "timed.png");
    ASSERT_EQ(a.rgba.size(), b.rgba.size());
    int largest = 0;
    for (size_t i = 0; i < a.rgba.size(); ++i) largest = std::max(largest, std::abs(a.rgba[i] - b.rgba[i]));
    EXPECT_LE(largest, 2);
}

}  // namespace
}  // namespace waxwork
