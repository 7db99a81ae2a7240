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
#include "tetops/uniform_refinement.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <tuple>

namespace waxwork {
namespace {

// Student's t for a two-sided 95% interval, t_{0.975}(dof), dof = 1..30; the normal 1.96 beyond.
double student_t_975(size_t dof) {
    static constexpr double kTable[30] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                                          2.201,  2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
                                          2.080,  2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
    return dof >= 1 && dof <= 30 ? kTable[dof - 1] : 1.96;
}

std::string two_digits(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.2f", value);
    return text;
}

}  // namespace

TetMesh study_ball_mesh(int surface_level, size_t target_tets) {
    MeshingOptions meshing;
    meshing.sizing.target_tets = target_tets;
    return tetrahedralize(make_icosphere(surface_level, kStudyBallRadiusMm), meshing).mesh;
}

double mean_tet_size_mm(const TetMesh& mesh, double mm_per_unit) {
    return mm_per_unit * std::cbrt(total_volume(mesh) / static_cast<double>(mesh.tet_count()));
}

OrderFit ConvergenceSeries::fit_order() const {
    constexpr size_t kMinPoints = 4;
    constexpr double kMinSizeRange = 4, kMaxHalfWidth = 0.5, kMaxLocalSpread = 1.0;
    OrderFit fit;
    const size_t n = points.size();
    std::vector<std::string> reasons;
    if (n < kMinPoints) reasons.push_back("fewer than 4 points (" + std::to_string(n) + ")");
    if (n < 2) {
        fit.ci95_low = -std::numeric_limits<double>::infinity();
        fit.ci95_high = std::numeric_limits<double>::infinity();
        fit.why_unreliable = reasons.front();
        return fit;
    }
    std::vector<double> x(n), y(n);
    double min_size = points[0].tet_size_mm, max_size = points[0].tet_size_mm;
    for (size_t i = 0; i < n; ++i) {
        x[i] = std::log(points[i].tet_size_mm), y[i] = std::log(points[i].relative_error);
        min_size = std::min(min_size, points[i].tet_size_mm), max_size = std::max(max_size, points[i].tet_size_mm);
    }
    double mean_x = 0, mean_y = 0;
    for (size_t i = 0; i < n; ++i) mean_x += x[i] / static_cast<double>(n), mean_y += y[i] / static_cast<double>(n);
    double sxx = 0, sxy = 0;
    for (size_t i = 0; i < n; ++i) sxx += (x[i] - mean_x) * (x[i] - mean_x), sxy += (x[i] - mean_x) * (y[i] - mean_y);
    fit.order = sxy / sxx;
    fit.size_range = max_size / min_size;
    if (n > 2) {
        double residuals = 0;
        for (size_t i = 0; i < n; ++i) {
            const double r = y[i] - (mean_y + fit.order * (x[i] - mean_x));
            residuals += r * r;
        }
        const double standard_error = std::sqrt(residuals / static_cast<double>(n - 2) / sxx);
        const double half_width = student_t_975(n - 2) * standard_error;
        fit.ci95_low = fit.order - half_width, fit.ci95_high = fit.order + half_width;
    } else {
        fit.ci95_low = -std::numeric_limits<double>::infinity();
        fit.ci95_high = std::numeric_limits<double>::infinity();
    }
    for (size_t i = 0; i + 1 < n; ++i) fit.local_orders.push_back((y[i + 1] - y[i]) / (x[i + 1] - x[i]));

    if (fit.size_range < kMinSizeRange)
        reasons.push_back("tet sizes span a factor of " + two_digits(fit.size_range) + ", under 4");
    const double half_width = 0.5 * (fit.ci95_high - fit.ci95_low);
    if (!(half_width <= kMaxHalfWidth))
        reasons.push_back("95% interval half-width " + two_digits(half_width) + " above 0.5");
    const auto [low, high] = std::minmax_element(fit.local_orders.begin(), fit.local_orders.end());
    if (*high - *low > kMaxLocalSpread)
        reasons.push_back("local orders spread by " + two_digits(*high - *low) + " (" + two_digits(*low) + " to " +
                          two_digits(*high) + "), more than 1.0");
    fit.reliable = reasons.empty();
    for (const std::string& reason : reasons) fit.why_unreliable += (fit.why_unreliable.empty() ? "" : "; ") + reason;
    return fit;
}

double ConvergenceSeries::observed_order() const { return fit_order().order; }

nlohmann::ordered_json to_json(const std::vector<ConvergenceSeries>& series) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const ConvergenceSeries& s : series) {
        nlohmann::ordered_json points = nlohmann::ordered_json::array();
        for (const ConvergencePoint& p : s.points)
            points.push_back({{"tets", p.tets},
                              {"tet_size_mm", p.tet_size_mm},
                              {"relative_error", p.relative_error},
                              {"solve_ms", p.solve_ms}});
        const OrderFit fit = s.fit_order();
        out.push_back({{"name", s.name},
                       {"observed_order", fit.order},
                       {"order_ci95", {fit.ci95_low, fit.ci95_high}},
                       {"size_range", fit.size_range},
                       {"local_orders", fit.local_orders},
                       {"reliable", fit.reliable},
                       {"why_unreliable", fit.why_unreliable},
                       {"points", points}});
    }
    return out;
}

