// The live editor's frames per solver method and backend (scene/live_solver.h): the per-frame
// solve while the light rotates and while a brush paints, on spot at ~100K tets, as
// bench/live_scene_bench.cpp measures the default (CPU Jacobi CG), for
//   0: CPU Jacobi CG (double), 1: CPU multigrid CG, three channels per V-cycle (the budget of 8 is 2
//   V-cycles; cg_its_per_frame counts each V-cycle once per channel), 2: GPU CG (float, OpenGL compute),
//   3: CPU multires (Li et al. Sec. 4: coarse to fine after a rebuild, then the level-0 Jacobi CG warm
//   per frame, double), 4: the same on the GPU (GpuMultiresSolver, float), 5: multigrid CG on the GPU
//   (GpuMultigridFrameSolver, float; V-cycles counted as in 1; a time budget checked between V-cycles).
//   ./build/bench/live_solver_bench
// BM_RelightFramesWithinBudget: the same relighting with a budget of 10 ms per frame instead of 8
// iterations (below).
// The GPU backend runs in an OSMesa context: on a machine without a GPU (and in CI) that is Mesa's
// llvmpipe, which runs the compute shaders on the CPU cores, so its times say nothing about a real
// GPU (WAXWORK_GL_DEVICE=egl reaches one where there is one). A GPU frame includes reading phi back
// (the host copy the CPU radiance and saves use); counters as in live_scene_bench, plus true_error:
// max |phi - phi*| / max |phi*| after the last frame, phi* the same scene converged to 1e-8 with CPU
// Jacobi CG, and true_error_l2: the largest per-channel sqrt(sum (phi - phi*)^2 / sum phi*^2) (final_error is
// the solver's own estimate, which for multigrid CG lags one update: it describes phi before it).
#include "base/timing.h"
#include "scene/document.h"
#include "scene/live_scene.h"
#include "solver/frame_budget.h"
#include "solver/material.h"
#include "bench_main.h"
#include "bench_meshes.h"
#include "live_scene_setup.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

