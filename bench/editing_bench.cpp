// Editing at the paper's scale (TransCut Sec. 5, Table 1: 500K-1M tets): a plane cut through spot with
// relaxation and the connectivity rebuild the solver needs afterwards, the exact cut, fracture
// into 8 pieces, and a 100-point paint stroke.
// Goals: cut + connectivity + 10 relaxation sweeps <= 500 ms; fracture into 8 pieces <= 1 s; paint
// stroke <= 20 ms. BM_CrossSectionAccuracy charts how far the cross-section is from the plane and the
// worst dihedral angle for both cut modes (counters; --benchmark_format=json for the chart):
//   ./build/bench/editing_bench
//   ./build/bench/editing_bench --benchmark_filter=CrossSection --benchmark_format=json
#include "bench/studies/cut_study.h"
#include "solver/material.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/exact_cut.h"
#include "tetops/fracture.h"
#include "tetops/paint.h"
#include "tetops/quality.h"
#include "tetops/relaxation.h"
#include "bench_main.h"
#include "bench_meshes.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <set>

namespace waxwork {
namespace {

constexpr size_t kTets = 500'000;

// A slanted plane through the middle of the bounding box: cuts across the whole model.
PlaneCut middle_plane(const TetMesh& mesh) {
    const auto box = bounding_box(mesh);
    const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 0.3, 0.2).normalized();
    return PlaneCut(normal, normal.dot(0.5 * (box[0] + box[1])));
}

// Arg 0: guard in degrees (0.5 as in the paper; 0 shows Fig. 9(a)'s flattened tets).
void BM_CutRelaxConnectivity(benchmark::State& state) {
    const TetMesh& source = bench::spot_volume(kTets);
    const PlaneCut plane = middle_plane(source);
    RelaxationOptions options;
    options.max_iterations = 10;
    options.min_dihedral_guard_deg = static_cast<double>(state.range(0)) / 10.0;
    RelaxationReport report;
    size_t tets_after = 0;
    for (auto _ : state) {
        state.PauseTiming();
        TetMesh mesh = source;
        state.ResumeTiming();
        remove_cut_away_tets(mesh, plane);
        // Relaxation moves vertices only, so the connectivity built here stays valid for the solver.
        const TetConnectivity connectivity = build_connectivity(mesh);
        report = relax_cut_vertices(mesh, connectivity, plane, options);
        benchmark::DoNotOptimize(connectivity.edges.data());
        tets_after = mesh.tet_count();
    }
    state.counters["tets_before"] = static_cast<double>(source.tet_count());
    state.counters["tets_after"] = static_cast<double>(tets_after);
    state.counters["movable"] = static_cast<double>(report.movable_vertices);
    state.counters["moved"] = static_cast<double>(report.vertices_moved);
    state.counters["rejected"] = static_cast<double>(report.moves_rejected);
    state.counters["min_dihedral_deg"] = report.min_dihedral_deg;
}
BENCHMARK(BM_CutRelaxConnectivity)->Arg(5)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();

// The stages of the cut on their own, to see where the time goes.
void BM_CutOnly(benchmark::State& state) {
    const TetMesh& source = bench::spot_volume(kTets);
    const PlaneCut plane = middle_plane(source);
    for (auto _ : state) {
        state.PauseTiming();
        TetMesh mesh = source;
        state.ResumeTiming();
        benchmark::DoNotOptimize(remove_cut_away_tets(mesh, plane).tets_removed);
    }
}
BENCHMARK(BM_CutOnly)->Unit(benchmark::kMillisecond)->UseRealTime();

// The exact cut and the connectivity rebuild after it (no relaxation needed).
void BM_ExactCutConnectivity(benchmark::State& state) {
    const TetMesh& source = bench::spot_volume(kTets);
    const PlaneCut plane = middle_plane(source);
    ExactCutResult result;
    size_t tets_after = 0;
    for (auto _ : state) {
        state.PauseTiming();
        TetMesh mesh = source;
        state.ResumeTiming();
        result = cut_exact(mesh, plane);
        const TetConnectivity connectivity = build_connectivity(mesh);
        benchmark::DoNotOptimize(connectivity.edges.data());
        tets_after = mesh.tet_count();
    }
    state.counters["tets_before"] = static_cast<double>(source.tet_count());
    state.counters["tets_after"] = static_cast<double>(tets_after);
    state.counters["tets_split"] = static_cast<double>(result.tets_split);
    state.counters["snapped"] = static_cast<double>(result.vertices_snapped);
    state.counters["min_dihedral_deg"] = result.min_dihedral_deg;
    state.counters["tets_under_guard"] = static_cast<double>(result.tets_under_guard);
}
BENCHMARK(BM_ExactCutConnectivity)->Unit(benchmark::kMillisecond)->UseRealTime();

// Cross-section accuracy of both cut modes on spot (bench/studies/cut_study.h; `waxwork bench --only cut_modes`
// charts the distributions). Arg 0: 0 = remove + 10 relaxation sweeps with the 0.5 degree guard
// (TransCut Sec. 5), 1 = exact.
void BM_CrossSectionAccuracy(benchmark::State& state) {
    const TetMesh& source = bench::spot_volume(kTets);
    const size_t mode = static_cast<size_t>(state.range(0));
    CutModeResult result;
    for (auto _ : state) result = compare_cut_modes(source, middle_plane(source))[mode];
    state.counters["cross_section_vertices"] = static_cast<double>(result.distances_per_edge.size());
    state.counters["max_distance_per_edge"] = result.max_distance_per_edge();
    state.counters["rms_distance_per_edge"] = result.rms_distance_per_edge();
    state.counters["min_dihedral_deg"] = result.worst_dihedral_deg();
    state.counters["tets_below_5_deg"] = static_cast<double>(result.tets_below(5.0));
    state.counters["tets_after"] = static_cast<double>(result.tets_after);
    state.SetLabel(result.mode);
}
BENCHMARK(BM_CrossSectionAccuracy)->Arg(0)->Arg(1)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// Fracture into 8 Voronoi pieces (seed scattering included). Arg 0: 1 = exact (flat cracks), 0 = cracks
// on tet faces.
void BM_Fracture8(benchmark::State& state) {
    const TetMesh& source = bench::spot_volume(kTets);
    FractureOptions options;
    options.exact = state.range(0) == 1;
    FractureResult result;
    size_t tets_after = 0;
    for (auto _ : state) {
        state.PauseTiming();
        TetMesh mesh = source;
        state.ResumeTiming();
        const std::vector<Eigen::Vector3d> seeds = scatter_fracture_seeds(mesh, 8, 1);
        result = fracture_voronoi(mesh, seeds, options);
        tets_after = mesh.tet_count();
    }
    state.counters["tets_after"] = static_cast<double>(tets_after);
    state.counters["pieces"] = result.pieces_after;
    state.counters["tets_split"] = static_cast<double>(result.tets_split);
    state.counters["vertices_duplicated"] = static_cast<double>(result.vertices_duplicated);
    state.counters["min_dihedral_deg"] = result.min_dihedral_deg;
    state.counters["tets_under_guard"] = static_cast<double>(result.tets_under_guard);
}
BENCHMARK(BM_Fracture8)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();

std::vector<Eigen::Vector3d> stroke_through(const TetMesh& mesh, size_t points) {
    const auto box = bounding_box(mesh);
    std::vector<Eigen::Vector3d> stroke;
    for (size_t i = 0; i < points; ++i) {
        const double s = 0.25 + 0.5 * static_cast<double>(i) / static_cast<double>(points - 1);
        stroke.push_back(box[0] + s * (box[1] - box[0]));
    }
    return stroke;
}

// The kd-tree is built once per mesh state (after each cut), not per stroke.
void BM_PaintIndexBuild(benchmark::State& state) {
    const TetMesh& source = bench::spot_volume(kTets);
    for (auto _ : state) {
        const PaintIndex index(source);
        benchmark::DoNotOptimize(index.tet_count());
    }
}
BENCHMARK(BM_PaintIndexBuild)->Unit(benchmark::kMillisecond)->UseRealTime();

// Arg 0: sigma in thousandths of the bounding-box diagonal.
void BM_PaintStroke100(benchmark::State& state) {
    TetMesh mesh = bench::spot_volume(kTets);
    mesh.materials.assign(mesh.tet_count(), material_preset("marble"));
    const PaintIndex index(mesh);
    const std::vector<Eigen::Vector3d> stroke = stroke_through(mesh, 100);
    const auto box = bounding_box(mesh);
    PaintBrush brush;
    brush.material = material_preset("marble");
    brush.material.mua = {0.5, 0.01, 0.01};
    brush.sigma = static_cast<double>(state.range(0)) / 1000.0 * (box[1] - box[0]).norm();
    size_t changed = 0;
    for (auto _ : state) changed = paint_stroke(mesh, index, stroke, brush).changed_tets.size();
    state.counters["tets"] = static_cast<double>(mesh.tet_count());
    state.counters["changed"] = static_cast<double>(changed);
}
BENCHMARK(BM_PaintStroke100)->Arg(5)->Arg(10)->Arg(20)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace waxwork

WAXWORK_BENCHMARK_MAIN()
