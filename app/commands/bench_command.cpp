// `waxwork bench`: measurements that back docs/ (performance, accuracy, stability), written as JSON, SVG and PDF.
//   waxwork bench solvers --mesh MESH [--max-tets N] -o DIR [--backend cpu|gpu] [--material NAME | ...]
//                         [--repeats N] [--threads N] [--include-setup] [--mesher auto|tetgen|cgal] [--fill-holes] [...]
// `bench` itself takes the subcommand; it is a CLI11 app with an optional subcommand so that a later
// `waxwork bench [--quick] -o DIR` (all benchmarks) can be the parent's own action.
#include "app/commands.h"
#include "app/options/material_options.h"
#include "app/options/surface_meshing_options.h"
#include "base/error.h"
#include "bench/studies/bench_suite.h"
#include "bench/studies/provenance.h"
#include "bench/studies/thread_limit.h"
#include "bench/studies/solver_comparison.h"
#include "io/surface_reader.h"
#include "io/volume_file.h"
#include "scene/session.h"
#include "solver/light_spec.h"
#include "solver/material.h"
#include "tetops/tetrahedralize.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

namespace waxwork {
namespace {

struct SolversCommandOptions {
    std::string mesh;
    std::optional<size_t> max_tets;
    std::string output;
    std::string backend = "cpu";
    std::optional<double> scale;
    double floor_error = 1e-4;
    double max_seconds = 60;
    int repeats = 0;  // 0: the comparison's default statistic
    int threads = 1;  // every library alike (bench/studies/thread_limit.h); 0: every hardware thread
    bool include_setup = false;
    SurfaceMeshingOptions meshing;
    MaterialOptions material;
};

// The volume to compare on, and how it was made (the provenance's "meshing").
std::pair<TetMesh, nlohmann::ordered_json> load_or_mesh(const SolversCommandOptions& o) {
    if (is_volume_path(o.mesh)) return {read_volume(o.mesh), {{"mesher", "none: read from the volume file"}}};
    if (!o.max_tets)
        throw InvalidArgumentError(o.mesh + ": a surface needs --max-tets (or pass a volume file)");
    const LoadedSurface surface = load_surface_to_mesh(o.mesh, o.meshing);
    MeshingOptions meshing = meshing_options(o.meshing);
    meshing.sizing.target_tets = o.max_tets;
    if (surface.wrap) meshing.remesh_edge_ratio = kWrapRemeshEdgeRatio;
    MeshingResult result = tetrahedralize_surface_file(o.mesh, surface.surface, meshing);
    nlohmann::ordered_json made = {{"mesher", mesher_name(result.mesher)},
                                   {"why", result.mesher_reason},
                                   {"target_tets", *o.max_tets},
                                   {"max_radius_edge_ratio", meshing.max_radius_edge_ratio},
                                   {"min_dihedral_bound_deg", meshing.min_dihedral_deg},
                                   {"repair", o.meshing.repair.empty() ? "none" : o.meshing.repair},
                                   {"fill_holes", o.meshing.fill_holes}};
    return {std::move(result.mesh), std::move(made)};
}

// The longest side of the bounding box becomes 100 mm unless --scale says otherwise.
double mm_per_unit(const TetMesh& mesh, const std::optional<double>& scale) {
    if (scale) return *scale;
    const auto box = bounding_box(mesh);
    const double side = (box[1] - box[0]).maxCoeff();
    return side > 0 ? 100.0 / side : 1.0;
}

void run_solvers_command(const SolversCommandOptions& o) {
    if (o.scale) validate_mm_per_unit(*o.scale, "--scale");
    if (!(o.floor_error > 0 && o.floor_error < 1))
        throw InvalidArgumentError("--floor must be between 0 and 1");
    if (!(o.max_seconds > 0) || !std::isfinite(o.max_seconds))
        throw InvalidArgumentError("--max-seconds must be positive");
    const std::optional<TetMaterial> material = chosen_material(o.material);  // before the (long) meshing
    const ThreadLimit threads(o.threads);  // before the OpenGL context: llvmpipe sizes its pool once
    RunProvenance provenance(threads);
    const auto [mesh, meshing] = load_or_mesh(o);
    if (mesh.tet_count() == 0) throw InvalidArgumentError(o.mesh + ": the volume has no tets");
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<TetMaterial> materials = resolve_materials(mesh, material);
    Lighting lighting;
    lighting.lights.push_back(default_key_light());

    SolverComparisonOptions options;
    options.mm_per_unit = mm_per_unit(mesh, o.scale);
    provenance.warn_if_under_resolved(mesh, materials, options.mm_per_unit);
    options.floor_error = o.floor_error;
    options.max_seconds = o.max_seconds;
    options.repeats = o.repeats;
    // --backend gpu adds the GPU curves (OpenGL compute shaders; OSMesa's llvmpipe unless
    // WAXWORK_GL_DEVICE=egl finds a GPU); the CPU curves stay for comparison.
    std::unique_ptr<HeadlessGlContext> context;
    if (o.backend == "gpu") context = open_gpu_for_comparison(options);
    const SolverComparison comparison = compare_solvers(mesh, connectivity, materials, lighting, options);
    if (!comparison.gpu_fallback_reason.empty())
        std::cerr << "warning: no GPU curves: " << comparison.gpu_fallback_reason << "\n";

    const std::filesystem::path dir(o.output);
    std::error_code error;
    std::filesystem::create_directories(dir, error);
    if (error) throw FileError(dir, "cannot create the directory (" + error.message() + ")");
    const std::string material_name = resolved_materials_name(mesh, material);
    SolverChartOptions chart;
    chart.include_setup = o.include_setup;
    if (context) provenance.set_gl_renderer(context->renderer());
    if (const std::string busy = busy_machine_warning(comparison); !busy.empty()) provenance.warn(busy);
    if (const std::string peers = missing_peers_warning(comparison); !peers.empty()) provenance.warn(peers);
    nlohmann::ordered_json inputs = mesh_inputs(o.mesh, mesh, options.mm_per_unit);
    inputs["meshing"] = meshing;
    inputs["material"] = material_name;
    inputs["lighting"] = lighting_to_json(lighting);
    const nlohmann::ordered_json block = provenance.to_json(inputs, solver_comparison_definitions(options));
    write_solver_comparison(dir, "solvers", {o.mesh, material_name, options.mm_per_unit}, comparison, block, chart);

    nlohmann::ordered_json summary_times = nlohmann::ordered_json::object();
    for (const SolverCurve& s : comparison.solvers)
        summary_times[s.name] = s.time_to_target_ms ? nlohmann::ordered_json(*s.time_to_target_ms) : nullptr;
    nlohmann::ordered_json summary = {
        {"output", o.output},
        {"material", material_name},
        {"tets", comparison.tets},
        {"vertices", comparison.vertices},
        {"levels", comparison.levels},
    };
    for (const auto& [key, ms] : setup_times(comparison)) summary[key] = ms;
    summary["time_to_1pct_ms"] = summary_times;
    if (context) summary["gpu_renderer"] = context->renderer();
    summary["threads"] = threads.threads();
    summary["warnings"] = block.at("warnings");
    std::cout << summary.dump() << "\n";
}

}  // namespace

void add_bench_command(CLI::App& app) {
    auto suite = std::make_shared<BenchSuiteOptions>();
    auto suite_output = std::make_shared<std::string>();
    CLI::App* bench = app.add_subcommand(
        "bench", "Speed against accuracy: the whole suite (-o DIR [--quick]) or one benchmark (solvers)");
    bench->require_subcommand(0, 1);
    bench->add_option("-o,--output", *suite_output, "Output directory of the whole suite");
    bench->add_flag("--quick", suite->quick, "Smaller meshes and fewer samples (under 2 minutes)");
    bench->add_option("--only", suite->only, "Run only these parts (solvers_50k, solvers_500k, coarse_start, accuracy, cut_modes, environment, "
                                             "table1, stability, methods, resolution, diffusion_vs_transport)")
        ->delimiter(',');
    bench->add_option("--repeats", suite->repeats,
                      "Report the median of N runs per timed point, with min and max (default: the fastest of 3 "
                      "short runs; Table 1: median of 3)")
        ->check(CLI::Range(1, 1000));
    bench->add_option("--threads", suite->threads,
                      "Threads for every library, 0 for all (default: 1 in the solver comparisons, so every "
                      "solver gets the same; all in the other parts)")
        ->check(CLI::Range(0, kMaxBenchThreads));
    bench->footer("Without a subcommand runs every part (bench/studies/bench_suite.h) and writes JSON, SVG charts and\n"
                  "markdown tables into the output directory.");
    bench->callback([bench, suite, suite_output] {
        if (!bench->get_subcommands().empty()) return;
        if (suite_output->empty())
            throw InvalidArgumentError("bench: give -o DIR for the whole suite, or name a benchmark (solvers)");
        suite->output_dir = *suite_output;
        suite->asset_dir = WAXWORK_ASSET_DIR;
        suite->progress = [](const std::string& part) { std::cerr << "bench: " << part << "\n"; };
        const auto start = std::chrono::steady_clock::now();
        run_bench_suite(*suite);
        std::cout << nlohmann::ordered_json{{"output", *suite_output},
                                            {"quick", suite->quick},
                                            {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}}
                         .dump()
                  << "\n";
    });

    auto options = std::make_shared<SolversCommandOptions>();
    CLI::App* cmd = bench->add_subcommand(
        "solvers", "Error of phi against time for every diffusion solver on one lit mesh (solvers.json, solvers.svg)");
    cmd->add_option("--mesh", options->mesh, "Surface (OBJ, OFF, PLY, STL) or volume file")
        ->required()
        ->check(CLI::ExistingFile);
    add_max_tets_option(*cmd, options->max_tets, "Mesh a surface with about this many tets");
    cmd->add_option("-o,--output", options->output, "Output directory")->required();
    cmd->add_option("--backend", options->backend,
                    "cpu, or gpu: also the GPU solvers (gpu_cg, gpu_multires) on OpenGL compute shaders")
        ->check(CLI::IsMember({"cpu", "gpu"}))
        ->capture_default_str();
    cmd->add_option("--scale", options->scale, "Millimetres per model unit (default: longest side 100 mm)");
    cmd->add_option("--floor", options->floor_error, "Stop each curve below this relative error")
        ->capture_default_str();
    cmd->add_option("--max-seconds", options->max_seconds, "Measuring time limit per solver")->capture_default_str();
    cmd->add_option("--repeats", options->repeats,
                    "Median of N runs per point, with min and max (default: fastest of 3 for runs under 100 ms)")
        ->check(CLI::Range(1, 1000));
    cmd->add_option("--threads", options->threads,
                    "Threads for every library alike (TBB, OpenMP, BLAS, llvmpipe), 0 for all hardware threads")
        ->check(CLI::Range(0, kMaxBenchThreads))
        ->capture_default_str();
    cmd->add_flag("--include-setup", options->include_setup,
                  "Chart setup + solve time (default: solve time; the JSON has both)");
    add_surface_meshing_options(*cmd, options->meshing);
    add_material_options(*cmd, options->material);
    cmd->footer(
        "Meshing options apply to a surface. Materials: --material (or --mua, --musp, --eta) for every tet, else\n"
        "the volume's stored ones, else marble. Light: the default key light of waxwork render.\n"
        "Error: relative L2 over the three channels against a direct solution (bench/studies/solver_comparison.h).");
    cmd->callback([options] { run_solvers_command(*options); });
}

}  // namespace waxwork