namespace waxwork {
namespace {

using Clock = std::chrono::steady_clock;

constexpr size_t kFrameTets = 100'000;
constexpr int kFrames = 30;
constexpr int kFrameIterations = 8;  // as live_scene_bench: CG iterations per channel and frame

struct Variant {
    LiveMethod method;
    LiveBackend backend;
    const char* label;
};
constexpr Variant kVariants[] = {
    {LiveMethod::JacobiCg, LiveBackend::Cpu, "cpu_jacobi"},
    {LiveMethod::MultigridCg, LiveBackend::Cpu, "cpu_mgcg"},
    {LiveMethod::JacobiCg, LiveBackend::Gpu, "gpu_cg_llvmpipe"},
    {LiveMethod::Multires, LiveBackend::Cpu, "cpu_multires"},
    {LiveMethod::Multires, LiveBackend::Gpu, "gpu_multires_llvmpipe"},
    {LiveMethod::MultigridCg, LiveBackend::Gpu, "gpu_mgcg_llvmpipe"},
};

LiveSceneOptions scene_options(const TetMesh& mesh, const Variant& variant) {
    LiveSceneOptions o = bench::live_scene_options(mesh);
    o.method = variant.method;
    o.backend = variant.backend;
    return o;
}

using bench::turning_light;

// max |a - b| / max |b| over vertices and channels.
double relative_difference(const std::vector<std::array<double, 3>>& a, const std::vector<std::array<double, 3>>& b) {
    double largest = 0, difference = 0;
    for (size_t v = 0; v < std::min(a.size(), b.size()); ++v)
        for (int c = 0; c < 3; ++c) {
            largest = std::max(largest, std::abs(b[v][c]));
            difference = std::max(difference, std::abs(a[v][c] - b[v][c]));
        }
    return largest > 0 ? difference / largest : -1;
}

// max over channels of sqrt(sum (a - b)^2 / sum b^2): the measure of bench/multires_bench.cpp.
double relative_l2_error(const std::vector<std::array<double, 3>>& a, const std::vector<std::array<double, 3>>& b) {
    double largest = 0;
    for (int c = 0; c < 3; ++c) {
        double e = 0, norm = 0;
        for (size_t v = 0; v < std::min(a.size(), b.size()); ++v) {
            e += (a[v][c] - b[v][c]) * (a[v][c] - b[v][c]);
            norm += b[v][c] * b[v][c];
        }
        largest = std::max(largest, norm > 0 ? std::sqrt(e / norm) : -1.0);
    }
    return largest;
}

// The scene's phi against the same scene converged far below the frames' tolerance.
void true_errors(benchmark::State& state, const TetMesh& mesh, const LiveScene& scene) {
    LiveSceneOptions o = scene.options();
    o.method = LiveMethod::JacobiCg;
    o.backend = LiveBackend::Cpu;
    o.relative_tolerance = 1e-8;
    LiveScene reference(mesh, scene.lighting(), o);
    reference.converge(100000);
    state.counters["true_error"] = relative_difference(scene.phi(), reference.phi());
    state.counters["true_error_l2"] = relative_l2_error(scene.phi(), reference.phi());
}

void report(benchmark::State& state, std::vector<double> ms, const LiveScene& scene, int iterations,
            const TetMesh& mesh) {
    std::sort(ms.begin(), ms.end());
    state.counters["median_ms"] = ms[ms.size() / 2];
    state.counters["p90_ms"] = ms[static_cast<size_t>(0.9 * (ms.size() - 1))];
    state.counters["median_fps"] = 1000.0 / ms[ms.size() / 2];
    state.counters["cg_its_per_frame"] = static_cast<double>(iterations) / ms.size();
    state.counters["final_error"] = scene.estimated_error().value_or(-1);
    true_errors(state, mesh, scene);
    if (scene.backend() != kVariants[state.range(0)].backend)
        state.SkipWithError(("fell back to the CPU: " + scene.gpu_fallback_reason()).c_str());
    state.SetLabel(scene.solver_description());
}

void BM_RelightFrames(benchmark::State& state) {
    const Variant& variant = kVariants[state.range(0)];
    Document doc(bench::spot_volume(kFrameTets), material_preset("marble"));
    LiveScene scene(doc.mesh(), turning_light(0), scene_options(doc.mesh(), variant));
    scene.converge();
    std::vector<double> ms;
    int iterations = 0;
    for (auto _ : state) {
        for (int f = 1; f <= kFrames; ++f) {
            const auto start = Clock::now();
            scene.set_lighting(turning_light(3.0 * f));
            iterations += scene.step(kFrameIterations).total_iterations();
            benchmark::DoNotOptimize(scene.radiance_factors().data());
            ms.push_back(milliseconds_since(start));
        }
    }
    report(state, ms, scene, iterations, doc.mesh());
}
BENCHMARK(BM_RelightFrames)->DenseRange(0, 5)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PaintFrames(benchmark::State& state) {
    const Variant& variant = kVariants[state.range(0)];
    Document doc(bench::spot_volume(kFrameTets), material_preset("marble"));
    LiveScene scene(doc.mesh(), turning_light(0), scene_options(doc.mesh(), variant));
    scene.converge();
    const auto box = bounding_box(doc.mesh());
    std::vector<double> ms;
    int iterations = 0;
    for (auto _ : state) {
        for (int f = 0; f < kFrames; ++f) {
            const PaintOp op = bench::body_stroke_dab(box, f, kFrames);
            const auto start = Clock::now();
            scene.apply_change(doc.mesh(), doc.apply(op));
            iterations += scene.step(kFrameIterations).total_iterations();
            benchmark::DoNotOptimize(scene.radiance_factors().data());
            ms.push_back(milliseconds_since(start));
        }
    }
    report(state, ms, scene, iterations, doc.mesh());
}
BENCHMARK(BM_PaintFrames)->DenseRange(0, 5)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// The first frame after a plane cut through the middle (a new matrix): scene_ms is the scene's rebuild
// (for multigrid CG and multires including the hierarchy), frame_ms one frame of the usual budget from
// the cut's warm start (the old phi through the vertex map; multires corrects it with its
// coarse-to-fine pass first, MultiresSolver::set_warm_start), true_error as above after that frame.
void BM_FirstFrameAfterCut(benchmark::State& state) {
    const Variant& variant = kVariants[state.range(0)];
    Document doc(bench::spot_volume(kFrameTets), material_preset("marble"));
    LiveScene scene(doc.mesh(), turning_light(0), scene_options(doc.mesh(), variant));
    scene.converge();
    const PlaneCutOp cut = bench::middle_cut(doc.mesh());
    double scene_ms = 0, frame_ms = 0;
    int iterations = 0;
    for (auto _ : state) {
        const SceneUpdate update = scene.apply_change(doc.mesh(), doc.apply(cut));
        scene_ms = update.milliseconds;
        const auto start = Clock::now();
        iterations = scene.step(kFrameIterations).total_iterations();
        benchmark::DoNotOptimize(scene.radiance_factors().data());
        frame_ms = milliseconds_since(start);
    }
    state.counters["scene_ms"] = scene_ms;
    state.counters["frame_ms"] = frame_ms;
    state.counters["cg_its"] = iterations;
    true_errors(state, doc.mesh(), scene);
    if (scene.backend() != variant.backend)
        state.SkipWithError(("fell back to the CPU: " + scene.gpu_fallback_reason()).c_str());
    state.SetLabel(scene.solver_description());
}
BENCHMARK(BM_FirstFrameAfterCut)->DenseRange(0, 5)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// From a plane cut to a settled image: the scene's rebuild (scene_ms) and then frames of the usual
// budget until the true error (true_error_l2 as above, against the cut volume converged to 1e-8 with
// CPU Jacobi CG, measured outside the timing) is under 1% (settle_ms, frames) and until the solver
// reports convergence at the scene's tolerance (converged_ms); the document's cut itself, the same
// for every method, is not timed. The measure behind the editor's default method: a method whose
// rebuild costs more must win it back in fewer frames. CPU methods only (the GPU ones run on llvmpipe
// here); range(1): tets.
//   ./build/bench/live_solver_bench --benchmark_filter=BM_CutToSettledImage
void BM_CutToSettledImage(benchmark::State& state) {
    const Variant& variant = kVariants[state.range(0)];
    Document doc(bench::spot_volume(static_cast<size_t>(state.range(1))), material_preset("marble"));
    LiveScene scene(doc.mesh(), turning_light(0), scene_options(doc.mesh(), variant));
    scene.converge();
    const PlaneCutOp cut = bench::middle_cut(doc.mesh());
    constexpr int kMaxFrames = 400;
    double scene_ms = 0, settle_ms = -1, converged_ms = -1;
    int frames_to_settle = -1, frames_to_converge = -1;
    for (auto _ : state) {
        const ChangeReport report = doc.apply(cut);
        // The reference first, so that its work is not inside the timed frames.
        LiveSceneOptions o = scene.options();
        o.method = LiveMethod::JacobiCg;
        o.relative_tolerance = 1e-8;
        LiveScene reference(doc.mesh(), scene.lighting(), o);
        reference.converge(100000);
        const auto start = Clock::now();
        scene_ms = scene.apply_change(doc.mesh(), report).milliseconds;
        double paused_ms = 0;  // error measurements, excluded
        for (int f = 1; f <= kMaxFrames && (frames_to_settle < 0 || frames_to_converge < 0); ++f) {
            const bool converged = scene.step(kFrameIterations).converged;
            benchmark::DoNotOptimize(scene.radiance_factors().data());
            const double now_ms = milliseconds_since(start) - paused_ms;
            if (converged && frames_to_converge < 0) {
                frames_to_converge = f;
                converged_ms = now_ms;
            }
            const auto pause = Clock::now();
            if (frames_to_settle < 0 && relative_l2_error(scene.phi(), reference.phi()) < 0.01) {
                frames_to_settle = f;
                settle_ms = now_ms;
            }
            paused_ms += milliseconds_since(pause);
        }
    }
    state.counters["scene_ms"] = scene_ms;
    state.counters["settle_ms"] = settle_ms;
    state.counters["frames_to_settle"] = frames_to_settle;
    state.counters["converged_ms"] = converged_ms;
    state.counters["frames_to_converge"] = frames_to_converge;
    if (frames_to_settle < 0) state.SkipWithError("not under 1% true error within the frame limit");
    state.SetLabel(scene.solver_description());
}
BENCHMARK(BM_CutToSettledImage)
    ->ArgsProduct({{0, 1, 3}, {static_cast<long>(kFrameTets), 500'000}})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Frames with a time budget instead of iterations (solver/frame_budget.h, `--frame-ms`): the light
// turns 3 degrees per frame as in BM_RelightFrames and each frame's solver step gets kFrameBudgetMs.
// step_* is the solver step alone (what the budget limits), over_* how far it went past the budget
// (an iteration or V-cycle that started finishes; with three channels one after the other, each gets
// its share), frame_* the whole frame (light + step + radiance), its_per_frame the iterations per
// frame summed over channels (multigrid CG: V-cycles, counted once per channel). The GPU Jacobi and
// multires rows turn the budget into a predicted iteration count (iteration_time_predictor.h); the GPU
// multigrid checks the deadline between V-cycles; on llvmpipe.
//   ./build/bench/live_solver_bench --benchmark_filter=BM_RelightFramesWithinBudget
constexpr double kFrameBudgetMs = 10;

double percentile(std::vector<double> v, double p) {
    std::sort(v.begin(), v.end());
    return v[static_cast<size_t>(p * static_cast<double>(v.size() - 1))];
}

void BM_RelightFramesWithinBudget(benchmark::State& state) {
    const Variant& variant = kVariants[state.range(0)];
    Document doc(bench::spot_volume(kFrameTets), material_preset("marble"));
    LiveScene scene(doc.mesh(), turning_light(0), scene_options(doc.mesh(), variant));
    scene.converge();
    const FrameBudget budget = FrameBudget::milliseconds(kFrameBudgetMs);
    std::vector<double> frame_ms, step_ms, over_ms;
    int iterations = 0;
    for (auto _ : state) {
        for (int f = 1; f <= kFrames; ++f) {
            const auto start = Clock::now();
            scene.set_lighting(turning_light(3.0 * f));
            const auto step_start = Clock::now();
            iterations += scene.step(budget).total_iterations();
            step_ms.push_back(milliseconds_since(step_start));
            benchmark::DoNotOptimize(scene.radiance_factors().data());
            frame_ms.push_back(milliseconds_since(start));
            over_ms.push_back(step_ms.back() - kFrameBudgetMs);
        }
    }
    state.counters["budget_ms"] = kFrameBudgetMs;
    state.counters["step_median_ms"] = percentile(step_ms, 0.5);
    state.counters["step_p90_ms"] = percentile(step_ms, 0.9);
    state.counters["step_max_ms"] = percentile(step_ms, 1.0);
    state.counters["over_median_ms"] = percentile(over_ms, 0.5);
    state.counters["over_p90_ms"] = percentile(over_ms, 0.9);
    state.counters["frame_median_ms"] = percentile(frame_ms, 0.5);
    state.counters["frame_p90_ms"] = percentile(frame_ms, 0.9);
    state.counters["its_per_frame"] = static_cast<double>(iterations) / kFrames;
    state.counters["final_error"] = scene.estimated_error().value_or(-1);
    true_errors(state, doc.mesh(), scene);
    if (scene.backend() != variant.backend)
        state.SkipWithError(("fell back to the CPU: " + scene.gpu_fallback_reason()).c_str());
    state.SetLabel(scene.solver_description());
}
BENCHMARK(BM_RelightFramesWithinBudget)->DenseRange(0, 5)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace waxwork

WAXWORK_BENCHMARK_MAIN()
