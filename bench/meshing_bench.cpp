// Meshing spot (assets/meshes/spot.obj) to a tet count with TetGen and CGAL. Reports the tets produced
// and the wall time of one tetrahedralize() call (which includes the target_tets search passes).
#include "tetops/tetrahedralize.h"

#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

// Spot is a clean triangle OBJ (v and f records only matter); a local reader keeps the benchmark
// independent of the io/ readers' validation cost.
waxwork::TriangleSurface read_spot() {
    std::ifstream in(std::filesystem::path(WAXWORK_ASSET_DIR) / "meshes" / "spot.obj");
    waxwork::TriangleSurface surface;
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream words(line);
        std::string tag;
        words >> tag;
        if (tag == "v") {
            Eigen::Vector3d p;
            words >> p.x() >> p.y() >> p.z();
            surface.points.push_back(p);
        } else if (tag == "f") {
            std::array<int32_t, 3> t{};
            std::string word;
            for (auto& v : t) {
                words >> word;
                v = std::stoi(word.substr(0, word.find('/'))) - 1;
            }
            surface.triangles.push_back(t);
        }
    }
    return surface;
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

BENCHMARK_MAIN();
