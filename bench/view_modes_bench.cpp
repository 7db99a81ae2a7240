// Building the geometry of each optional view (render/view_modes.h) for spot: what the editor's worker
// pays when the view or the geometry changes (the slice also when phi moves; the levels view includes
// assembling the matrix and building the hierarchy). Drawing is not timed here.
//
//   build-cc/bench/view_modes_bench --benchmark_filter=/500000
//
// The views' cost does not depend on the values of phi, so the scene's phi is a smooth stand-in
// (exp(-x) per channel) instead of a 500K-tet solve.
#include "render/view_modes.h"
#include "bench_main.h"
#include "bench_meshes.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>

namespace waxwork {
namespace {

struct ViewScene {
    const TetMesh& mesh;
    TetConnectivity connectivity;
    std::vector<TetMaterial> materials;
    SolvedScene scene;
};

const ViewScene& view_scene(size_t target_tets) {
    static std::map<size_t, std::unique_ptr<ViewScene>> cache;
    std::unique_ptr<ViewScene>& slot = cache[target_tets];
    if (slot) return *slot;
    const TetMesh& mesh = bench::spot_volume(target_tets);
    slot = std::make_unique<ViewScene>(ViewScene{mesh, build_connectivity(mesh), {}, {}});
    ViewScene& s = *slot;
    s.materials.assign(mesh.tet_count(), material_preset("marble"));
    s.scene.surface = extract_boundary_surface(mesh, s.connectivity, s.materials);
    s.scene.diffusion.phi.resize(mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        const double value = std::exp(-mesh.positions[v].x());
        s.scene.diffusion.phi[v] = {value, value, value};
    }
    return s;
}

void BM_ViewGeometry(benchmark::State& state, ViewMode mode) {
    const ViewScene& s = view_scene(static_cast<size_t>(state.range(0)));
    ViewOptions options;
    options.mode = mode;
    size_t overlay = 0, colours = 0;
    for (auto _ : state) {
        const ViewGeometry view = build_view_geometry(s.mesh, s.connectivity, s.materials, s.scene, options);
        overlay = view.overlay.line_vertices.size() + view.overlay.triangle_vertices.size() + view.overlay.points.size();
        colours = view.colours.size();
        benchmark::DoNotOptimize(view.colours.data());
    }
    state.counters["tets"] = static_cast<double>(s.mesh.tet_count());
    state.counters["overlay_vertices"] = static_cast<double>(overlay);
    state.counters["colours"] = static_cast<double>(colours);
}

BENCHMARK_CAPTURE(BM_ViewGeometry, materials, ViewMode::Materials)->Arg(50000)->Arg(500000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ViewGeometry, quality, ViewMode::Quality)->Arg(50000)->Arg(500000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ViewGeometry, wireframe, ViewMode::Wireframe)->Arg(50000)->Arg(500000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ViewGeometry, slice, ViewMode::Slice)->Arg(50000)->Arg(500000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ViewGeometry, levels, ViewMode::Levels)->Arg(50000)->Arg(500000)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace waxwork

WAXWORK_BENCHMARK_MAIN()
