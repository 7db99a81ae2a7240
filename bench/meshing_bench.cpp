// Meshing spot (assets/meshes/spot.obj) to a tet count with TetGen and CGAL. Reports the tets produced
// and the wall time of one tetrahedralize() call (which includes the target_tets search passes).
#include "io/surface_reader.h"
#include "tetops/tetrahedralize.h"
#include "bench_main.h"

#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

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

}  // namespace

WAXWORK_BENCHMARK_MAIN()
