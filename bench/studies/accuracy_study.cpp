#include "bench/studies/accuracy_study.h"

#include "base/error.h"
#include "io/surface_reader.h"
#include "solver/light_spec.h"
#include "solver/material.h"
#include "solver/mesh_resolution.h"
#include "solver/reference/analytic_ball.h"
#include "solver/solved_scene.h"
#include "tetops/connectivity.h"
#include "tetops/icosphere.h"
#include "tetops/tetrahedralize.h"

#include <cmath>
#include <map>
#include <tuple>

namespace waxwork {
namespace {

double tet_size_mm(const TetMesh& mesh, double mm_per_unit) {
    return mm_per_unit * std::cbrt(total_volume(mesh) / static_cast<double>(mesh.tet_count()));
}

}  // namespace

double ConvergenceSeries::observed_order() const {
    if (points.size() < 2) return 0;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const ConvergencePoint& p : points) {
        const double x = std::log(p.tet_size_mm), y = std::log(p.relative_error);
        sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    const double n = static_cast<double>(points.size());
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

nlohmann::ordered_json to_json(const std::vector<ConvergenceSeries>& series) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const ConvergenceSeries& s : series) {
        nlohmann::ordered_json points = nlohmann::ordered_json::array();
        for (const ConvergencePoint& p : s.points)
            points.push_back({{"tets", p.tets},
                              {"tet_size_mm", p.tet_size_mm},
                              {"relative_error", p.relative_error},
                              {"solve_ms", p.solve_ms}});
        out.push_back({{"name", s.name}, {"observed_order", s.observed_order()}, {"points", points}});
    }
    return out;
}

std::vector<ConvergenceSeries> study_ball_convergence(const StudySize& size) {
    constexpr double kRadius = 10.0;
    const TetMaterial material{{0.01, 0.01, 0.01}, {1.0, 1.0, 1.0}, 1.3};
    struct Level {
        int surface_level;
        size_t tets;
    };
    const std::vector<Level> levels = size.quick ? std::vector<Level>{{2, 2000}, {3, 6000}, {3, 16000}}
                                                 : std::vector<Level>{{2, 2000}, {3, 6000}, {3, 16000}, {4, 48000}, {4, 128000}};
    const std::pair<Discretization, const char*> methods[] = {{Discretization::TransCut, "transcut"},
                                                              {Discretization::Fem, "fem"}};
    const std::pair<BallLight, const char*> lights[] = {{BallLight::Uniform, "uniform"},
                                                        {BallLight::Directional, "directional"}};
    std::vector<ConvergenceSeries> series;
    for (const auto& [method, method_name] : methods)
        for (const auto& [light, light_name] : lights)
            series.push_back({std::string("ball ") + method_name + " " + light_name, {}});
    for (const Level& level : levels) {
        MeshingOptions meshing;
        meshing.sizing.target_tets = level.tets;
        const TetMesh mesh = tetrahedralize(make_icosphere(level.surface_level, kRadius), meshing).mesh;
        const TetConnectivity connectivity = build_connectivity(mesh);
        size_t s = 0;
        for (const auto& [method, method_name] : methods)
            for (const auto& [light, light_name] : lights) {
                DiffusionOptions options;
                options.discretization = method;
                options.relative_tolerance = 1e-8;
                const BallComparison comparison =
                    compare_with_analytic_ball(mesh, connectivity, material, kRadius, light, options);
                series[s++].points.push_back({mesh.tet_count(), tet_size_mm(mesh, 1.0), comparison.relative_error,
                                              comparison.solution.assembly_ms + comparison.solution.solve_ms});
            }
    }
    return series;
}

ConvergenceSeries study_surface_convergence(const SurfaceConvergenceOptions& options) {
    const TetMaterial material = material_preset(options.material);
    const TriangleSurface surface = load_closed_surface(options.surface).surface;
    Lighting lighting;
    lighting.lights.push_back(default_key_light());

    // phi of the input surface's vertices, found by their exact coordinates (TetGen copies input points).
    using Key = std::tuple<double, double, double>;
    auto solve_at_surface = [&](double factor, ConvergencePoint* point) {
        MeshingOptions meshing;
        meshing.mesher = Mesher::TetGen;  // the comparison needs the input's vertices, which CGAL remeshes
        meshing.sizing = default_mesh_sizing(surface, material, options.mm_per_unit, {.size_factor = factor});
        const TetMesh mesh = tetrahedralize(surface, meshing).mesh;
        const TetConnectivity connectivity = build_connectivity(mesh);
        const std::vector<TetMaterial> materials(mesh.tet_count(), material);
        DiffusionOptions diffusion;
        diffusion.mm_per_unit = options.mm_per_unit;
        diffusion.relative_tolerance = 1e-8;
        const SolvedScene scene = solve_scene(mesh, connectivity, materials, lighting, diffusion);
        std::map<Key, size_t> index;
        for (size_t v = 0; v < mesh.vertex_count(); ++v)
            index.emplace(Key{mesh.positions[v].x(), mesh.positions[v].y(), mesh.positions[v].z()}, v);
        std::vector<std::array<double, 3>> phi;
        phi.reserve(surface.points.size());
        for (const Eigen::Vector3d& p : surface.points) {
            const auto it = index.find(Key{p.x(), p.y(), p.z()});
            if (it == index.end())
                throw AlgorithmError(options.surface.string() + ": the mesher moved an input vertex; cannot compare");
            phi.push_back(scene.diffusion.phi[it->second]);
        }
        if (point) {
            point->tets = mesh.tet_count();
            point->tet_size_mm = tet_size_mm(mesh, options.mm_per_unit);
            point->solve_ms = scene.diffusion.assembly_ms + scene.diffusion.solve_ms;
        }
        return phi;
    };

    const auto reference = solve_at_surface(options.reference_size_factor, nullptr);
    ConvergenceSeries series;
    series.name = options.surface.stem().string() + " (" + options.material + ", " +
                  std::to_string(static_cast<int>(std::lround(options.mm_per_unit))) + " mm per unit)";
    for (double factor : options.size_factors) {
        ConvergencePoint point;
        const auto phi = solve_at_surface(factor, &point);
        double error = 0, norm = 0;
        for (size_t v = 0; v < phi.size(); ++v)
            for (int c = 0; c < 3; ++c) {
                error += (phi[v][c] - reference[v][c]) * (phi[v][c] - reference[v][c]);
                norm += reference[v][c] * reference[v][c];
            }
        point.relative_error = std::sqrt(error / norm);
        series.points.push_back(point);
    }
    return series;
}

}  // namespace waxwork