std::string order_table_markdown(const std::vector<ConvergenceSeries>& series) {
    std::string table = "| series | points | tets | size range | order | 95% interval | reliable? |\n"
                        "|---|---|---|---|---|---|---|\n";
    for (const ConvergenceSeries& s : series) {
        const OrderFit fit = s.fit_order();
        const std::string tets = s.points.empty() ? "-"
                                                  : std::to_string(s.points.front().tets) + " to " +
                                                        std::to_string(s.points.back().tets);
        const std::string interval = std::isfinite(fit.ci95_low) && std::isfinite(fit.ci95_high)
                                         ? two_digits(fit.ci95_low) + " to " + two_digits(fit.ci95_high)
                                         : "-";
        table += "| " + s.name + " | " + std::to_string(s.points.size()) + " | " + tets + " | " +
                 two_digits(fit.size_range) + " | " + two_digits(fit.order) + " | " + interval + " | " +
                 (fit.reliable ? std::string("yes") : "no: " + fit.why_unreliable) + " |\n";
    }
    return table;
}

namespace {

constexpr double kBallRadius = kStudyBallRadiusMm;
const TetMaterial& kBallMaterial = kStudyBallMaterial;
const std::pair<Discretization, const char*> kBallMethods[] = {{Discretization::TransCut, "transcut"},
                                                               {Discretization::Fem, "fem"}};
const std::pair<BallLight, const char*> kBallLights[] = {{BallLight::Uniform, "uniform"},
                                                         {BallLight::Directional, "directional"}};

// Four series named PREFIX METHOD LIGHT, in the order ball_points fills them.
std::vector<ConvergenceSeries> ball_series(const std::string& prefix) {
    std::vector<ConvergenceSeries> series;
    for (const auto& [method, method_name] : kBallMethods)
        for (const auto& [light, light_name] : kBallLights)
            series.push_back({prefix + " " + method_name + " " + light_name, {}});
    return series;
}

// One point per series: `mesh` of the ball solved by each method under each light, against the analytic solution.
void add_ball_points(const TetMesh& mesh, std::vector<ConvergenceSeries>& series) {
    const TetConnectivity connectivity = build_connectivity(mesh);
    size_t s = 0;
    for (const auto& [method, method_name] : kBallMethods)
        for (const auto& [light, light_name] : kBallLights) {
            DiffusionOptions options;
            options.discretization = method;
            options.relative_tolerance = 1e-8;
            const BallComparison comparison =
                compare_with_analytic_ball(mesh, connectivity, kBallMaterial, kBallRadius, light, options);
            series[s++].points.push_back({mesh.tet_count(), mean_tet_size_mm(mesh, 1.0), comparison.relative_error,
                                          comparison.solution.assembly_ms + comparison.solution.solve_ms});
        }
}

// The coarse mesh of the nested family. Every tet has one face on the sphere and the rest inside, which
// projection needs to keep the shapes over the levels (tetops/uniform_refinement.h). TetGen meshes the
// 320-triangle icosphere so (one tet per triangle around the centre); on the 80-triangle one it adds no
// interior vertex, leaving tets with two faces on the sphere, so the quick family joins those triangles
// to the centre itself.
TetMesh nested_ball_coarse_mesh(bool quick) {
    TetMesh mesh;
    if (quick) {
        const TriangleSurface surface = make_icosphere(1, kBallRadius);
        std::vector<Eigen::Vector3d> positions = surface.points;
        const auto centre = static_cast<int32_t>(positions.size());
        positions.push_back(Eigen::Vector3d::Zero());
        std::vector<Tet> tets;
        for (const auto& triangle : surface.triangles) tets.push_back({triangle[0], triangle[1], triangle[2], centre});
        mesh = make_tet_mesh(std::move(positions), std::move(tets));
    } else {
        MeshingOptions meshing;
        meshing.sizing.target_tets = 360;
        mesh = tetrahedralize(make_icosphere(2, kBallRadius), meshing).mesh;
    }
    const TetConnectivity connectivity = build_connectivity(mesh);
    std::vector<int> boundary_faces(mesh.tet_count(), 0);
    for (const BoundaryFace& face : connectivity.boundary_faces)
        if (++boundary_faces[face.tet] > 1)
            throw AlgorithmError("nested ball study: tet " + std::to_string(face.tet) +
                                 " of the coarse mesh has two faces on the sphere, whose refined children projection "
                                 "would flatten");
    return mesh;
}

}  // namespace

