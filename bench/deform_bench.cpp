// As-rigid-as-possible deformation (tetops/arap_deformation.h) on spot at 100K and 500K tets: the
// factorisation when the handle changes, one drag frame's local/global iterations, and how many
// iterations per frame keep the energy within 1% of converged while dragging.
// Targets: factorisation <= 1 s at 100K; a frame's iterations within a 30 fps budget at 100K (with
// the lighting), >= 10 fps at 500K.
#include "scene/document.h"
#include "scene/live_scene.h"
#include "solver/material.h"
#include "tetops/arap_deformation.h"
#include "tetops/connectivity.h"
#include "bench_main.h"
#include "bench_meshes.h"
#include "live_scene_setup.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <string>

namespace waxwork {
namespace {

using Clock = std::chrono::steady_clock;

// The drag every benchmark runs: the handle at spot's highest vertex (radius 15% of the bounding-box
// diagonal), a pin at its lowest (20%), moved by 10% of the diagonal sideways and up.
struct DragSetup {
    const TetMesh& mesh;
    TetConnectivity connectivity;
    DragRegion region;
};

const DragSetup& drag_setup(size_t target_tets) {
    static std::map<size_t, std::unique_ptr<DragSetup>> cache;
    std::unique_ptr<DragSetup>& slot = cache[target_tets];
    if (!slot) {
        const TetMesh& mesh = bench::spot_volume(target_tets);
        slot = std::make_unique<DragSetup>(DragSetup{mesh, build_connectivity(mesh), {}});
        const auto box = bounding_box(mesh);
        const double diagonal = (box[1] - box[0]).norm();
        auto by_y = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.y() < b.y(); };
        const Eigen::Vector3d top = *std::max_element(mesh.positions.begin(), mesh.positions.end(), by_y);
        const Eigen::Vector3d bottom = *std::min_element(mesh.positions.begin(), mesh.positions.end(), by_y);
        const PinSphere pin{bottom, 0.2 * diagonal};
        slot->region = select_drag_region(mesh, slot->connectivity, top, 0.15 * diagonal,
                                          HandleMotion::translation(0.1 * diagonal * Eigen::Vector3d(1, 0.5, 0.5).normalized()), std::span(&pin, 1));
    }
    return *slot;
}

void add_size_counters(benchmark::State& state, const DragSetup& s) {
    state.counters["tets"] = static_cast<double>(s.mesh.tet_count());
    state.counters["vertices"] = static_cast<double>(s.mesh.vertex_count());
    state.counters["constrained"] = static_cast<double>(s.region.handle.size() + s.region.pinned.size());
}

// Benchmark arguments for ArapOptions: the factor (0 CHOLMOD simplicial solves, 1 CHOLMOD supernodal,
// 2 Eigen SimplicialLLT) and the rotations (0 double, 1 float).
ArapOptions arap_options(int64_t factor, int64_t rotations) {
    ArapOptions o;
    o.factor = factor == 0 ? ArapFactor::CholmodSimplicialSolves
                           : factor == 1 ? ArapFactor::CholmodSupernodal : ArapFactor::EigenSimplicialLLT;
    o.rotations = rotations == 0 ? ArapRotations::Double : ArapRotations::Float;
    return o;
}

// The handle's fraction of the move in drag frame `frame`: 1/30 more per frame, back and forth.
double drag_phase(int frame) {
    const int phase = frame % 60;
    return (phase < 30 ? phase + 1 : 60 - phase) / 30.0;
}

// What a change of handle costs: the per-tet operators and the Cholesky factorisation (range(1): the
// factor, as arap_options).
void BM_ArapFactorize(benchmark::State& state) {
    const DragSetup& s = drag_setup(static_cast<size_t>(state.range(0)));
    for (auto _ : state) {
        ArapDeformer deformer(s.mesh, s.region.body_tets, arap_options(state.range(1), 0));
        deformer.set_constrained(s.region.constrained());
        benchmark::DoNotOptimize(deformer.positions().data());
    }
    add_size_counters(state, s);
    state.counters["factor"] = static_cast<double>(state.range(1));
}
BENCHMARK(BM_ArapFactorize)
    ->Args({100'000, 0})
    ->Args({100'000, 1})
    ->Args({100'000, 2})
    ->Args({500'000, 0})
    ->Args({500'000, 1})
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One drag frame: range(1) local/global iterations warm-started from the previous frame, the handle
// advancing by 1/30 of the move per frame (back and forth); range(2) and range(3) the options (as
// arap_options).
void BM_ArapDragFrame(benchmark::State& state) {
    const DragSetup& s = drag_setup(static_cast<size_t>(state.range(0)));
    const int iterations = static_cast<int>(state.range(1));
    ArapDeformer deformer(s.mesh, s.region.body_tets, arap_options(state.range(2), state.range(3)));
    deformer.set_constrained(s.region.constrained());
    int frame = 0;
    for (auto _ : state) {
        const std::vector<Eigen::Vector3d> targets = drag_targets(s.region, s.mesh.positions, drag_phase(frame++));
        benchmark::DoNotOptimize(deformer.solve(targets, iterations).energy);
    }
    add_size_counters(state, s);
    state.counters["iterations"] = iterations;
    state.counters["factor"] = static_cast<double>(state.range(2));
    state.counters["float_rotations"] = static_cast<double>(state.range(3));
}
BENCHMARK(BM_ArapDragFrame)
    ->Args({100'000, 1, 1, 0})
    ->Args({100'000, 1, 0, 1})
    ->Args({100'000, 4, 1, 0})
    ->Args({100'000, 4, 0, 1})
    ->Args({500'000, 1, 1, 0})
    ->Args({500'000, 1, 0, 1})
    ->Args({500'000, 4, 1, 0})
    ->Args({500'000, 4, 0, 1})
    ->Iterations(10)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The options side by side on one machine state: a drag of one iteration per frame run by each
// variant in turn, frame after frame (the machine's load changes alike for all of them). Counters:
// each variant's median milliseconds per frame (`<name>_ms`), and how far the float rotations' drag
// is from the double one after the frames (energy relative to it, largest vertex distance relative to
// the bounding-box diagonal).
void BM_ArapVariantsInterleaved(benchmark::State& state) {
    const DragSetup& s = drag_setup(static_cast<size_t>(state.range(0)));
    struct Variant {
        const char* name;
        ArapOptions options;
        std::unique_ptr<ArapDeformer> deformer;
        std::vector<double> ms;
        double energy = 0;
    };
    std::vector<Variant> variants;
    variants.push_back({"supernodal_double", arap_options(1, 0), {}, {}});
    variants.push_back({"simplicial_double", arap_options(0, 0), {}, {}});
    variants.push_back({"simplicial_float", arap_options(0, 1), {}, {}});
    if (state.range(1)) variants.push_back({"eigen_llt_double", arap_options(2, 0), {}, {}});
    for (Variant& v : variants) {
        v.deformer = std::make_unique<ArapDeformer>(s.mesh, s.region.body_tets, v.options);
        v.deformer->set_constrained(s.region.constrained());
    }
    int frame = 0;
    for (auto _ : state) {
        const std::vector<Eigen::Vector3d> targets = drag_targets(s.region, s.mesh.positions, drag_phase(frame++));
        for (Variant& v : variants) {
            const auto start = Clock::now();
            v.energy = v.deformer->solve(targets, 1).energy;
            v.ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
        }
    }
    add_size_counters(state, s);
    for (Variant& v : variants) {
        std::nth_element(v.ms.begin(), v.ms.begin() + v.ms.size() / 2, v.ms.end());
        state.counters[std::string(v.name) + "_ms"] = v.ms[v.ms.size() / 2];
    }
    const ArapDeformer& dbl = *variants[1].deformer;
    const ArapDeformer& flt = *variants[2].deformer;
    const auto box = bounding_box(s.mesh);
    double farthest = 0;
    for (size_t v = 0; v < s.mesh.vertex_count(); ++v)
        farthest = std::max(farthest, (dbl.positions()[v] - flt.positions()[v]).norm());
    state.counters["float_energy_relative"] = variants[2].energy / variants[1].energy - 1;
    state.counters["float_farthest_relative"] = farthest / (box[1] - box[0]).norm();
}
BENCHMARK(BM_ArapVariantsInterleaved)
    ->Args({100'000, 1})
    ->Args({500'000, 0})
    ->Iterations(20)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The guard every drag frame runs after its iterations (guard_step over the body's tets), when the
// whole step passes: one minimum-dihedral and volume check of every tet.
void BM_ArapGuardStep(benchmark::State& state) {
    const DragSetup& s = drag_setup(static_cast<size_t>(state.range(0)));
    ArapDeformer deformer(s.mesh, s.region.body_tets);
    deformer.set_constrained(s.region.constrained());
    deformer.solve(drag_targets(s.region, s.mesh.positions, 1.0 / 30), 2);
    for (auto _ : state) {
        const GuardedStep step = guard_step(s.mesh, s.region.body_tets, s.mesh.positions, deformer.positions());
        benchmark::DoNotOptimize(step.min_dihedral_deg);
        state.counters["halvings"] = step.halvings;
    }
    add_size_counters(state, s);
}
BENCHMARK(BM_ArapGuardStep)->Arg(100'000)->Iterations(10)->Unit(benchmark::kMillisecond)->UseRealTime();

// The drag in 10 frames of k iterations each; counters: the final energy's excess over converged (the
// same final targets after 200 more iterations from the k = 8 drag), in percent.
void BM_ArapIterationsPerFrame(benchmark::State& state) {
    const DragSetup& s = drag_setup(static_cast<size_t>(state.range(0)));
    const int frames = 10;
    static std::map<size_t, double> converged;
    const std::vector<Eigen::Vector3d> final_targets = drag_targets(s.region, s.mesh.positions, 1.0);
    if (!converged.count(s.mesh.tet_count())) {
        ArapDeformer reference(s.mesh, s.region.body_tets);
        reference.set_constrained(s.region.constrained());
        for (int f = 1; f <= frames; ++f) reference.solve(drag_targets(s.region, s.mesh.positions, f / double(frames)), 8);
        converged[s.mesh.tet_count()] = reference.solve(final_targets, 200).energy;
    }
    const int k = static_cast<int>(state.range(1));
    double energy = 0;
    for (auto _ : state) {
        ArapDeformer deformer(s.mesh, s.region.body_tets);
        deformer.set_constrained(s.region.constrained());
        for (int f = 1; f <= frames; ++f)
            energy = deformer.solve(drag_targets(s.region, s.mesh.positions, f / double(frames)), k).energy;
    }
    add_size_counters(state, s);
    state.counters["iterations_per_frame"] = k;
    state.counters["energy"] = energy;
    state.counters["converged_energy"] = converged[s.mesh.tet_count()];
    state.counters["excess_percent"] = 100 * (energy / converged[s.mesh.tet_count()] - 1);
}
// A whole editor drag frame, as the Grab tool runs it: Document::preview_deform with range(1)
// iterations warm-started from the previous frame, the live scene's update (the moved rows of the
// matrix on the kept pattern, the surface, shadows and q) and one warm solver frame of
// kFrameIterations Jacobi-CG iterations per channel; the handle advances by 1/30 of the move per
// frame. Counters: each part's milliseconds per frame.
void BM_DeformDragFrameWithLight(benchmark::State& state) {
    const DragSetup& s = drag_setup(static_cast<size_t>(state.range(0)));
    const int iterations = static_cast<int>(state.range(1));
    Document document(s.mesh, material_preset("marble"));
    const Lighting lighting = bench::turning_light(0);
    LiveScene scene(document.mesh(), lighting, bench::live_scene_options(s.mesh));
    scene.converge();
    DeformOp op;
    // The region drag_setup selected, as an operation: same grab, radius and pin.
    const auto box = bounding_box(s.mesh);
    const double diagonal = (box[1] - box[0]).norm();
    auto by_y = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.y() < b.y(); };
    op.grab = *std::max_element(s.mesh.positions.begin(), s.mesh.positions.end(), by_y);
    op.radius = 0.15 * diagonal;
    op.pins = {PinSphere{*std::min_element(s.mesh.positions.begin(), s.mesh.positions.end(), by_y), 0.2 * diagonal}};
    const Eigen::Vector3d move = 0.1 * diagonal * Eigen::Vector3d(1, 0.5, 0.5).normalized();
    double arap_ms = 0, scene_ms = 0, solve_ms = 0;
    int frame = 0;
    const auto advance = [&] {
        op.motion = HandleMotion::translation(drag_phase(frame++) * move);
    };
    // The press: region, operators and factorisation (BM_ArapFactorize), not part of a drag frame.
    advance();
    scene.apply_change(document.mesh(), document.preview_deform(op, iterations));
    scene.step(bench::kFrameIterations);
    const int first_timed = frame;
    for (auto _ : state) {
        advance();
        const auto start = Clock::now();
        const ChangeReport report = document.preview_deform(op, iterations);
        const auto moved = Clock::now();
        scene.apply_change(document.mesh(), report);
        const auto updated = Clock::now();
        scene.step(bench::kFrameIterations);
        const auto solved = Clock::now();
        arap_ms += std::chrono::duration<double, std::milli>(moved - start).count();
        scene_ms += std::chrono::duration<double, std::milli>(updated - moved).count();
        solve_ms += std::chrono::duration<double, std::milli>(solved - updated).count();
    }
    add_size_counters(state, s);
    state.counters["iterations"] = iterations;
    const double frames = frame - first_timed;
    state.counters["arap_ms"] = arap_ms / frames;
    state.counters["scene_update_ms"] = scene_ms / frames;
    state.counters["solve_ms"] = solve_ms / frames;
}
BENCHMARK(BM_DeformDragFrameWithLight)
    ->Args({100'000, 1})
    ->Args({100'000, 2})
    ->Args({500'000, 1})
    ->Iterations(10)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK(BM_ArapIterationsPerFrame)
    ->Args({100'000, 1})
    ->Args({100'000, 2})
    ->Args({100'000, 4})
    ->Args({100'000, 8})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace waxwork

WAXWORK_BENCHMARK_MAIN()
