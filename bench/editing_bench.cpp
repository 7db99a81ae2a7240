// Editing at the paper's scale (TransCut Sec. 5, Table 1: 500K-1M tets): a plane cut through spot with
// relaxation and the connectivity rebuild the solver needs afterwards, the exact cut (issue 6), fracture
// into 8 pieces, and a 100-point paint stroke.
// Goals: cut + connectivity + 10 relaxation sweeps <= 500 ms; fracture into 8 pieces <= 1 s; paint
// stroke <= 20 ms. BM_CrossSectionAccuracy charts how far the cross-section is from the plane and the
// worst dihedral angle for both cut modes (counters; --benchmark_format=json for the chart):
//   ./build/bench/editing_bench
//   ./build/bench/editing_bench --benchmark_filter=CrossSection --benchmark_format=json
#include "bench_meshes.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/exact_cut.h"
#include "tetops/fracture.h"
#include "tetops/paint.h"
#include "tetops/quality.h"
#include "tetops/relaxation.h"
#include "solver/material.h"

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
}
BENCHMARK(BM_ExactCutConnectivity)->Unit(benchmark::kMillisecond)->UseRealTime();

// Cross-section accuracy of both cut modes on spot. Cross-section vertices: boundary vertices after
// the cut that are not on the original boundary (an original vertex that was not a boundary vertex,
// or a vertex the exact cut created on an interior edge). Their distance to the plane (max and RMS,
// also relative to the mean edge length) and the worst dihedral angle of the whole mesh.
// Arg 0: 0 = remove + 10 relaxation sweeps with the 0.5 degree guard (TransCut Sec. 5), 1 = exact.
void BM_CrossSectionAccuracy(benchmark::State& state) {
    const TetMesh& source = bench::spot_volume(kTets);
    const PlaneCut plane = middle_plane(source);
    const TetConnectivity before = build_connectivity(source);
    std::set<std::pair<int32_t, int32_t>> boundary_edges;
    for (const BoundaryFace& f : before.boundary_faces)
        for (int k = 0; k < 3; ++k) {
            const int32_t a = f.vertices[k], b = f.vertices[(k + 1) % 3];
            boundary_edges.insert({std::min(a, b), std::max(a, b)});
        }
    const bool exact = state.range(0) == 1;
    TetMesh mesh;
    std::vector<uint8_t> on_original_boundary;
    for (auto _ : state) {
        mesh = source;
        if (exact) {
            const ExactCutResult r = cut_exact(mesh, plane);
            on_original_boundary.resize(mesh.vertex_count());
            for (size_t v = 0; v < mesh.vertex_count(); ++v) {
                const auto [a, b] = r.vertex_origins[v];
                on_original_boundary[v] = a == b ? before.is_boundary_vertex[a]
                                                 : boundary_edges.count({std::min(a, b), std::max(a, b)}) > 0;
            }
        } else {
            const CutResult r = remove_cut_away_tets(mesh, plane);
            relax_cut_vertices(mesh, build_connectivity(mesh), plane);
            on_original_boundary.resize(mesh.vertex_count());
            for (size_t v = 0; v < r.old_to_new_vertex.size(); ++v)
                if (r.old_to_new_vertex[v] >= 0) on_original_boundary[r.old_to_new_vertex[v]] = before.is_boundary_vertex[v];
        }
    }
    const TetConnectivity after = build_connectivity(mesh);
    double max_distance = 0, sum_squares = 0;
    size_t count = 0;
    for (int32_t v : after.boundary_vertices) {
        if (on_original_boundary[v]) continue;
        const double d = std::abs(plane.side(mesh.positions[v]));
        max_distance = std::max(max_distance, d);
        sum_squares += d * d;
        ++count;
    }
    const QualityReport quality = measure_quality(mesh);
    const double h = measure_quality(source).mean_edge_length;
    const double rms = count ? std::sqrt(sum_squares / static_cast<double>(count)) : 0.0;
    state.counters["cross_section_vertices"] = static_cast<double>(count);
    state.counters["max_distance"] = max_distance;
    state.counters["rms_distance"] = rms;
    state.counters["max_distance_per_edge"] = max_distance / h;
    state.counters["rms_distance_per_edge"] = rms / h;
    state.counters["min_dihedral_deg"] = quality.min_dihedral_deg;
    state.counters["tets_below_5_deg"] = static_cast<double>(quality.tets_below_5_deg);
    state.counters["tets_after"] = static_cast<double>(mesh.tet_count());
    state.SetLabel(exact ? "exact" : "remove+relax");
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

BENCHMARK_MAIN();
