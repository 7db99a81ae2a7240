#include "bench/studies/method_study.h"

#include "base/error.h"
#include "base/timing.h"
#include "io/surface_reader.h"
#include "multires/hierarchy.h"
#include "multires/multigrid_cg.h"
#include "multires/multigrid_preconditioner.h"
#include "solver/diffusion_matrix.h"
#include "solver/diffusion_solve.h"
#include "solver/material.h"
#include "solver/reference/analytic_ball.h"
#include "tetops/connectivity.h"

#include <chrono>
#include <cmath>
#include <cstdio>

namespace waxwork {
namespace {

constexpr double kBallRadius = kStudyBallRadiusMm;
const TetMaterial& kBallMaterial = kStudyBallMaterial;
constexpr size_t kDipoleMaxTets = 120'000;

// The runs of one method on one mesh of the ball, or the reason it could not run.
struct BallProblem {
    const TetMesh& mesh;
    const TetConnectivity& connectivity;
    const std::vector<TetMaterial>& materials;
    std::vector<std::array<double, 3>> q;
    BallLight light;
};

MethodRun transcut_cg_run(const BallProblem& ball, double tolerance) {
    DiffusionOptions options;
    options.relative_tolerance = tolerance;
    const DiffusionSolution solution = solve_diffusion(ball.mesh, ball.connectivity, ball.materials, ball.q, options);
    MethodRun run;
    run.unknowns = ball.mesh.vertex_count();
    run.setup_ms = solution.assembly_ms;
    run.solve_ms = solution.solve_ms;
    run.iterations = solution.iterations[0];
    run.relative_error = ball_relative_error(ball.mesh, ball.connectivity, kBallMaterial, kBallRadius, ball.light, 1.0,
                                             solution.phi);
    return run;
}

// TransCut's matrix with the product's fastest CPU solver: CG preconditioned by the multigrid V-cycle
// on the independent-set hierarchy; its setup counts the assembly, the hierarchy and the V-cycle's.
MethodRun transcut_multigrid_run(const BallProblem& ball, double tolerance) {
    const auto start = std::chrono::steady_clock::now();
    const DiffusionMatrix matrix = assemble_diffusion_matrix(ball.mesh, ball.connectivity, ball.materials, {});
    const MultiresHierarchy hierarchy = build_multires_hierarchy(matrix, ball.mesh.positions);
    MultigridPreconditioner multigrid(hierarchy);
    MethodRun run;
    run.unknowns = ball.mesh.vertex_count();
    run.setup_ms = milliseconds_since(start);
    const auto solve_start = std::chrono::steady_clock::now();
    std::vector<std::array<double, 3>> phi(ball.mesh.vertex_count(), {0, 0, 0});
    std::vector<double> b(phi.size()), x(phi.size());
    ConjugateGradientOptions options;
    options.relative_tolerance = tolerance;
    for (int c = 0; c < 3; ++c) {
        diffusion_right_hand_side(matrix, ball.q, c, b);
        std::fill(x.begin(), x.end(), 0.0);
        const ConjugateGradientResult result = solve_multigrid_cg(multigrid, c, b, x, options);
        if (c == 0) run.iterations = result.iterations;
        for (size_t v = 0; v < x.size(); ++v) phi[v][static_cast<size_t>(c)] = x[v];
    }
    run.solve_ms = milliseconds_since(solve_start);
    run.relative_error =
        ball_relative_error(ball.mesh, ball.connectivity, kBallMaterial, kBallRadius, ball.light, 1.0, phi);
    return run;
}

MethodRun alternative_run(const BallProblem& ball, AlternativeMethod method, double tolerance) {
    const MethodProblem problem{ball.mesh, ball.connectivity, ball.materials, ball.q, 1.0};
    AlternativeMethodSettings settings;
    settings.method = method;
    settings.relative_tolerance = tolerance;
    const MethodSolution solution = solve_alternative(problem, settings);
    MethodRun run;
    run.unknowns = solution.unknowns;
    run.resolution_mm = uses_voxel_grid(method) ? default_cell_mm(problem) : 0.0;
    run.setup_ms = solution.setup_ms;
    run.solve_ms = solution.solve_ms;
    run.iterations = solution.iterations[0];
    run.warnings = solution.warnings;
    run.relative_error = ball_relative_error(ball.mesh, ball.connectivity, kBallMaterial, kBallRadius, ball.light, 1.0,
                                             solution.phi);
    return run;
}

// Series names: TransCut's two solvers, then the alternatives.
std::vector<std::string> method_names(const MethodStudyOptions& options) {
    std::vector<std::string> names = {"transcut_cg", "transcut_multigrid_cg"};
    for (AlternativeMethod method : options.methods) names.push_back(alternative_method_name(method));
    return names;
}

MethodSeries& series_of(std::vector<MethodSeries>& all, const std::string& scene, const std::string& method) {
    for (MethodSeries& s : all)
        if (s.scene == scene && s.method == method) return s;
    all.push_back({scene, method, {}});
    return all.back();
}

void report(const MethodStudyOptions& options, const std::string& line) {
    if (options.progress) options.progress(line);
}

void run_ball(const MethodStudyOptions& options, std::vector<MethodSeries>& all) {
    struct Level {
        int surface_level;
        size_t tets;
    };
    const std::vector<Level> levels = options.quick ? std::vector<Level>{{2, 2000}, {3, 6000}, {3, 16000}}
                                                    : std::vector<Level>{{2, 2000}, {3, 8000}, {4, 32000}, {4, 96000}, {5, 300000}};
    for (const Level& level : levels) {
        const TetMesh mesh = study_ball_mesh(level.surface_level, level.tets);
        const TetConnectivity connectivity = build_connectivity(mesh);
        const std::vector<TetMaterial> materials(mesh.tet_count(), kBallMaterial);
        for (BallLight light : {BallLight::Uniform, BallLight::Directional}) {
            const std::string scene = light == BallLight::Uniform ? "ball uniform" : "ball directional";
            const BallProblem ball{mesh, connectivity, materials, ball_light(mesh, connectivity, light, kBallMaterial.eta),
                                   light};
            for (const std::string& name : method_names(options)) {
                // The dipole sums over every pair of a boundary and any vertex: beyond this it takes
                // minutes, and its error is the model's plateau from the coarsest mesh on.
                if (name == "dipole" && mesh.tet_count() > kDipoleMaxTets) continue;
                report(options, scene + ", " + std::to_string(mesh.tet_count()) + " tets: " + name);
                MethodSeries& series = series_of(all, scene, name);
                MethodRun run;
                try {
                    if (name == "transcut_cg")
                        run = transcut_cg_run(ball, options.relative_tolerance);
                    else if (name == "transcut_multigrid_cg")
                        run = transcut_multigrid_run(ball, options.relative_tolerance);
                    else
                        run = alternative_run(ball, *parse_alternative_method(name), options.relative_tolerance);
                } catch (const InvalidArgumentError& e) {
                    run.warnings.push_back(std::string("did not run: ") + e.what());
                    run.relative_error = std::nan("");
                }
                run.tets = mesh.tet_count();
                if (run.resolution_mm == 0) run.resolution_mm = mean_tet_size_mm(mesh, 1.0);
                series.runs.push_back(std::move(run));
            }
        }
    }
}

// Spot in marble at 30 mm per unit, every method at the default mesh (the grid methods at as many
// voxels as it has vertices), against TransCut at half the default size.
void run_surface(const MethodStudyOptions& options, std::vector<MethodSeries>& all) {
    const TriangleSurface surface = load_closed_surface(options.surface).surface;
    const std::string name = options.surface.string();
    const TetMaterial material = material_preset("marble");
    const double mm_per_unit = options.quick ? 3.0 : 30.0;
    const double reference_factor = options.quick ? 0.7 : 0.5;
    const std::string scene = options.surface.stem().string();
    report(options, scene + ": the reference (TransCut at " + std::to_string(reference_factor) + " x the default size)");
    const SurfaceSolve reference = solve_at_input_vertices(surface, name, material, mm_per_unit, reference_factor);
    for (const std::string& method : method_names(options)) {
        if (method == "transcut_multigrid_cg") continue;  // the same phi as transcut_cg on one mesh
        report(options, scene + ": " + method);
        MethodSeries& series = series_of(all, scene, method);
        MethodRun run;
        try {
            std::optional<AlternativeMethodSettings> settings;
            if (method != "transcut_cg") {
                settings.emplace();
                settings->method = *parse_alternative_method(method);
                settings->relative_tolerance = options.relative_tolerance;
            }
            const SurfaceSolve solve =
                solve_at_input_vertices(surface, name, material, mm_per_unit, 1.0, settings ? &*settings : nullptr);
            run.tets = solve.tets;
            run.unknowns = solve.alternative ? solve.alternative->unknowns : solve.vertices;
            run.resolution_mm = solve.tet_size_mm;
            run.setup_ms = solve.setup_ms;
            run.solve_ms = solve.solve_ms;
            run.iterations = solve.iterations;
            if (solve.alternative) run.warnings = solve.alternative->warnings;
            run.relative_error = relative_l2_error(solve.phi, reference.phi);
        } catch (const InvalidArgumentError& e) {
            run.warnings.push_back(std::string("did not run: ") + e.what());
            run.relative_error = std::nan("");
        }
        series.runs.push_back(std::move(run));
    }
}

}  // namespace

OrderFit MethodSeries::fit_order() const {
    ConvergenceSeries convergence;
    convergence.name = scene + " " + method;
    for (const MethodRun& run : runs)
        if (std::isfinite(run.relative_error) && run.relative_error > 0)
            convergence.points.push_back({run.tets, run.resolution_mm, run.relative_error, run.setup_ms + run.solve_ms});
    return convergence.fit_order();
}

std::vector<MethodSeries> study_methods(const MethodStudyOptions& options) {
    std::vector<MethodSeries> all;
    run_ball(options, all);
    if (!options.surface.empty()) run_surface(options, all);
    return all;
}

nlohmann::ordered_json to_json(const std::vector<MethodSeries>& series) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const MethodSeries& s : series) {
        nlohmann::ordered_json runs = nlohmann::ordered_json::array();
        for (const MethodRun& r : s.runs)
            runs.push_back({{"tets", r.tets},
                            {"unknowns", r.unknowns},
                            {"resolution_mm", r.resolution_mm},
                            {"setup_ms", r.setup_ms},
                            {"solve_ms", r.solve_ms},
                            {"iterations", r.iterations},
                            {"relative_error", std::isfinite(r.relative_error) ? nlohmann::ordered_json(r.relative_error)
                                                                               : nlohmann::ordered_json()},
                            {"warnings", r.warnings}});
        nlohmann::ordered_json entry = {{"scene", s.scene}, {"method", s.method}, {"runs", runs}};
        if (s.runs.size() > 1) {
            const OrderFit fit = s.fit_order();
            entry["observed_order"] = fit.order;
            entry["order_ci95"] = {fit.ci95_low, fit.ci95_high};
            entry["reliable"] = fit.reliable;
            entry["why_unreliable"] = fit.why_unreliable;
        }
        out.push_back(entry);
    }
    return out;
}

std::string method_table_markdown(const std::vector<MethodSeries>& series) {
    std::string table = "| scene | method | unknowns (finest) | setup ms | solve ms | iterations | relative error | "
                        "observed order |\n| --- | --- | ---: | ---: | ---: | ---: | ---: | --- |\n";
    for (const MethodSeries& s : series) {
        if (s.runs.empty()) continue;
        const MethodRun& r = s.runs.back();
        char row[512];
        std::string order = "-";
        if (s.runs.size() > 1) {
            const OrderFit fit = s.fit_order();
            char text[96];
            std::snprintf(text, sizeof text, "%.2f%s", fit.order, fit.reliable ? "" : " (unreliable)");
            order = text;
        }
        char error[32] = "did not run";
        if (std::isfinite(r.relative_error)) std::snprintf(error, sizeof error, "%.3g", r.relative_error);
        std::snprintf(row, sizeof row, "| %s | %s | %zu | %.1f | %.1f | %d | %s | %s |\n", s.scene.c_str(),
                      s.method.c_str(), r.unknowns, r.setup_ms, r.solve_ms, r.iterations, error, order.c_str());
        table += row;
    }
    return table;
}

}  // namespace waxwork
