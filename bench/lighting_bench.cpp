// Incident light q with shadows on spot: the goal is <= 30 ms for a 500K-tet volume (30K-60K boundary
// vertices) on two cores. Also compares the hand-written BVH with CGAL's AABB_tree on the same shadow
// rays (the justification in solver/ray_caster.h).
//
//   build/bench/lighting_bench --benchmark_filter=Spot
//   build/bench/lighting_bench --benchmark_filter='SplitAtCreases|ShadingLight|SourceLight' 
#include "io/surface_reader.h"
#include "solver/lighting.h"
#include "solver/ray_caster.h"
#include "solver/shading_surface.h"
#include "tetops/connectivity.h"
#include "tetops/tetrahedralize.h"
#include "bench_main.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <random>

namespace waxwork {
namespace {

// spot.obj (2930 vertices) split 1:4 twice at edge midpoints: ~47K vertices and ~94K triangles, the
// boundary size of a 500K-tet spot volume, without waiting for the mesher.
BoundarySurface subdivided_spot() {
    TriangleSurface surface = read_surface_file(WAXWORK_ASSET_DIR "/meshes/spot.obj");
    for (int level = 0; level < 2; ++level) {
        std::map<std::pair<int32_t, int32_t>, int32_t> midpoints;
        auto midpoint = [&](int32_t a, int32_t b) {
            const auto key = std::minmax(a, b);
            auto [it, inserted] = midpoints.try_emplace({key.first, key.second}, static_cast<int32_t>(surface.points.size()));
            if (inserted) surface.points.push_back(0.5 * (surface.points[a] + surface.points[b]));
            return it->second;
        };
        std::vector<std::array<int32_t, 3>> finer;
        for (const auto& t : surface.triangles) {
            const int32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
            finer.push_back({t[0], ab, ca});
            finer.push_back({ab, t[1], bc});
            finer.push_back({ca, bc, t[2]});
            finer.push_back({ab, bc, ca});
        }
        surface.triangles = std::move(finer);
    }
    BoundarySurface result;
    result.positions = surface.points;
    result.triangles = surface.triangles;
    result.normals = area_weighted_normals(result.positions, result.triangles);
    result.eta.assign(result.positions.size(), 1.3);
    result.vertices.resize(result.positions.size());
    for (size_t i = 0; i < result.vertices.size(); ++i) result.vertices[i] = static_cast<int32_t>(i);
    return result;
}

const BoundarySurface& spot() {
    static const BoundarySurface surface = subdivided_spot();
    return surface;
}

Lighting key_light() {
    Lighting lighting;
    lighting.lights.push_back({LightType::Directional, Eigen::Vector3d(-0.4, -1.0, -0.6), {1, 1, 1}});
    lighting.ambient = {0.05, 0.05, 0.05};
    return lighting;
}

// The shadow rays incident_light casts for the key light: from the lit vertices towards the light.
struct Rays {
    std::vector<Eigen::Vector3f> origins;
    Eigen::Vector3f direction;
};
const Rays& spot_rays() {
    static const Rays rays = [] {
        Rays r;
        const Eigen::Vector3d to_light = -key_light().lights[0].vector.normalized();
        r.direction = to_light.cast<float>();
        for (size_t i = 0; i < spot().positions.size(); ++i) {
            if (spot().normals[i].dot(to_light) > 0) {
                r.origins.push_back((spot().positions[i] + 1e-4 * spot().normals[i]).cast<float>());
            }
        }
        return r;
    }();
    return rays;
}

void BM_IncidentLight_Spot_PrebuiltBvh(benchmark::State& state) {
    const TriangleBvh bvh = build_shadow_bvh(spot());
    const Lighting lighting = key_light();
    for (auto _ : state) benchmark::DoNotOptimize(incident_light(spot(), bvh, lighting));
    state.counters["vertices"] = static_cast<double>(spot().positions.size());
    state.counters["triangles"] = static_cast<double>(spot().triangles.size());
}
BENCHMARK(BM_IncidentLight_Spot_PrebuiltBvh)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_IncidentLight_Spot_IncludingBvhBuild(benchmark::State& state) {
    const Lighting lighting = key_light();
    for (auto _ : state) benchmark::DoNotOptimize(incident_light(spot(), lighting));
    state.counters["vertices"] = static_cast<double>(spot().positions.size());
}
BENCHMARK(BM_IncidentLight_Spot_IncludingBvhBuild)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BuildBvh_Spot(benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize(build_shadow_bvh(spot()));
}
BENCHMARK(BM_BuildBvh_Spot)->Unit(benchmark::kMillisecond)->UseRealTime();

// Single-threaded, same rays for both structures.
void BM_ShadowRays_HandBvh(benchmark::State& state) {
    const TriangleBvh bvh = build_shadow_bvh(spot());
    const Rays& rays = spot_rays();
    size_t blocked = 0;
    for (auto _ : state) {
        blocked = 0;
        for (const Eigen::Vector3f& o : rays.origins) {
            blocked += bvh.occluded(o, rays.direction, 0.0f, std::numeric_limits<float>::infinity());
        }
        benchmark::DoNotOptimize(blocked);
    }
    state.counters["rays"] = static_cast<double>(rays.origins.size());
    state.counters["blocked"] = static_cast<double>(blocked);
}
BENCHMARK(BM_ShadowRays_HandBvh)->Unit(benchmark::kMillisecond)->UseRealTime();

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalTriangles = std::vector<Kernel::Triangle_3>;
using CgalPrimitive = CGAL::AABB_triangle_primitive<Kernel, CgalTriangles::const_iterator>;
using CgalTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, CgalPrimitive>>;

CgalTriangles cgal_triangles() {
    CgalTriangles triangles;
    auto point = [](const Eigen::Vector3d& p) { return Kernel::Point_3(p.x(), p.y(), p.z()); };
    for (const auto& t : spot().triangles) {
        triangles.emplace_back(point(spot().positions[t[0]]), point(spot().positions[t[1]]), point(spot().positions[t[2]]));
    }
    return triangles;
}

void BM_BuildCgalAabbTree_Spot(benchmark::State& state) {
    const CgalTriangles triangles = cgal_triangles();
    for (auto _ : state) {
        CgalTree tree(triangles.begin(), triangles.end());
        tree.build();
        benchmark::DoNotOptimize(tree.size());
    }
}
BENCHMARK(BM_BuildCgalAabbTree_Spot)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ShadowRays_CgalAabbTree(benchmark::State& state) {
    const CgalTriangles triangles = cgal_triangles();
    CgalTree tree(triangles.begin(), triangles.end());
    tree.build();
    const Rays& rays = spot_rays();
    const Kernel::Vector_3 direction(rays.direction.x(), rays.direction.y(), rays.direction.z());
    size_t blocked = 0;
    for (auto _ : state) {
        blocked = 0;
        for (const Eigen::Vector3f& o : rays.origins) {
            blocked += tree.do_intersect(Kernel::Ray_3(Kernel::Point_3(o.x(), o.y(), o.z()), direction));
        }
        benchmark::DoNotOptimize(blocked);
    }
    state.counters["rays"] = static_cast<double>(rays.origins.size());
    state.counters["blocked"] = static_cast<double>(blocked);
}
BENCHMARK(BM_ShadowRays_CgalAabbTree)->Unit(benchmark::kMillisecond)->UseRealTime();

// The real thing: a 500K-tet volume of spot from the mesher (slow setup, once).
void BM_IncidentLight_SpotVolume500K(benchmark::State& state) {
    static const std::unique_ptr<std::pair<TetMesh, TetConnectivity>> volume = [] {
        MeshingOptions options;
        options.sizing.target_tets = 500000;
        TetMesh mesh = tetrahedralize(load_closed_surface(WAXWORK_ASSET_DIR "/meshes/spot.obj").surface, options).mesh;
        TetConnectivity connectivity = build_connectivity(mesh);
        return std::make_unique<std::pair<TetMesh, TetConnectivity>>(std::move(mesh), std::move(connectivity));
    }();
    const BoundarySurface surface = extract_boundary_surface(volume->first, volume->second, {});
    const TriangleBvh bvh = build_shadow_bvh(surface);
    const Lighting lighting = key_light();
    for (auto _ : state) benchmark::DoNotOptimize(incident_light(surface, bvh, lighting));
    state.counters["tets"] = static_cast<double>(volume->first.tet_count());
    state.counters["boundary_vertices"] = static_cast<double>(surface.positions.size());
}
BENCHMARK(BM_IncidentLight_SpotVolume500K)->Unit(benchmark::kMillisecond)->UseRealTime();

// The image's shading at creases (solver/shading_surface.h), on the subdivided spot (its own 77-degree
// folds at horn and ear tips survive subdivision): the split at the default angle and at 20 degrees
// (many more copies), then the copies' light (their own shadow rays) from the surface's q.
void BM_SplitAtCreases_Spot(benchmark::State& state) {
    const double angle = static_cast<double>(state.range(0));
    size_t copies = 0;
    for (auto _ : state) {
        const ShadingSurface shading = split_at_creases(spot(), angle);
        copies = shading.size() - spot().positions.size();
        benchmark::DoNotOptimize(shading.normals.data());
    }
    state.counters["copies"] = static_cast<double>(copies);
}
BENCHMARK(BM_SplitAtCreases_Spot)->Arg(40)->Arg(20)->Unit(benchmark::kMillisecond)->UseRealTime();

// The subdivided spot's light and its split at `angle`, as the renderer makes them.
struct SpotShading {
    TriangleBvh bvh = build_shadow_bvh(spot());
    Lighting lighting = key_light();
    std::vector<float> visibility;
    std::vector<Rgb> q = incident_light(spot(), bvh, lighting, &visibility);
    ShadingSurface shading;
    explicit SpotShading(double angle) : shading(split_at_creases(spot(), angle)) {}
};

void BM_ShadingLight_Spot(benchmark::State& state) {
    const SpotShading s(static_cast<double>(state.range(0)));
    for (auto _ : state)
        benchmark::DoNotOptimize(shading_light(spot(), s.shading, s.bvh, s.lighting, s.q, s.visibility).q.data());
    state.counters["split_copies"] = static_cast<double>(s.shading.split_copies.size());
}
BENCHMARK(BM_ShadingLight_Spot)->Arg(40)->Arg(20)->Unit(benchmark::kMillisecond)->UseRealTime();

// The solve's light from the copies' (source_light): one pass over the triangles at split vertices.
void BM_SourceLight_Spot(benchmark::State& state) {
    const SpotShading s(static_cast<double>(state.range(0)));
    const ShadingLight light = shading_light(spot(), s.shading, s.bvh, s.lighting, s.q, s.visibility);
    for (auto _ : state) benchmark::DoNotOptimize(source_light(spot(), s.shading, light.q).data());
    state.counters["split_copies"] = static_cast<double>(s.shading.split_copies.size());
}
BENCHMARK(BM_SourceLight_Spot)->Arg(40)->Arg(20)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace waxwork

WAXWORK_BENCHMARK_MAIN()