std::vector<ConvergenceSeries> study_ball_convergence(const StudySize& size) {
    struct Level {
        int surface_level;
        size_t tets;
    };
    const std::vector<Level> levels = size.quick ? std::vector<Level>{{2, 2000}, {3, 6000}, {3, 16000}}
                                                 : std::vector<Level>{{2, 2000}, {3, 6000}, {3, 16000}, {4, 48000}, {4, 128000}};
    std::vector<ConvergenceSeries> series = ball_series("ball");
    for (const Level& level : levels) {
        add_ball_points(study_ball_mesh(level.surface_level, level.tets), series);
    }
    return series;
}

std::vector<ConvergenceSeries> study_ball_nested_convergence(const StudySize& size, int refinements) {
    if (refinements < 0 || refinements > 4)
        throw InvalidArgumentError("nested ball study: refinements = " + std::to_string(refinements) +
                                   " must be in [0, 4] (each multiplies the tets by 8)");
    const auto onto_sphere = [](const Eigen::Vector3d& p) -> Eigen::Vector3d { return kBallRadius * p.normalized(); };
    std::vector<ConvergenceSeries> series = ball_series("ball nested");
    TetMesh mesh = nested_ball_coarse_mesh(size.quick);
    for (int level = 0; level <= refinements; ++level) {
        if (level > 0) mesh = refine_uniformly(mesh, onto_sphere);
        add_ball_points(mesh, series);
    }
    return series;
}

SurfaceSolve solve_at_input_vertices(const TriangleSurface& surface, const std::string& surface_name,
                                     const TetMaterial& material, double mm_per_unit, double size_factor,
                                     const AlternativeMethodSettings* alternative) {
    Lighting lighting;
    lighting.lights.push_back(default_key_light());
    MeshingOptions meshing;
    meshing.mesher = Mesher::TetGen;  // the comparison needs the input's vertices, which CGAL remeshes
    meshing.sizing = default_mesh_sizing(surface, material, mm_per_unit, {.size_factor = size_factor});
    const TetMesh mesh = tetrahedralize(surface, meshing).mesh;
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<TetMaterial> materials(mesh.tet_count(), material);
    DiffusionOptions diffusion;
    diffusion.mm_per_unit = mm_per_unit;
    diffusion.relative_tolerance = 1e-8;
    SolvedScene scene = solve_scene(mesh, connectivity, materials, lighting, diffusion, kDefaultCreaseAngleDegrees,
                                    alternative);
    // phi of the input surface's vertices, found by their exact coordinates (TetGen copies input points).
    using Key = std::tuple<double, double, double>;
    std::map<Key, size_t> index;
    for (size_t v = 0; v < mesh.vertex_count(); ++v)
        index.emplace(Key{mesh.positions[v].x(), mesh.positions[v].y(), mesh.positions[v].z()}, v);
    SurfaceSolve solve;
    solve.phi.reserve(surface.points.size());
    for (const Eigen::Vector3d& p : surface.points) {
        const auto it = index.find(Key{p.x(), p.y(), p.z()});
        if (it == index.end()) throw AlgorithmError(surface_name + ": the mesher moved an input vertex; cannot compare");
        solve.phi.push_back(scene.diffusion.phi[it->second]);
    }
    solve.tets = mesh.tet_count();
    solve.vertices = mesh.vertex_count();
    solve.tet_size_mm = mean_tet_size_mm(mesh, mm_per_unit);
    solve.setup_ms = scene.diffusion.assembly_ms;
    solve.solve_ms = scene.diffusion.solve_ms;
    solve.iterations = scene.diffusion.iterations[0];
    solve.alternative = std::move(scene.alternative);
    return solve;
}

double relative_l2_error(const std::vector<std::array<double, 3>>& phi, const std::vector<std::array<double, 3>>& reference) {
    double error = 0, norm = 0;
    for (size_t v = 0; v < phi.size(); ++v)
        for (int c = 0; c < 3; ++c) {
            error += (phi[v][c] - reference[v][c]) * (phi[v][c] - reference[v][c]);
            norm += reference[v][c] * reference[v][c];
        }
    return std::sqrt(error / norm);
}

ConvergenceSeries study_surface_convergence(const SurfaceConvergenceOptions& options) {
    const TetMaterial material = material_preset(options.material);
    const TriangleSurface surface = load_closed_surface(options.surface).surface;
    const std::string name = options.surface.string();
    const SurfaceSolve reference =
        solve_at_input_vertices(surface, name, material, options.mm_per_unit, options.reference_size_factor);
    ConvergenceSeries series;
    series.name = options.surface.stem().string() + " (" + options.material + ", " +
                  std::to_string(static_cast<int>(std::lround(options.mm_per_unit))) + " mm per unit)";
    for (double factor : options.size_factors) {
        const SurfaceSolve solve = solve_at_input_vertices(surface, name, material, options.mm_per_unit, factor);
        series.points.push_back({solve.tets, solve.tet_size_mm, relative_l2_error(solve.phi, reference.phi),
                                 solve.setup_ms + solve.solve_ms});
    }
    return series;
}

}  // namespace waxwork
