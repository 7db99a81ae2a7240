#include "editor/timing_table.h"

#include "editor/render_pipeline.h"
#include "io/surface_reader.h"
#include "multires/multires_solver.h"
#include "solver/diffusion_matrix.h"
#include "solver/material.h"
#include "tetops/connectivity.h"
#include "tetops/error.h"
#include "tetops/cut.h"
#include "tetops/paint.h"
#include "tetops/relaxation.h"
#include "tetops/tetrahedralize.h"

#include <chrono>
#include <cstdio>
#include <sstream>

namespace waxwork {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct SolverState {
    TetConnectivity connectivity;
    DiffusionMatrix matrix;
    std::unique_ptr<MultiresSolver> solver;
};

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

    auto start = Clock::now();
    TetConnectivity connectivity = build_connectivity(mesh);
    row.connectivity_ms = ms_since(start);
    start = Clock::now();
    DiffusionMatrix matrix = assemble_diffusion_matrix(mesh, connectivity, materials, assembly);
    row.matrix_ms = ms_since(start);
    start = Clock::now();
    MultiresSolver solver(matrix, mesh.positions);
    row.hierarchy_ms = ms_since(start);
    row.build_ms = row.connectivity_ms + row.hierarchy_ms;
    row.levels = static_cast<int>(solver.hierarchy().level_count());

    Lighting lighting;
    lighting.lights.push_back(default_key_light());
    const std::vector<Rgb> q = incident_light(mesh, connectivity, materials, lighting);
    MultiresSolveOptions solve_options;
    solve_options.relative_tolerance = 0.01;
    std::vector<double> b(matrix.size()), x(matrix.size());
    double solve_ms = 0;
    for (int c = 0; c < 3; ++c) {
        diffusion_right_hand_side(matrix, q, c, b);  // not timed: q is the lighting's share
        start = Clock::now();
        solver.solve(b, c, x, solve_options);
        solve_ms += ms_since(start);
    }
    row.solve_ms = solve_ms;

    // Paint first (on the uncut mesh, as the paper's Fig. 10): a 100-point stroke across the box.
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
        mesh.materials = materials;
        start = Clock::now();
        const PaintResult painted = paint_stroke(mesh, index, stroke, brush);
        const std::vector<int32_t> rows =
            update_diffusion_matrix(matrix, mesh, connectivity, mesh.materials, painted.changed_tets);
        solver.update_values(matrix, rows);  // only the coarse rows that depend on the painted ones
        row.paint_ms = ms_since(start);
        materials = mesh.materials;
    }

    // Cut: a slanted plane through the middle, relaxation, and every rebuild the next frame needs.
    {
        const auto box = bounding_box(mesh);
        const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 0.3, 0.2).normalized();
        const PlaneCut plane(normal, normal.dot(0.5 * (box[0] + box[1])));
        start = Clock::now();
        remove_cut_away_tets(mesh, plane);
        const TetConnectivity cut_connectivity = build_connectivity(mesh);
        RelaxationOptions relax;
        relax.max_iterations = 10;
        relax_cut_vertices(mesh, cut_connectivity, plane, relax);
        const DiffusionMatrix cut_matrix = assemble_diffusion_matrix(mesh, cut_connectivity, mesh.materials, assembly);
        const MultiresSolver cut_solver(cut_matrix, mesh.positions);
        row.cut_ms = ms_since(start);
    }
    return row;
}

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
                       {"cut_ms", r.cut_ms},
                       {"paint_ms", r.paint_ms}});
    return out;
}

std::string timing_table_markdown(const std::vector<TimingRow>& rows) {
    std::ostringstream md;
    md << "| model | #tet | #level | T_b (ms) | T_m (ms) | T_s (ms) | cut (ms) | paint (ms) |\n"
       << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    char line[256];
    for (const TimingRow& r : rows) {
        const std::string model = r.model + (r.mesher == "tetgen" ? "" : " (" + r.mesher + ")");
        std::snprintf(line, sizeof line, "| %s | %zu | %d | %.0f | %.0f | %.0f | %.0f | %.1f |\n", model.c_str(), r.tets,
                      r.levels, r.build_ms, r.matrix_ms, r.solve_ms, r.cut_ms, r.paint_ms);
        md << line;
    }
    for (const PaperTimingRow& p : kTransCutTable1) {
        std::snprintf(line, sizeof line, "| %s (paper, GTX 480) | %zu | %d | %.0f | %.0f | %.0f | < 3000 | real time |\n",
                      p.model, p.tets, p.levels, p.build_ms, p.matrix_ms, p.solve_ms);
        md << line;
    }
    return md.str();
}

}  // namespace waxwork
