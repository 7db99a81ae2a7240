// Meshing spot (assets/meshes/spot.obj) to a tet count with TetGen and CGAL. Reports the tets produced
// and the wall time of one tetrahedralize() call (which includes the target_tets search passes).
// DefaultAgainstTetGenPq/<mesh>: the default meshing of every shared mesh against TetGen's own
// quality run on the same surface (docs/meshing_speed_table.sh turns it into docs/meshing.md's table).
#include "io/surface_reader.h"
#include "solver/material.h"
#include "solver/mesh_resolution.h"
#include "tetops/alpha_wrap.h"
#include "tetops/model_scale.h"
#include "tetops/tetgen_mesher.h"
#include "tetops/tetrahedralize.h"
#include "bench_main.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace {

waxwork::TriangleSurface read_spot() {
    return waxwork::read_surface_file(std::filesystem::path(WAXWORK_ASSET_DIR) / "meshes" / "spot.obj");
}

void mesh_spot(benchmark::State& state, waxwork::Mesher mesher) {
    static const waxwork::TriangleSurface spot = read_spot();
    waxwork::MeshingOptions options;
    options.mesher = mesher;
    options.sizing.target_tets = static_cast<size_t>(state.range(0));
    waxwork::MeshingResult result;
    for (auto _ : state) {
        result = waxwork::tetrahedralize(spot, options);
        benchmark::DoNotOptimize(result.mesh.tets.data());
    }
    state.counters["tets"] = double(result.mesh.tet_count());
    state.counters["ms"] = result.milliseconds;
    state.counters["min_dihedral"] = result.quality.min_dihedral_deg;
}

void BM_TetGenSpot(benchmark::State& state) { mesh_spot(state, waxwork::Mesher::TetGen); }
void BM_CgalSpot(benchmark::State& state) { mesh_spot(state, waxwork::Mesher::Cgal); }

BENCHMARK(BM_TetGenSpot)->Arg(50'000)->Arg(500'000)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_CgalSpot)->Arg(50'000)->Unit(benchmark::kMillisecond)->Iterations(1);

// A shared mesh as `waxwork mesh` takes it: checked (and safely repaired), or, when it is refused for
// its defects, wrapped as `--repair wrap` does.
struct SharedSurface {
    waxwork::TriangleSurface surface;
    bool wrapped = false;
};

SharedSurface load_shared_surface(const std::filesystem::path& path) {
    try {
        return {waxwork::load_closed_surface(path).surface, false};
    } catch (const waxwork::SurfaceRefusedError&) {
        return {waxwork::wrap_surface(waxwork::read_surface_file(path), {}).surface, true};
    }
}

// The timed loop is the default meshing (auto mesher, marble's graded size at the model's default
// scale, the wrap's remeshing rule for a wrapped surface). TetGen's plain quality run (`tetgen -pq`:
// radius-edge ratio 2, no dihedral bound, no size bound) of the same surface is timed once beside it.
void default_against_tetgen_pq(benchmark::State& state, const std::filesystem::path& path) {
    const SharedSurface shared = load_shared_surface(path);
    const waxwork::TriangleSurface& surface = shared.surface;
    const double mm_per_unit =
        waxwork::choose_model_scale(std::nullopt, std::nullopt, waxwork::bounding_extent(surface.points)).mm_per_unit;
    waxwork::MeshingOptions options;
    options.mesher = waxwork::Mesher::Auto;
    options.sizing = waxwork::default_mesh_sizing(surface, waxwork::material_preset("marble"), mm_per_unit);
    if (shared.wrapped) options.remesh_edge_ratio = waxwork::kWrapRemeshEdgeRatio;
    waxwork::MeshingResult result;
    for (auto _ : state) {
        result = waxwork::tetrahedralize(surface, options);
        benchmark::DoNotOptimize(result.mesh.tets.data());
    }
    waxwork::TetGenSettings plain;
    plain.max_radius_edge_ratio = 2.0;
    plain.min_dihedral_deg = 0;
    const auto start = std::chrono::steady_clock::now();
    const waxwork::TetMesh pq = waxwork::tetgen_tetrahedralize(surface, plain);
    const double pq_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const waxwork::QualityReport pq_quality = waxwork::measure_quality(pq);

    state.counters["triangles"] = double(surface.triangles.size());
    state.counters["wrapped"] = shared.wrapped;
    state.counters["remeshed"] = result.surface_remeshed.has_value();
    state.counters["tets"] = double(result.mesh.tet_count());
    state.counters["ms"] = result.milliseconds;
    state.counters["min_dihedral"] = result.quality.min_dihedral_deg;
    state.counters["under_5_deg"] = double(result.quality.tets_below_5_deg);
    state.counters["pq_tets"] = double(pq.tet_count());
    state.counters["pq_ms"] = pq_ms;
    state.counters["pq_min_dihedral"] = pq_quality.min_dihedral_deg;
    state.counters["pq_under_5_deg"] = double(pq_quality.tets_below_5_deg);
    state.counters["ratio"] = result.milliseconds / pq_ms;
    // The default asks for more tets than -pq makes where the surface is coarser than the light needs
    // (the cube: 48 triangles, 36 tets), so the time per tet is compared too.
    state.counters["ratio_per_tet"] = (result.milliseconds / double(result.mesh.tet_count())) / (pq_ms / double(pq.tet_count()));
}

// One benchmark per mesh file of the shared data, in name order; none when it is absent.
const bool registered_shared_meshes = [] {
    const std::filesystem::path folder = std::filesystem::path(WAXWORK_SHARED_DIR) / "data" / "meshes";
    std::error_code error;
    std::vector<std::filesystem::path> meshes;
    for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
        const std::string extension = entry.path().extension().string();
        if (extension == ".obj" || extension == ".off" || extension == ".ply" || extension == ".stl")
            meshes.push_back(entry.path());
    }
    std::sort(meshes.begin(), meshes.end());
    for (const auto& mesh : meshes) {
        benchmark::RegisterBenchmark(("DefaultAgainstTetGenPq/" + mesh.stem().string()).c_str(),
                                     default_against_tetgen_pq, mesh)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(1);
    }
    return true;
}();

}  // namespace

WAXWORK_BENCHMARK_MAIN()
