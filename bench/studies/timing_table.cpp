#include "bench/studies/timing_table.h"

#include "base/error.h"
#include "base/timing.h"
#include "bench/studies/repeated_timing.h"
#include "io/surface_reader.h"
#include "multires/multires_solver.h"
#include "solver/diffusion_matrix.h"
#include "solver/light_spec.h"
#include "solver/material.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/paint.h"
#include "tetops/relaxation.h"
#include "tetops/tetrahedralize.h"

#include <array>
#include <chrono>
#include <cstdio>
#include <optional>
#include <sstream>

namespace waxwork {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

TimingRow measure_timing_row(const std::filesystem::path& surface_path, const TimingOptions& options) {
    const TetMaterial material = material_preset(options.material);
    const TriangleSurface surface = load_closed_surface(surface_path).surface;
    MeshingOptions meshing;
    meshing.sizing.target_tets = options.target_tets;
    TimingRow row;
    row.mesher = "tetgen";
    MeshingResult meshed;
    try {
        meshed = tetrahedralize(surface, meshing);
    } catch (const InvalidArgumentError&) {  // TetGen's floor on the count for this surface
        meshing.mesher = Mesher::Cgal;
        row.mesher = "cgal";
        meshed = tetrahedralize(surface, meshing);
    }
    TetMesh mesh = std::move(meshed.mesh);

    row.model = surface_path.stem().string();
    row.tets = mesh.tet_count();
    row.vertices = mesh.vertex_count();
    row.meshing_ms = meshed.milliseconds;

    AssemblyOptions assembly;
    assembly.mm_per_unit = options.mm_per_unit;
    std::vector<TetMaterial> materials(mesh.tet_count(), material);
    // Times a stage `options.runs` times, keeping its median, fastest and slowest run.
    auto timed = [&](const char* stage, const std::function<double()>& run) {
        const RunTimes times = repeated_run_ms(options.runs, run);
        row.runs[stage] = times;
        return times.ms;
    };

    // Each stage runs `runs` times and its median is kept; what a run built is released before the
    // next run starts its clock, and the last run's result feeds the next stage.
    std::optional<TetConnectivity> connectivity;
    row.connectivity_ms = timed("connectivity", [&] {
        connectivity.reset();
        const auto start = Clock::now();
        connectivity.emplace(build_connectivity(mesh));
        return milliseconds_since(start);
    });
    std::optional<DiffusionMatrix> matrix;
    row.matrix_ms = timed("matrix", [&] {
        matrix.reset();
        const auto start = Clock::now();
        matrix.emplace(assemble_diffusion_matrix(mesh, *connectivity, materials, assembly));
        return milliseconds_since(start);
    });
    std::optional<MultiresSolver> solver;
    row.hierarchy_ms = timed("hierarchy", [&] {
        solver.reset();
        const auto start = Clock::now();
        solver.emplace(*matrix, mesh.positions);
        return milliseconds_since(start);
    });
    row.build_ms = row.connectivity_ms + row.hierarchy_ms;
    row.levels = static_cast<int>(solver->hierarchy().level_count());

    Lighting lighting;
    lighting.lights.push_back(default_key_light());
    const std::vector<Rgb> q = incident_light(mesh, *connectivity, materials, lighting);
    std::array<std::vector<double>, 3> b;  // not timed: q is the lighting's share
    for (int c = 0; c < 3; ++c) {
        b[static_cast<size_t>(c)].resize(matrix->size());
        diffusion_right_hand_side(*matrix, q, c, b[static_cast<size_t>(c)]);
    }
    MultiresSolveOptions solve_options;
    solve_options.relative_tolerance = 0.01;
    std::vector<double> x(matrix->size());
    bool first_solve = true;
    row.solve_ms = timed("solve", [&] {
        const auto start = Clock::now();
        for (int c = 0; c < 3; ++c) {
            const MultiresSolveReport report = solver->solve(b[static_cast<size_t>(c)], c, x, solve_options);
            if (first_solve) row.solve_level0_iterations[static_cast<size_t>(c)] = report.fine.iterations;
        }
        first_solve = false;
        return milliseconds_since(start);
    });

    // Paint first (on the uncut mesh, as the paper's Fig. 10): a 100-point stroke across the box. Each
    // run repaints the same tets with a brush 1% apart from the last run's, so that every run changes
    // every tet it reaches (the same work) on the one mesh, matrix and hierarchy.
    mesh.materials = materials;
    {
        const auto box = bounding_box(mesh);
        std::vector<Eigen::Vector3d> stroke;
        for (int i = 0; i < 100; ++i) {
            const double s = 0.2 + 0.6 * i / 99.0;
            stroke.push_back(box[0] + s * (box[1] - box[0]));
        }
        const PaintIndex index(mesh);  // built once per mesh state, not per stroke
        PaintBrush brush;
        brush.material = material_preset("skin1");
        brush.sigma = 0.01 * (box[1] - box[0]).norm();
        row.paint_ms = timed("paint", [&] {
            const auto start = Clock::now();
            const PaintResult painted = paint_stroke(mesh, index, stroke, brush);
            const std::vector<int32_t> rows =
                update_diffusion_matrix(*matrix, mesh, *connectivity, mesh.materials, painted.changed_tets);
            solver->update_values(*matrix, rows);  // only the coarse rows that depend on the painted ones
            const double ms = milliseconds_since(start);
            brush.material.mua[1] *= 1.01;
            return ms;
        });
    }

    // Cut: a slanted plane through the middle, relaxation, and every rebuild the next frame needs, each
    // run on a fresh copy of the painted mesh. The hierarchy is rebuilt around the cut from the
    // painted mesh's, as the editor does (rebuild_multires_hierarchy; the paper rebuilds from scratch).
    {
        const auto box = bounding_box(mesh);
        const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 0.3, 0.2).normalized();
        const PlaneCut plane(normal, normal.dot(0.5 * (box[0] + box[1])));
        row.cut_ms = timed("cut", [&] {
            TetMesh cut = mesh;
            const auto start = Clock::now();
            const CutResult removed = remove_cut_away_tets(cut, plane);
            const TetConnectivity cut_connectivity = build_connectivity(cut);
            RelaxationOptions relax;
            relax.max_iterations = 10;
            relax_cut_vertices(cut, cut_connectivity, plane, relax);
            const DiffusionMatrix cut_matrix = assemble_diffusion_matrix(cut, cut_connectivity, cut.materials, assembly);
            const MultiresSolver cut_solver(
                rebuild_multires_hierarchy(solver->hierarchy(), removed.old_to_new_vertex, cut_matrix, cut.positions));
            return milliseconds_since(start);
        });
    }
    return row;
}

