#include "bench/studies/bench_suite.h"

#include "base/error.h"
#include "bench/studies/accuracy_study.h"
#include "bench/studies/coarse_start_bound.h"
#include "bench/studies/cut_study.h"
#include "bench/studies/environment_study.h"
#include "bench/studies/method_failures.h"
#include "bench/studies/method_study.h"
#include "bench/studies/transport_study.h"
#include "bench/studies/provenance.h"
#include "bench/studies/resolution_study.h"
#include "bench/studies/solver_comparison.h"
#include "bench/studies/stability_study.h"
#include "bench/studies/svg_chart.h"
#include "bench/studies/timing_table.h"
#include "io/atomic_file.h"
#include "io/file_contents.h"
#include "io/surface_reader.h"
#include "multires/multigrid_preconditioner.h"
#include "multires/multires_solver.h"
#include "scene/session.h"
#include "solver/light_spec.h"
#include "solver/material.h"
#include "solver/reference/reference_solvers.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/quality.h"
#include "tetops/tetrahedralize.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <exception>
#include <iostream>
#include <map>
#include <thread>

namespace waxwork {
namespace {

// The lighting of the surface part: the default key light, no ambient.
Lighting key_light_only() {
    Lighting lighting;
    lighting.lights = {default_key_light()};
    return lighting;
}

using Json = nlohmann::ordered_json;

void write_json(const std::filesystem::path& path, const Json& json) {
    write_file_atomically(path, [&](std::ostream& out) { out << json.dump(2) << "\n"; });
}

void write_text(const std::filesystem::path& path, const std::string& text) {
    write_file_atomically(path, [&](std::ostream& out) { out << text; });
}

// A part's JSON: its provenance block (bench/studies/provenance.h) first, then the part's own fields.
Json with_provenance(RunProvenance& provenance, const Json& inputs, const Json& definitions, const Json& body) {
    Json out = {{"provenance", provenance.to_json(inputs, definitions)}};
    for (const auto& [key, value] : body.items()) out[key] = value;
    return out;
}

// A chart or table title, marked when the run was --quick (smaller meshes, fewer samples).
std::string titled(const BenchSuiteOptions& o, const std::string& title) {
    return o.quick ? title + " (quick run)" : title;
}

// The shipped spot meshed by TetGen to about target_tets.
TetMesh spot_volume(const BenchSuiteOptions& o, size_t target_tets) {
    MeshingOptions meshing;
    meshing.sizing.target_tets = target_tets;
    return tetrahedralize(load_closed_surface(o.asset_dir / "meshes/spot.obj").surface, meshing).mesh;
}

// The solver parts' scene: spot in marble, 30 mm per unit, under the key light.
constexpr double solver_scene_mm_per_unit = 30;

struct SolverScene {
    size_t target_tets = 0;
    TetMesh mesh;
    TetConnectivity connectivity;
    std::vector<TetMaterial> materials;
    Lighting lighting;
};

// The inputs block of a part measured on `scene` (provenance.h).
Json scene_inputs(const BenchSuiteOptions& o, const SolverScene& scene, double mm_per_unit) {
    Json inputs = mesh_inputs(o.asset_dir / "meshes/spot.obj", scene.mesh, mm_per_unit);
    inputs["meshing"] = {{"mesher", "tetgen"}, {"target_tets", scene.target_tets}};
    inputs["material"] = "marble";
    inputs["lighting"] = lighting_to_json(scene.lighting);
    return inputs;
}

SolverScene solver_scene(const BenchSuiteOptions& o, size_t target_tets) {
    SolverScene scene;
    scene.target_tets = target_tets;
    scene.mesh = spot_volume(o, target_tets);
    scene.connectivity = build_connectivity(scene.mesh);
    scene.materials.assign(scene.mesh.tet_count(), material_preset("marble"));
    scene.lighting.lights.push_back(default_key_light());
    return scene;
}

void run_solver_part(const BenchSuiteOptions& o, size_t target_tets, Json& index, RunProvenance& provenance) {
    const SolverScene scene = solver_scene(o, target_tets);
    provenance.warn_if_under_resolved(scene.mesh, scene.materials, solver_scene_mm_per_unit);
    SolverComparisonOptions options;
    options.mm_per_unit = solver_scene_mm_per_unit;
    options.max_seconds = o.quick ? 8.0 : 60.0;
    options.repeats = o.repeats;
    // Every path, the GPU one included (llvmpipe here: a CPU, so its times are not GPU times).
    const std::unique_ptr<HeadlessGlContext> context = open_gpu_for_comparison(options);
    const SolverComparison comparison = compare_solvers(scene.mesh, scene.connectivity, scene.materials, scene.lighting, options);
    if (!comparison.gpu_fallback_reason.empty())
        std::cerr << "warning: no GPU curves: " << comparison.gpu_fallback_reason << "\n";
    const std::string stem = "solvers_spot_" + std::to_string((target_tets + 500) / 1000) + "k";
    SolverChartOptions chart;
    chart.quick = o.quick;
    if (context) provenance.set_gl_renderer(context->renderer());
    if (const std::string busy = busy_machine_warning(comparison); !busy.empty()) provenance.warn(busy);
    if (const std::string peers = missing_peers_warning(comparison); !peers.empty()) provenance.warn(peers);
    const Json block = provenance.to_json(scene_inputs(o, scene, solver_scene_mm_per_unit),
                                          solver_comparison_definitions(options));
    write_solver_comparison(o.output_dir, stem, {"assets/meshes/spot.obj", "marble", solver_scene_mm_per_unit},
                            comparison, block, chart);
    Json& listed = index["solvers"];
    if (!listed.is_array()) listed = Json::array();
    if (std::find(listed.begin(), listed.end(), Json(stem + ".json")) == listed.end()) listed.push_back(stem + ".json");
}

// One row of the coarse_start part: on one lit system, for each choice of Eq. 16's weights
// (hierarchy.h InterpolationWeights), the best start level 1 can give the paper's scheme
// (bench/studies/coarse_start_bound.h), the start its own coarse pass gives, and the V-cycle-preconditioned
// CG's iterations on the same hierarchy.
Json coarse_start_row(const SolverScene& scene, const std::vector<TetMaterial>& materials, double mm_per_unit) {
    constexpr double target_error = 1e-2;  // "to 1%", as in the solver comparison
    AssemblyOptions assembly;
    assembly.mm_per_unit = mm_per_unit;
    const DiffusionMatrix matrix = assemble_diffusion_matrix(scene.mesh, scene.connectivity, materials, assembly);
    const std::vector<Rgb> q = incident_light(scene.mesh, scene.connectivity, materials, scene.lighting);
    ChannelVectors b, reference;
    for (int c = 0; c < 3; ++c) {
        const auto sc = static_cast<size_t>(c);
        b[sc].resize(matrix.size());
        diffusion_right_hand_side(matrix, q, c, b[sc]);
        const Eigen::VectorXd x = refined_direct_solution(
            to_eigen_sparse(matrix, c), Eigen::Map<const Eigen::VectorXd>(b[sc].data(), static_cast<Eigen::Index>(b[sc].size())));
        reference[sc].assign(x.data(), x.data() + x.size());
    }
    Json row = {{"tets", scene.mesh.tet_count()}, {"vertices", matrix.size()}, {"mm_per_unit", mm_per_unit}};
    for (const auto& [key, weights] : {std::pair{"paper_weights", InterpolationWeights::InverseEdgeLength},
                                       std::pair{"linear_exact_weights", InterpolationWeights::LinearExact}}) {
        HierarchyOptions hierarchy_options;
        hierarchy_options.weights = weights;
        // The scheme's own start: its coarse-to-fine pass as MultiresSolver runs it, no level-0 iteration.
        MultiresSolver scheme(matrix, scene.mesh.positions, hierarchy_options);
        ChannelVectors scheme_start;
        MultiresSolveOptions coarse_pass_only;
        coarse_pass_only.max_iterations = 0;
        for (int c = 0; c < 3; ++c) {
            scheme_start[static_cast<size_t>(c)].resize(matrix.size());
            scheme.solve(b[static_cast<size_t>(c)], c, scheme_start[static_cast<size_t>(c)], coarse_pass_only);
        }
        const MultiresHierarchy& hierarchy = scheme.hierarchy();
        const CoarseStartBound bound = measure_coarse_start_bound(hierarchy, b, reference, target_error);
        const int from_scheme = jacobi_cg_iterations_to(hierarchy, b, scheme_start, reference, target_error, 10000);
        MultigridPreconditioner multigrid(hierarchy);
        const auto ratio = [&](int iterations) {
            return bound.iterations_from_zero > 0 && iterations >= 0
                       ? Json(static_cast<double>(iterations) / bound.iterations_from_zero)
                       : Json(nullptr);
        };
        const InterpolationOperator& p = hierarchy.levels[0].interpolation;
        row[key] = {{"level1_vertices", bound.coarse_vertices},
                    {"linear_exact_rows", p.linear_exact_rows},
                    {"paper_weight_rows", p.paper_weight_rows},
                    {"interpolation_error", bound.interpolation_error},
                    {"eq17_start_error", bound.eq17_start_error},
                    {"galerkin_start_error", bound.galerkin_start_error},
                    {"scheme_start_error", combined_relative_error(scheme_start, reference)},
                    {"iterations_to_1pct", {{"zero_start", bound.iterations_from_zero},
                                            {"scheme_coarse_pass", from_scheme},
                                            {"eq17_exact_level1", bound.iterations_from_eq17},
                                            {"galerkin_exact_level1", bound.iterations_from_galerkin}}},
                    {"iteration_ratio_eq17", ratio(bound.iterations_from_eq17)},
                    {"iteration_ratio_galerkin", ratio(bound.iterations_from_galerkin)},
                    {"multigrid_cg_iterations", {{"to_1pct", multigrid_cg_iterations_to(multigrid, b, reference, 1e-2, 1000)},
                                                 {"to_1e-6", multigrid_cg_iterations_to(multigrid, b, reference, 1e-6, 1000)}}}};
    }
    return row;
}

// The best start the paper's coarse level can give the level-0 CG, on the solver parts' systems and, at
// 50K tets, across the measured materials and scales (the diffusion length against the mesh size), with
// the paper's weights and linear-exact ones: why its coarse-to-fine scheme saves so few iterations.
void run_coarse_start_part(const BenchSuiteOptions& o, Json& index, RunProvenance& provenance) {
    Json sizes = Json::array();
    const std::vector<size_t> targets = o.quick ? std::vector<size_t>{50'000} : std::vector<size_t>{50'000, 500'000};
    for (const size_t target : targets) {
        const SolverScene scene = solver_scene(o, target);
        sizes.push_back(coarse_start_row(scene, scene.materials, solver_scene_mm_per_unit));
    }
    // The sweep: every preset at the solver scene's scale, and marble from 3 mm to 300 mm per unit.
    const SolverScene scene = solver_scene(o, 50'000);
    std::vector<std::pair<std::string, double>> cases;
    if (o.quick) {
        cases = {{"marble", 3}, {"marble", 300}, {"spectralon", solver_scene_mm_per_unit}};
    } else {
        for (const std::string& name : material_preset_names()) cases.emplace_back(name, solver_scene_mm_per_unit);
        for (const double scale : {3.0, 10.0, 100.0, 300.0}) cases.emplace_back("marble", scale);
    }
    const double mean_edge = measure_quality(scene.mesh).mean_edge_length;  // model units
    Json sweep = Json::array();
    for (const auto& [name, scale] : cases) {
        const TetMaterial material = material_preset(name);
        Json row = coarse_start_row(scene, std::vector<TetMaterial>(scene.mesh.tet_count(), material), scale);
        Json lengths = Json::array();
        for (int c = 0; c < 3; ++c) lengths.push_back(diffusion_length(material.mua[static_cast<size_t>(c)], material.musp[static_cast<size_t>(c)]));
        row["material"] = name;
        row["diffusion_length_mm"] = lengths;  // null (infinite) where mu_a = 0
        row["mean_edge_mm"] = mean_edge * scale;
        sweep.push_back(std::move(row));
    }
    const Json definitions = {
        {"error", "relative L2 error of phi over every vertex and the three channels against the direct solution "
                  "(plus one refinement step)"},
        {"iterations_to_1pct", "level-0 Jacobi CG iterations until the true error is at most 1%"},
        {"multigrid_cg_iterations", "V-cycle-preconditioned CG iterations until the true error reaches the target"},
        {"iteration_ratio", "iterations from the coarse start over iterations from zero"},
        {"lengths", "mm"}};
    write_json(o.output_dir / "coarse_start.json",
               with_provenance(provenance, scene_inputs(o, scene, solver_scene_mm_per_unit), definitions,
                               {{"mesh", "assets/meshes/spot.obj"},
                                {"material", "marble"},
                                {"mm_per_unit", solver_scene_mm_per_unit},
                                {"sizes", sizes},
                                {"materials", sweep}}));
    index["coarse_start"] = "coarse_start.json";
}

// Cross-section distance and dihedral distributions of both cut modes.
void run_cut_modes_part(const BenchSuiteOptions& o, Json& index, RunProvenance& provenance) {
    const TetMesh mesh = spot_volume(o, o.quick ? 50'000 : 500'000);
    const auto box = bounding_box(mesh);
    const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 0.3, 0.2).normalized();
    const std::vector<CutModeResult> results =
        compare_cut_modes(mesh, PlaneCut(normal, normal.dot(0.5 * (box[0] + box[1]))));
    const Json definitions = {
        {"distance", "each cross-section vertex's distance to the cutting plane, over the mesh's mean edge length"},
        {"dihedral", "each tet's smallest dihedral angle after the cut, in degrees"},
        {"times", "milliseconds of wall clock, one run"}};
    write_json(o.output_dir / "cut_modes.json",
               with_provenance(provenance, mesh_inputs(o.asset_dir / "meshes/spot.obj", mesh, 1.0), definitions,
                               {{"tets_before", mesh.tet_count()}, {"modes", to_json(results)}}));

    // At most ~200 points per line: every k-th sample of a sorted distribution, the last one always.
    auto thin = [](size_t n, auto&& point) {
        std::vector<std::pair<double, double>> points;
        const size_t step = std::max<size_t>(1, n / 200);
        for (size_t i = 0; i < n; i += step) points.push_back(point(i));
        if (n > 0 && (n - 1) % step != 0) points.push_back(point(n - 1));
        return points;
    };
    std::vector<ChartSeries> distance_lines, quality_lines;
    for (const CutModeResult& r : results) {
        const size_t n = r.distances_per_edge.size();
        // Exact cuts put vertices on the plane to rounding (often exactly 0): drawn at 1e-17.
        distance_lines.push_back({r.mode, thin(n, [&](size_t i) {
                                      return std::pair{static_cast<double>(i + 1) / static_cast<double>(n),
                                                       std::max(r.distances_per_edge[i], 1e-17)};
                                  }), false});
        const size_t below_10 = r.tets_below(10.0);
        char name[96];
        std::snprintf(name, sizeof name, "%s (worst %.2f deg)", r.mode.c_str(), r.worst_dihedral_deg());
        quality_lines.push_back({name, thin(below_10, [&](size_t i) {
                                     return std::pair{r.min_dihedral_deg[i], static_cast<double>(i + 1)};
                                 }), false});
    }
    ChartOptions distance_chart;
    distance_chart.title = titled(o, "Cross-section vertices' distance to the cutting plane (spot, " +
                                         std::to_string(mesh.tet_count()) + " tets)");
    distance_chart.caption = provenance.caption();
    distance_chart.x = {"fraction of cross-section vertices (sorted)", AxisScale::Linear, 0, 1};
    distance_chart.y = {"distance / mean edge length", AxisScale::Log};
    write_svg_chart(o.output_dir / "cut_modes.svg", distance_lines, distance_chart);
    ChartOptions quality_chart;
    quality_chart.title = titled(o, "Tets under a minimum dihedral angle after the cut");
    quality_chart.caption = provenance.caption();
    quality_chart.x = {"minimum dihedral angle (degrees)", AxisScale::Log, 0.1, 10};
    quality_chart.y = {"tets below", AxisScale::Log};
    write_svg_chart(o.output_dir / "cut_quality.svg", quality_lines, quality_chart);
    index["cut_modes"] = "cut_modes.json";
}

void run_accuracy_part(const BenchSuiteOptions& o, Json& index, RunProvenance& provenance) {
    const StudySize size{.quick = o.quick};
    const std::vector<ConvergenceSeries> ball = study_ball_convergence(size);
    const std::vector<ConvergenceSeries> ball_nested = study_ball_nested_convergence(size);
    SurfaceConvergenceOptions spot_options;
    spot_options.surface = o.asset_dir / "meshes/spot.obj";
    if (o.quick) {
        spot_options.mm_per_unit = 3;  // the coarse (D/25) default mesh: seconds, not minutes
        spot_options.size_factors = {2.0, 1.5, 1.0};
        spot_options.reference_size_factor = 0.6;
    }
    const ConvergenceSeries spot = study_surface_convergence(spot_options);
    const Json inputs = {
        {"ball", "icosphere of radius 10 mm meshed by TetGen; mu_a 0.01, mu_s' 1 per mm, eta 1.3"},
        {"ball_nested", "a coarse TetGen ball refined 1:8 per level (tetops/uniform_refinement.h), new boundary "
                        "vertices projected onto the sphere: size ratio 2 per level"},
        {"surface", {{"mesh_file", spot_options.surface.string()},
                     {"mesh_sha256", file_sha256(spot_options.surface)},
                     {"material", spot_options.material},
                     {"mm_per_unit", spot_options.mm_per_unit},
                     {"size_factors", spot_options.size_factors},
                     {"reference_size_factor", spot_options.reference_size_factor},
                     {"lighting", lighting_to_json(key_light_only())}}}};
    const Json definitions = {
        {"ball_error", "relative L2 error of phi (channel 0, weighted by lumped vertex volume) against the analytic "
                       "series (60 Legendre terms for the directional light); solves to relative tolerance 1e-8"},
        {"surface_error", "relative L2 error of phi at the input surface's vertices, three channels, against the "
                          "mesh of reference_size_factor x the default size; solves to 1e-8"},
        {"tet_size_mm", "(volume / tets)^(1/3)"},
        {"observed_order", "least-squares slope of log(error) against log(tet_size_mm), with its 95% confidence "
                           "interval (Student t, n - 2 degrees of freedom); flagged unreliable below 4 points, over "
                           "a size range under 4x, with an interval wider than +-0.5 or local orders spread by "
                           "more than 1"},
        {"solve_ms", "assembly + solve, milliseconds of wall clock, one run"}};
    write_json(o.output_dir / "accuracy.json",
               with_provenance(provenance, inputs, definitions,
                               {{"ball", to_json(ball)}, {"ball_nested", to_json(ball_nested)}, {"surface", to_json({spot})}}));
    std::vector<ConvergenceSeries> all = ball;
    all.insert(all.end(), ball_nested.begin(), ball_nested.end());
    all.push_back(spot);
    write_text(o.output_dir / "accuracy.md", "### " + titled(o, "Observed orders of convergence") +
                                                 "\n\nLeast-squares slope of log(relative L2 error of phi) on log(mean "
                                                 "tet size), with its 95% interval (Student's t at n - 2 degrees of "
                                                 "freedom); reliable with at least 4 points over a size range of at least "
                                                 "4, a half-width of at most 0.5 and local orders within 1.0 of each "
                                                 "other.\n\n" +
                                                 order_table_markdown(all));

    auto chart = [&](const std::vector<ConvergenceSeries>& series, const std::string& title,
                     const std::filesystem::path& path) {
        std::vector<ChartSeries> lines;
        for (const ConvergenceSeries& s : series) {
            ChartSeries line;
            char name[224];
            // The fitted order with its 95% interval, flagged where the fit is not to be trusted.
            const OrderFit fit = s.fit_order();
            if (std::isfinite(fit.ci95_low) && std::isfinite(fit.ci95_high))
                std::snprintf(name, sizeof name, "%s (order %.2f, 95%% CI %.2f to %.2f%s)", s.name.c_str(), fit.order,
                              fit.ci95_low, fit.ci95_high, fit.reliable ? "" : "; unreliable");
            else
                std::snprintf(name, sizeof name, "%s (order %.2f; unreliable)", s.name.c_str(), fit.order);
            line.name = name;
            for (const ConvergencePoint& p : s.points) line.points.emplace_back(p.tet_size_mm, p.relative_error);
            lines.push_back(std::move(line));
        }
        ChartOptions options;
        options.title = titled(o, title);
        options.x = {"mean tet size (mm)", AxisScale::Log};
        options.y = {"relative L2 error of phi", AxisScale::Log};
        options.slope_orders = {1, 2};
        options.caption = provenance.caption();
        write_svg_chart(path, lines, options);
    };
    chart(ball, "Ball (R = 10 mm) against the analytic solution", o.output_dir / "accuracy_ball.svg");
    chart(ball_nested, "Ball (R = 10 mm), nested 1:8 refinement, against the analytic solution",
          o.output_dir / "accuracy_ball_nested.svg");
    chart({spot}, "Spot against a mesh of half the default size", o.output_dir / "accuracy_spot.svg");
    index["accuracy"] = "accuracy.json";
}

// The environment transfer against the sampled reference, per order, under the sky dome and a studio.
void run_environment_part(const BenchSuiteOptions& o, Json& index, RunProvenance& provenance) {
    const TetMesh mesh = spot_volume(o, o.quick ? 50'000 : 100'000);
    const std::vector<TetMaterial> materials(mesh.tet_count(), material_preset("marble"));
    const BoundarySurface surface = extract_boundary_surface(mesh, build_connectivity(mesh), materials);
    const TriangleBvh bvh = build_shadow_bvh(surface);
    const std::vector<int> orders = o.quick ? std::vector<int>{1, 2, 4, 6, 8} : std::vector<int>{1, 2, 3, 4, 6, 8, 10, 12};
    const int reference_samples = o.quick ? 2048 : 8192;
    std::vector<TransferAccuracy> studies;
    studies.push_back(study_transfer_accuracy(surface, bvh, sky_environment_light(SkySettings{35, 60, 3}),
                                              "sky dome (sun elevation 35, azimuth 60)", orders, reference_samples));
    studies.push_back(study_transfer_accuracy(surface, bvh, studio_environment(kDefaultTransferOrder),
                                              "studio (one 40 x 25 degree softbox)", orders, reference_samples));
    Json results = Json::array();
    for (const TransferAccuracy& study : studies) results.push_back(to_json(study));
    const Json definitions = {
        {"relative_l2", "L2 norm over surface vertices and channels of q_env(transfer) - q_env(reference), over the "
                        "reference's norm"},
        {"median_relative", "median over vertices lit above 1% of the brightest of |q_t - q_r| / q_r, green channel"},
        {"reference", "multiple importance sampling of the cosine and the environment's luminance, shadows on"},
        {"transfer_ms", "sampling every surface vertex's transfer (256 cosine-distributed rays each)"},
        {"relight_ms", "rotating the environment's coefficients and one dot product per vertex"}};
    write_json(o.output_dir / "environment.json",
               with_provenance(provenance, mesh_inputs(o.asset_dir / "meshes/spot.obj", mesh, 1.0), definitions,
                               {{"surface_vertices", surface.positions.size()}, {"studies", results}}));
    std::vector<ChartSeries> by_order, by_time;
    for (const TransferAccuracy& study : studies) {
        ChartSeries order_line{study.environment, {}}, time_line{study.environment, {}};
        for (const TransferAccuracyRow& r : study.rows) {
            order_line.points.emplace_back(r.order, r.relative_l2);
            time_line.points.emplace_back(r.transfer_ms, r.relative_l2);
        }
        by_order.push_back(order_line);
        by_time.push_back(time_line);
    }
    ChartOptions order_chart;
    order_chart.title = titled(o, "Environment transfer against the sampled integral (spot, " +
                                      std::to_string(surface.positions.size()) + " surface vertices)");
    order_chart.caption = provenance.caption();
    order_chart.x = {"spherical harmonics order", AxisScale::Linear};
    order_chart.y = {"relative L2 error of q_env", AxisScale::Log};
    order_chart.target_line = 1e-2;
    order_chart.target_label = "1%";
    write_svg_chart(o.output_dir / "environment_order.svg", by_order, order_chart);
    ChartOptions time_chart = order_chart;
    time_chart.title = titled(o, "Environment transfer: error against the time to sample it");
    time_chart.x = {"sampling every vertex's transfer (ms)", AxisScale::Log};
    write_svg_chart(o.output_dir / "environment_time.svg", by_time, time_chart);
    index["environment"] = "environment.json";
}

// TransCut's live image against the Monte Carlo image: where the diffusion approximation can be trusted.
void run_transport_part(const BenchSuiteOptions& o, Json& index, RunProvenance& provenance) {
    TransportStudyOptions study;
    if (o.quick) {
        study.plate_thicknesses = {1, 4, 16};
        study.mc_seconds = 1;
    }
    if (o.progress) study.progress = [&](const std::string& line) { o.progress("  " + line); };
    const std::vector<TransportCase> cases = run_transport_study(study);
    Json rows = Json::array();
    for (const TransportCase& c : cases) rows.push_back(to_json(c));
    const Json inputs = {{"materials", study.materials},
                         {"cube_scales_mm_per_unit", study.cube_scales},
                         {"plate_thicknesses_mfp", study.plate_thicknesses},
                         {"cut_scale_mm_per_unit", study.cut_scale},
                         {"image", {study.width, study.height}},
                         {"cube_cells", study.cube_cells},
                         {"mc_seconds_per_case", study.mc_seconds},
                         {"seed", study.seed},
                         {"light", "directional 1,-1,-1, white, no ambient"}};
    const Json definitions = {
        {"relative_l2", "sqrt(sum |live - MC|^2 / sum |MC|^2) over the pixels both cover, linear radiance, all channels"},
        {"scaled_relative_l2", "relative_l2 after scaling the live image by the least-squares factor mc_over_live"},
        {"psnr_db", "PSNR of the two images as shown, each tone-mapped at its own automatic exposure"},
        {"mc_noise", "the Monte Carlo image's relative standard error (from its passes)"},
        {"size_mfp", "cube side or plate thickness over the transport mean free path 1/(mu_a + mu_s'), green"},
        {"live_ms", "the diffusion solve: assembly and iterations (CPU, tolerance 1e-3)"}};
    write_json(o.output_dir / "diffusion_vs_transport.json",
               with_provenance(provenance, inputs, definitions, {{"cases", rows}}));
    write_text(o.output_dir / "diffusion_vs_transport.md",
               "### " + titled(o, "Diffusion (live image) against transport (Monte Carlo image)") + "\n\n" +
                   transport_table_markdown(cases));

    std::vector<ChartSeries> by_thickness, by_albedo, by_time;
    for (const std::string& material : study.materials) {
        for (const std::string& side : {std::string("plate, lit side"), std::string("plate, far side")}) {
            ChartSeries line{material + ", " + side.substr(7), {}};
            for (const TransportCase& c : cases)
                if (c.material == material && c.shape == side) line.points.emplace_back(c.size_mfp, c.difference.scaled_relative_l2);
            by_thickness.push_back(line);
        }
    }
    for (double scale : study.cube_scales) {
        char name[64];
        std::snprintf(name, sizeof name, "cube, %g mm per unit", scale);
        ChartSeries line{name, {}};
        for (const TransportCase& c : cases)
            if (c.shape == "cube" && c.mm_per_unit == scale) line.points.emplace_back(1 - c.albedo, c.difference.scaled_relative_l2);
        std::sort(line.points.begin(), line.points.end());
        by_albedo.push_back(line);
    }
    for (const TransportCase& c : cases) {
        if (c.shape != "cube" || c.mm_per_unit != 30) continue;
        ChartSeries trace{c.material + ": Monte Carlo standard error", c.convergence};
        trace.markers = false;
        by_time.push_back(trace);
        by_time.push_back(ChartSeries{c.material + ": live image against MC", {{c.live_ms / 1000, c.difference.scaled_relative_l2}}});
    }
    ChartOptions thickness_chart;
    thickness_chart.title = titled(o, "Live image against Monte Carlo: plates");
    thickness_chart.caption = provenance.caption();
    thickness_chart.x = {"plate thickness (transport mean free paths)", AxisScale::Log};
    thickness_chart.y = {"relative L2 error after the best brightness factor", AxisScale::Log};
    write_svg_chart(o.output_dir / "diffusion_vs_transport_thickness.svg", by_thickness, thickness_chart);
    ChartOptions albedo_chart = thickness_chart;
    albedo_chart.title = titled(o, "Live image against Monte Carlo: cubes of side 1 unit");
    albedo_chart.x = {"1 - reduced albedo (green)", AxisScale::Log};
    write_svg_chart(o.output_dir / "diffusion_vs_transport_albedo.svg", by_albedo, albedo_chart);
    ChartOptions time_chart = thickness_chart;
    time_chart.title = titled(o, "Monte Carlo convergence next to the live solve (cubes, 30 mm per unit)");
    time_chart.x = {"seconds", AxisScale::Log};
    time_chart.y = {"relative error", AxisScale::Log};
    write_svg_chart(o.output_dir / "diffusion_vs_transport_time.svg", by_time, time_chart);
    index["diffusion_vs_transport"] = "diffusion_vs_transport.json";
}

void run_table1_part(const BenchSuiteOptions& o, Json& index, RunProvenance& provenance) {
    std::vector<TimingRow> rows;
    TimingOptions options;
    options.target_tets = o.quick ? 100'000 : 500'000;
    if (o.repeats > 0) options.runs = o.repeats;
    const std::vector<std::string> models =
        o.quick ? std::vector<std::string>{"spot"} : std::vector<std::string>{"spot", "torus", "skull"};
    for (const std::string& model : models)
        rows.push_back(measure_timing_row(o.asset_dir / "meshes" / (model + ".obj"), options));
    Json inputs = Json::array();
    for (const std::string& model : models) {
        const std::filesystem::path file = o.asset_dir / "meshes" / (model + ".obj");
        inputs.push_back({{"mesh_file", file.string()}, {"mesh_sha256", file_sha256(file)}});
    }
    const Json definitions = {
        {"times", "milliseconds of wall clock, the median of " + std::to_string(options.runs) + " runs per stage"},
        {"stages", "timing_table.h: T_b = neighbourhood + hierarchy, T_m = matrix, T_s = solve from zero to the "
                   "solver's default tolerance, cut and paint with everything they rebuild"},
        {"target_tets", options.target_tets}};
    write_json(o.output_dir / "table1.json", with_provenance(provenance, inputs, definitions, {{"rows", to_json(rows)}}));
    write_text(o.output_dir / "table1.md", "### " + titled(o, "Table 1: build, matrix, solve, cut and paint times") +
                                               "\n\nTimes: median of " + std::to_string(options.runs) +
                                               " runs per stage (the paper's rows: as published).\n\n" +
                                               timing_table_markdown(rows));
    index["table1"] = "table1.md";
}

void run_stability_part(const BenchSuiteOptions& o, Json& index, RunProvenance& provenance) {
    std::vector<StudyTable> tables = run_stability_studies({.quick = o.quick});
    for (StudyTable& table : run_method_failure_studies({.quick = o.quick})) tables.push_back(std::move(table));
    Json json = Json::array();
    std::string markdown = "## " + titled(o, "Stability studies") +
                           "\n\nValues: one run per row (errors and iteration counts, no timings).\n\n";
    for (const StudyTable& t : tables) {
        json.push_back(t.to_json());
        StudyTable titled_table = t;
        titled_table.name = titled(o, t.name);
        markdown += titled_table.to_markdown() + "\n";
    }
    const Json definitions = {{"values", "one run per row; each table names its columns and their units"}};
    write_json(o.output_dir / "stability.json",
               with_provenance(provenance, {{"scenes", "generated by each study (stability_study.h)"}}, definitions,
                               {{"tables", json}}));
    write_text(o.output_dir / "stability.md", markdown);
    index["stability"] = "stability.md";
}

// The seeds' methods beside TransCut's solvers: error against time on the ball and on spot.
void run_methods_part(const BenchSuiteOptions& o, Json& index, RunProvenance& provenance) {
    MethodStudyOptions options;
    options.quick = o.quick;
    options.surface = o.asset_dir / "meshes/spot.obj";
    options.progress = o.progress;
    const std::vector<MethodSeries> series = study_methods(options);
    const Json inputs = {
        {"ball", "icosphere of radius 10 mm meshed by TetGen (2K to 300K tets; quick: 2K to 16K); mu_a 0.01, mu_s' 1 "
                 "per mm, eta 1.3; grid methods at the voxel size giving as many voxels as the mesh has vertices; the "
                 "dipole up to 120K tets (it is quadratic in the vertices)"},
        {"surface", {{"mesh_file", options.surface.string()},
                     {"mesh_sha256", file_sha256(options.surface)},
                     {"material", "marble"},
                     {"mm_per_unit", o.quick ? 3.0 : 30.0},
                     {"reference", "TransCut (Jacobi CG to 1e-8) on a TetGen mesh of 0.5 x the default size (quick: 0.7)"},
                     {"lighting", lighting_to_json(key_light_only())}}}};
    const Json definitions = {
        {"ball_error", "relative L2 error of phi (channel 0, weighted by TransCut's lumped vertex volume) at the mesh "
                       "vertices against the analytic series (60 Legendre terms for the directional light)"},
        {"surface_error", "relative L2 error of phi at the input surface's vertices, three channels, against the "
                          "reference"},
        {"setup_ms", "grid, graph, profile or hierarchy construction and assembly; one run, wall clock"},
        {"solve_ms", "iterations (or the direct evaluation) for three channels to relative tolerance 1e-6; one run"},
        {"resolution_mm", "mean tet size (volume / tets)^(1/3), or the voxel size of fd and lbm"},
        {"observed_order", "least-squares slope of log(error) against log(resolution_mm) (accuracy.json's fit)"}};
    write_json(o.output_dir / "methods.json",
               with_provenance(provenance, inputs, definitions, {{"series", to_json(series)}}));
    write_text(o.output_dir / "methods.md", "### " + titled(o, "The seeds' methods beside TransCut") +
                                                "\n\nFinest run of each series; one run each, wall clock.\n\n" +
                                                method_table_markdown(series));
    auto chart = [&](const std::string& scene, const std::string& title, const std::filesystem::path& path) {
        std::vector<ChartSeries> lines;
        for (const MethodSeries& s : series) {
            if (s.scene != scene) continue;
            ChartSeries line;
            line.name = s.method;
            if (s.runs.size() > 1) {
                const OrderFit fit = s.fit_order();
                char name[160];
                std::snprintf(name, sizeof name, "%s (order %.2f%s)", s.method.c_str(), fit.order,
                              fit.reliable ? "" : ", unreliable");
                line.name = name;
            }
            for (const MethodRun& r : s.runs)
                if (std::isfinite(r.relative_error) && r.relative_error > 0)
                    line.points.emplace_back(r.setup_ms + r.solve_ms, r.relative_error);
            if (!line.points.empty()) lines.push_back(std::move(line));
        }
        ChartOptions chart_options;
        chart_options.title = titled(o, title);
        chart_options.x = {"setup + solve, three channels (ms)", AxisScale::Log};
        chart_options.y = {"relative L2 error of phi", AxisScale::Log};
        chart_options.caption = provenance.caption();
        write_svg_chart(path, lines, chart_options);
    };
    chart("ball directional", "Error against time: ball (R = 10 mm), directional light", o.output_dir / "methods.svg");
    chart("ball uniform", "Error against time: ball (R = 10 mm), uniform light", o.output_dir / "methods_uniform.svg");
    chart("spot", "Error against time: spot (marble), against TransCut at half the tet size",
          o.output_dir / "methods_spot.svg");
    index["methods"] = "methods.json";
}

void run_resolution_part(const BenchSuiteOptions& o, Json& index, RunProvenance& provenance) {
    ResolutionStudyOptions options;
    options.surface = o.asset_dir / "meshes/spot.obj";
    if (o.quick) {
        options.mm_per_unit = 3;
        options.size_factors = {2.0, 1.0};
        options.tolerances = {0.1, 0.01, 1e-3};
        options.reference_size_factor = 0.7;
    }
    const ResolutionStudy study = run_resolution_study(options);
    Json json = study.to_json();
    json["material"] = options.material;
    json["mm_per_unit"] = options.mm_per_unit;
    json["error_bound"] = options.error_bound;
    const Json inputs = {{"mesh_file", options.surface.string()},
                         {"mesh_sha256", file_sha256(options.surface)},
                         {"material", options.material},
                         {"mm_per_unit", options.mm_per_unit},
                         {"image", {options.width, options.height}}};
    const Json definitions = {
        {"image_error", "relative L2 difference of the rendered image from the reference image (mesh at "
                        "reference_size_factor x the default size, tolerance reference_tolerance), same view and "
                        "exposure"},
        {"solve_ms", "assembly + solve, milliseconds of wall clock, one run per sample"}};
    write_json(o.output_dir / "resolution.json", with_provenance(provenance, inputs, definitions, json));

    std::map<double, ChartSeries> by_factor;
    for (const ResolutionSample& s : study.samples) {
        ChartSeries& line = by_factor[s.size_factor];
        char name[96];
        std::snprintf(name, sizeof name, "%.2g x default size (%zu tets)", s.size_factor, s.tets);
        line.name = name;
        line.points.emplace_back(s.solve_ms, s.image_error);
    }
    std::vector<ChartSeries> lines;
    for (auto& [factor, line] : by_factor) lines.push_back(std::move(line));
    ChartOptions chart;
    chart.title = titled(o, "Rendered image error against solve time (tolerances along each line)");
    chart.target_line = options.error_bound;
    chart.target_label = "error bound";
    chart.caption = provenance.caption() + " | times: one run per sample";
    chart.x = {"assembly + solve (ms)", AxisScale::Log};
    chart.y = {"relative image error", AxisScale::Log};
    write_svg_chart(o.output_dir / "resolution.svg", lines, chart);
    index["resolution"] = "resolution.json";
}

}  // namespace

void run_bench_suite(const BenchSuiteOptions& o) {
    std::error_code ec;
    std::filesystem::create_directories(o.output_dir, ec);
    if (ec) throw FileError(o.output_dir.string(), "cannot create the output directory: " + ec.message());

    // With --only, the parts not run keep their entries from an earlier run of the suite in DIR.
    Json index = Json::object();
    if (!o.only.empty() && std::filesystem::exists(o.output_dir / "bench.json")) {
        try {
            index = Json::parse(read_file_contents(o.output_dir / "bench.json"));
        } catch (const std::exception&) {
            index = Json::object();  // unreadable: start afresh
        }
    }
    index["quick"] = o.quick;
    index["repeats"] = o.repeats;
    index["hardware_threads"] = std::thread::hardware_concurrency();
    index["command"] = command_line();
    index["build"] = build_provenance();
    const std::time_t now = std::time(nullptr);
    char date[32];
    std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
    index["date"] = date;
    if (!index.contains("parts") || !index["parts"].is_object()) index["parts"] = Json::object();

    using Part = std::function<void(Json&, RunProvenance&)>;
    std::vector<std::pair<std::string, Part>> parts = {
        {"solvers_50k", [&](Json& i, RunProvenance& p) { run_solver_part(o, 50'000, i, p); }},
    };
    if (!o.quick) parts.emplace_back("solvers_500k", [&](Json& i, RunProvenance& p) { run_solver_part(o, 500'000, i, p); });
    parts.emplace_back("coarse_start", [&](Json& i, RunProvenance& p) { run_coarse_start_part(o, i, p); });
    parts.emplace_back("accuracy", [&](Json& i, RunProvenance& p) { run_accuracy_part(o, i, p); });
    parts.emplace_back("cut_modes", [&](Json& i, RunProvenance& p) { run_cut_modes_part(o, i, p); });
    parts.emplace_back("environment", [&](Json& i, RunProvenance& p) { run_environment_part(o, i, p); });
    parts.emplace_back("table1", [&](Json& i, RunProvenance& p) { run_table1_part(o, i, p); });
    parts.emplace_back("stability", [&](Json& i, RunProvenance& p) { run_stability_part(o, i, p); });
    parts.emplace_back("methods", [&](Json& i, RunProvenance& p) { run_methods_part(o, i, p); });
    parts.emplace_back("resolution", [&](Json& i, RunProvenance& p) { run_resolution_part(o, i, p); });
    parts.emplace_back("diffusion_vs_transport", [&](Json& i, RunProvenance& p) { run_transport_part(o, i, p); });

    for (const std::string& wanted : o.only)
        if (std::none_of(parts.begin(), parts.end(), [&](const auto& part) { return part.first == wanted; }))
            throw InvalidArgumentError("bench --only: unknown part '" + wanted + "'" +
                                       (o.quick && wanted == "solvers_500k" ? " (not part of --quick)" : ""));

    std::exception_ptr first_failure;
    for (const auto& [name, part] : parts) {
        if (!o.only.empty() && std::find(o.only.begin(), o.only.end(), name) == o.only.end()) continue;
        if (o.progress) o.progress(name);
        const auto start = std::chrono::steady_clock::now();
        Json entry;
        try {
            // The solver comparisons run every solver on the same count (one thread unless --threads says
            // otherwise: Eigen's and CHOLMOD's solvers use one); the other parts measure Waxwork as it
            // runs, on every hardware thread.
            const bool comparison = name.rfind("solvers_", 0) == 0;
            const ThreadLimit limit(o.threads.value_or(comparison ? 1 : 0));
            RunProvenance provenance(limit);
            entry["threads"] = limit.threads();
            part(index, provenance);
            entry["status"] = "ok";
        } catch (const std::exception& e) {
            entry["status"] = std::string("failed: ") + e.what();
            if (!first_failure) first_failure = std::current_exception();
        }
        entry["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        index["parts"][name] = entry;
        write_json(o.output_dir / "bench.json", index);  // after every part: a crash keeps what ran
    }
    if (first_failure) std::rethrow_exception(first_failure);
}

}  // namespace waxwork
