// The live editor's frame loop on spot: the per-frame CPU solve while the light rotates and
// while a brush paints, and the edits at the paper's scale with everything the solver needs rebuilt.
// Goals: >= 30 fps at ~100K tets while relighting and painting; a cut including connectivity,
// matrices and lighting <= 500 ms and a 100-point paint stroke including the row updates <= 20 ms at
// 500K tets.
//   ./build/bench/live_scene_bench
// Frame counters: median / p90 / max wall milliseconds over the frames of one sequence, and the median
// and p90 process CPU milliseconds (all threads; on an idle two-core machine a frame's wall time lies
// between half of it and all of it). The edit benchmarks' CPU column is the whole process too.
#include "base/timing.h"
#include "scene/document.h"
#include "scene/live_scene.h"
#include "solver/material.h"
#include "bench_main.h"
#include "bench_meshes.h"
#include "live_scene_setup.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <numbers>

namespace waxwork {
namespace {

using Clock = std::chrono::steady_clock;

using bench::kEditTets;
using bench::kFrameIterations;
using bench::kFrameTets;
constexpr int kFrames = 90;

// CPU time of the whole process (all TBB threads), in ms: on a shared machine wall time includes
// waiting for a core; this does not.
double process_cpu_ms() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

using bench::turning_light;
void report_frames(benchmark::State& state, std::vector<double> ms, std::vector<double> cpu) {
    std::sort(cpu.begin(), cpu.end());
    state.counters["median_cpu_ms"] = cpu[cpu.size() / 2];
    state.counters["p90_cpu_ms"] = cpu[static_cast<size_t>(0.9 * (cpu.size() - 1))];
    std::sort(ms.begin(), ms.end());
    state.counters["frames"] = static_cast<double>(ms.size());
    state.counters["median_ms"] = ms[ms.size() / 2];
    state.counters["p90_ms"] = ms[static_cast<size_t>(0.9 * (ms.size() - 1))];
    state.counters["max_ms"] = ms.back();
    state.counters["median_fps"] = 1000.0 / ms[ms.size() / 2];
}

// One frame as the window runs it: the solver step, then the radiance the renderer uploads.
void frame(LiveScene& scene, int& iterations) {
    iterations += scene.step(kFrameIterations).total_iterations();
    benchmark::DoNotOptimize(scene.radiance_factors().data());
}

void BM_RelightFrames(benchmark::State& state) {
    Document doc(bench::spot_volume(kFrameTets), material_preset("marble"));
    LiveScene scene(doc.mesh(), turning_light(0), bench::live_scene_options(doc.mesh()));
    scene.converge();
    std::vector<double> ms, cpu;
    int iterations = 0;
    for (auto _ : state) {
        for (int f = 1; f <= kFrames; ++f) {
            const auto start = Clock::now();
            const double cpu_start = process_cpu_ms();
            scene.set_lighting(turning_light(3.0 * f));  // a few degrees per frame
            frame(scene, iterations);
            ms.push_back(milliseconds_since(start));
            cpu.push_back(process_cpu_ms() - cpu_start);
        }
    }
    report_frames(state, ms, cpu);
    state.counters["tets"] = static_cast<double>(doc.mesh().tet_count());
    state.counters["cg_its_per_frame"] = static_cast<double>(iterations) / ms.size();
    state.counters["final_error"] = scene.estimated_error().value_or(-1);
}
BENCHMARK(BM_RelightFrames)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// A stroke point per frame: paint (one undoable operation), matrix row update, solver step.
void BM_PaintFrames(benchmark::State& state) {
    Document doc(bench::spot_volume(kFrameTets), material_preset("marble"));
    LiveScene scene(doc.mesh(), turning_light(0), bench::live_scene_options(doc.mesh()));
    scene.converge();
    const auto box = bounding_box(doc.mesh());
    std::vector<double> ms, cpu;
    int iterations = 0;
    size_t rows = 0;
    for (auto _ : state) {
        for (int f = 0; f < kFrames; ++f) {
            const PaintOp op = bench::body_stroke_dab(box, f, kFrames);
            const auto start = Clock::now();
            const double cpu_start = process_cpu_ms();
            rows += scene.apply_change(doc.mesh(), doc.apply(op)).updated_rows.size();
            frame(scene, iterations);
            ms.push_back(milliseconds_since(start));
            cpu.push_back(process_cpu_ms() - cpu_start);
        }
    }
    report_frames(state, ms, cpu);
    state.counters["tets"] = static_cast<double>(doc.mesh().tet_count());
    state.counters["rows_per_frame"] = static_cast<double>(rows) / ms.size();
    state.counters["cg_its_per_frame"] = static_cast<double>(iterations) / ms.size();
}
BENCHMARK(BM_PaintFrames)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// The cut as the editor pays for it: tets removed, connectivity, 10 relaxation sweeps, undo snapshot
// (Document::apply), then the live scene's rebuild of matrix, boundary, shadow BVH and q. Not included:
// the solver frames after it.
void BM_CutWithRebuild(benchmark::State& state) {
    const TetMesh& source = bench::spot_volume(kEditTets);
    const PlaneCutOp cut = bench::middle_cut(source);
    double apply_ms = 0, scene_ms = 0, undo_mib = 0;
    size_t tets_after = 0;
    for (auto _ : state) {
        state.PauseTiming();
        Document doc(source, material_preset("marble"));
        LiveScene scene(doc.mesh(), turning_light(0), bench::live_scene_options(doc.mesh()));
        state.ResumeTiming();
        const ChangeReport report = doc.apply(cut);
        const SceneUpdate update = scene.apply_change(doc.mesh(), report);
        apply_ms = report.milliseconds;
        scene_ms = update.milliseconds;
        tets_after = doc.mesh().tet_count();
        undo_mib = doc.undo_bytes() / double(1 << 20);
    }
    state.counters["tets_before"] = static_cast<double>(source.tet_count());
    state.counters["tets_after"] = static_cast<double>(tets_after);
    state.counters["document_ms"] = apply_ms;
    state.counters["scene_ms"] = scene_ms;
    state.counters["undo_MiB"] = undo_mib;  // the snapshot the cut keeps for undo
}
BENCHMARK(BM_CutWithRebuild)->Iterations(3)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

// A 100-point stroke (one operation) with the undo delta and the matrix row updates; the paint index
// is built by a first stroke outside the timing (it lives until the geometry changes).
void BM_PaintStrokeWithRowUpdates(benchmark::State& state) {
    Document doc(bench::spot_volume(kEditTets), material_preset("marble"));
    LiveScene scene(doc.mesh(), turning_light(0), bench::live_scene_options(doc.mesh()));
    const auto box = bounding_box(doc.mesh());
    const Eigen::Vector3d centre = 0.5 * (box[0] + box[1]);
    const double diagonal = (box[1] - box[0]).norm();
    PaintOp stroke;
    for (int i = 0; i < 100; ++i)
        stroke.points.push_back(centre + Eigen::Vector3d(0, 0.075 * diagonal, (i / 99.0 - 0.5) * 0.5 * diagonal));
    stroke.material = material_preset("ketchup");
    stroke.sigma = 0.01 * diagonal;
    scene.apply_change(doc.mesh(), doc.apply(stroke));  // builds the paint index
    size_t tets = 0, rows = 0;
    double document_ms = 0, scene_ms = 0;
    size_t undo_before = doc.undo_bytes(), undo_bytes = 0;
    for (auto _ : state) {
        stroke.material.mua[1] *= 1.01;  // a slightly different brush each time: every tet changes
        const ChangeReport report = doc.apply(stroke);
        const SceneUpdate update = scene.apply_change(doc.mesh(), report);
        rows = update.updated_rows.size();
        scene_ms = update.milliseconds;
        tets = report.changed_material_tets.size();
        document_ms = report.milliseconds;
        undo_bytes = doc.undo_bytes() - undo_before;
        undo_before = doc.undo_bytes();
    }
    state.counters["tets"] = static_cast<double>(doc.mesh().tet_count());
    state.counters["tets_painted"] = static_cast<double>(tets);
    state.counters["rows_updated"] = static_cast<double>(rows);
    state.counters["document_ms"] = document_ms;
    state.counters["scene_ms"] = scene_ms;
    state.counters["undo_KiB"] = undo_bytes / 1024.0;  // the delta one stroke keeps for undo
}
BENCHMARK(BM_PaintStrokeWithRowUpdates)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

}  // namespace
}  // namespace waxwork

WAXWORK_BENCHMARK_MAIN()