namespace {

// {stage: {"median", "min", "max"}} in ms.
nlohmann::ordered_json runs_json(const std::map<std::string, RunTimes>& runs) {
    nlohmann::ordered_json out = nlohmann::ordered_json::object();
    for (const auto& [stage, t] : runs) out[stage] = {{"median", t.ms}, {"min", t.min_ms}, {"max", t.max_ms}};
    return out;
}

// "median (min-max)" of a stage, or the bare median when it ran once or is missing.
std::string with_spread(const TimingRow& row, const char* stage, double median, const char* format) {
    char text[96];
    std::snprintf(text, sizeof text, format, median);
    const auto it = row.runs.find(stage);
    if (it == row.runs.end() || it->second.min_ms == it->second.max_ms) return text;
    char spread[96];
    std::snprintf(spread, sizeof spread, (std::string(" (") + format + "-" + format + ")").c_str(), it->second.min_ms,
                  it->second.max_ms);
    return text + std::string(spread);
}

}  // namespace

nlohmann::ordered_json to_json(const std::vector<TimingRow>& rows) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const TimingRow& r : rows)
        out.push_back({{"model", r.model},
                       {"mesher", r.mesher},
                       {"tets", r.tets},
                       {"vertices", r.vertices},
                       {"levels", r.levels},
                       {"meshing_ms", r.meshing_ms},
                       {"connectivity_ms", r.connectivity_ms},
                       {"hierarchy_ms", r.hierarchy_ms},
                       {"Tb_ms", r.build_ms},
                       {"Tm_ms", r.matrix_ms},
                       {"Ts_ms", r.solve_ms},
                       {"Ts_level0_iterations", r.solve_level0_iterations},
                       {"cut_ms", r.cut_ms},
                       {"paint_ms", r.paint_ms},
                       {"runs_ms", runs_json(r.runs)}});
    return out;
}

std::string timing_table_markdown(const std::vector<TimingRow>& rows) {
    std::ostringstream md;
    md << "| model | #tet | #level | T_b (ms) | T_m (ms) | T_s (ms) | cut (ms) | paint (ms) |\n"
       << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    char line[256];
    for (const TimingRow& r : rows) {
        const std::string model = r.model + (r.mesher == "tetgen" ? "" : " (" + r.mesher + ")");
        std::snprintf(line, sizeof line, "| %s | %zu | %d | %.0f | ", model.c_str(), r.tets, r.levels, r.build_ms);
        md << line << with_spread(r, "matrix", r.matrix_ms, "%.0f") << " | " << with_spread(r, "solve", r.solve_ms, "%.0f")
           << " | " << with_spread(r, "cut", r.cut_ms, "%.0f") << " | " << with_spread(r, "paint", r.paint_ms, "%.1f")
           << " |\n";
    }
    for (const PaperTimingRow& p : kTransCutTable1) {
        std::snprintf(line, sizeof line, "| %s (paper, GTX 480) | %zu | %d | %.0f | %.0f | %.0f | < 3000 | real time |\n",
                      p.model, p.tets, p.levels, p.build_ms, p.matrix_ms, p.solve_ms);
        md << line;
    }
    return md.str();
}

}  // namespace waxwork
