// Rebuild time of all derived connectivity (edges, one-rings, boundary, components) for spot.
// Target: under 150 ms at 500K tets on this 2-core machine.
#include "tetops/connectivity.h"
#include "tetops/quality.h"
#include "bench_main.h"
#include "bench_meshes.h"

#include <benchmark/benchmark.h>

namespace waxwork {
namespace {

void BM_BuildConnectivity(benchmark::State& state) {
    const TetMesh& mesh = bench::spot_volume(static_cast<size_t>(state.range(0)));
    for (auto _ : state) {
        TetConnectivity c = build_connectivity(mesh);
        benchmark::DoNotOptimize(c.edges.data());
    }
    state.counters["tets"] = static_cast<double>(mesh.tet_count());
    state.counters["vertices"] = static_cast<double>(mesh.vertex_count());
}
BENCHMARK(BM_BuildConnectivity)->Arg(50'000)->Arg(500'000)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MeasureQuality(benchmark::State& state) {
    const TetMesh& mesh = bench::spot_volume(static_cast<size_t>(state.range(0)));
    for (auto _ : state) benchmark::DoNotOptimize(measure_quality(mesh));
    state.counters["tets"] = static_cast<double>(mesh.tet_count());
}
BENCHMARK(BM_MeasureQuality)->Arg(500'000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace waxwork

WAXWORK_BENCHMARK_MAIN()
