#include "bench/studies/stability_study.h"

#include "base/error.h"
#include "multires/multigrid_cg.h"
#include "multires/multigrid_preconditioner.h"
#include "multires/multires_solver.h"
#include "solver/diffusion_matrix.h"
#include "solver/diffusion_solve.h"
#include "solver/material.h"
#include "solver/reference/analytic_ball.h"
#include "solver/reference/reference_solvers.h"
#include "tetops/box_mesh.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/icosphere.h"
#include "tetops/quality.h"
#include "tetops/relaxation.h"
#include "tetops/sliver_maker.h"
#include "tetops/tetrahedralize.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace waxwork {
namespace {

using Json = nlohmann::json;

// Homogeneous marble-like coefficients (1/mm) for the geometric studies: diffusion length ~5.8 mm,
// several tets, so the material itself is easy and only the geometry or precision is on trial.
const TetMaterial kPlainMaterial{{0.01, 0.01, 0.01}, {1.0, 1.0, 1.0}, 1.3};

// A number, or null when it is not finite (JSON has no NaN).
Json number(double value) { return std::isfinite(value) ? Json(value) : Json(nullptr); }

std::vector<std::array<double, 3>> boundary_light(const TetMesh& mesh, const TetConnectivity& connectivity,
                                                  double (*intensity)(const Eigen::Vector3d&)) {
    std::vector<std::array<double, 3>> q(mesh.vertex_count(), {0, 0, 0});
    for (int32_t v : connectivity.boundary_vertices) {
        const double value = intensity(mesh.positions[v]);
        q[v] = {value, value, value};
    }
    return q;
}

double everywhere(const Eigen::Vector3d&) { return 1.0; }

// Channel 0 of the exact discrete solution: double precision, gradient form, sparse direct.
std::vector<double> direct_solution(const TetMesh& mesh, const TetConnectivity& connectivity,
                                    const std::vector<TetMaterial>& materials,
                                    const std::vector<std::array<double, 3>>& q) {
    const DiffusionMatrix matrix = assemble_diffusion_matrix(mesh, connectivity, materials);
    Eigen::VectorXd b(static_cast<Eigen::Index>(matrix.size()));
    diffusion_right_hand_side(matrix, q, 0, std::span<double>(b.data(), matrix.size()));
    const DirectSolver direct(to_eigen_sparse(matrix, 0));
    const Eigen::VectorXd x = direct.solve(b);
    return {x.data(), x.data() + x.size()};
}

// Relative error of channel 0 against a reference, weighted by `weights` (all ones when empty).
double relative_error(const std::vector<std::array<double, 3>>& phi, const std::vector<double>& reference,
                      const std::vector<double>& weights = {}) {
    double error = 0, norm = 0;
    for (size_t v = 0; v < reference.size(); ++v) {
        const double w = weights.empty() ? 1.0 : weights[v];
        error += w * (phi[v][0] - reference[v]) * (phi[v][0] - reference[v]);
        norm += w * reference[v] * reference[v];
    }
    return std::sqrt(error / norm);
}

struct PathOutcome {
    std::string outcome;  // "converged" or "error: ..." (the solver's own report)
    int iterations = 0;
    double estimated_error = std::numeric_limits<double>::quiet_NaN();
    std::vector<std::array<double, 3>> phi;
};

PathOutcome run_solver(const TetMesh& mesh, const TetConnectivity& connectivity,
                       const std::vector<TetMaterial>& materials, const std::vector<std::array<double, 3>>& q,
                       SolverPrecision precision, StiffnessForm form, double tolerance) {
    DiffusionOptions options;
    options.precision = precision;
    options.stiffness_form = form;
    options.relative_tolerance = tolerance;
    PathOutcome outcome;
    try {
        DiffusionSolution solution = solve_diffusion(mesh, connectivity, materials, q, options);
        outcome.outcome = "converged";
        outcome.iterations = solution.iterations[0];
        outcome.estimated_error = solution.estimated_relative_error[0];
        outcome.phi = std::move(solution.phi);
    } catch (const AlgorithmError& e) {
        outcome.outcome = std::string("error: ") + e.what();
    }
    return outcome;
}

const char* precision_name(SolverPrecision p) { return p == SolverPrecision::Double ? "double" : "float"; }
const char* form_name(StiffnessForm f) { return f == StiffnessForm::Gradient ? "gradient" : "cotangent"; }

constexpr SolverPrecision kPrecisions[] = {SolverPrecision::Double, SolverPrecision::Float};
constexpr StiffnessForm kForms[] = {StiffnessForm::Gradient, StiffnessForm::Cotangent};

// Rows for every precision x form on one mesh: outcome, iterations, error against the direct solution.
void add_precision_form_rows(StudyTable& table, const std::vector<Json>& prefix, const TetMesh& mesh,
                             const TetConnectivity& connectivity, double tolerance) {
    const std::vector<TetMaterial> materials(mesh.tet_count(), kPlainMaterial);
    const auto q = boundary_light(mesh, connectivity, everywhere);
    const std::vector<double> reference = direct_solution(mesh, connectivity, materials, q);
    for (SolverPrecision precision : kPrecisions)
        for (StiffnessForm form : kForms) {
            const PathOutcome path = run_solver(mesh, connectivity, materials, q, precision, form, tolerance);
            std::vector<Json> row = prefix;
            row.insert(row.end(), {precision_name(precision), form_name(form), path.outcome, path.iterations,
                                   number(path.phi.empty() ? NAN : relative_error(path.phi, reference))});
            table.rows.push_back(std::move(row));
        }
}

double mesh_min_dihedral(const TetMesh& mesh) { return measure_quality(mesh).min_dihedral_deg; }

// A box of n^3 unit cells with six interior vertices pushed into caps of relative height `flatness`.
TetMesh sliver_box(int n, double flatness) {
    TetMesh mesh = make_box_mesh({n, n, n}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(n));
    flatten_into_slivers(mesh, build_connectivity(mesh), 6, flatness);
    return mesh;
}

}  // namespace

nlohmann::ordered_json StudyTable::to_json() const {
    nlohmann::ordered_json out;
    out["name"] = name;
    out["what_fails"] = what_fails;
    out["how_it_shows"] = how_it_shows;
    out["what_waxwork_does"] = what_waxwork_does;
    out["columns"] = columns;
    out["rows"] = rows;
    return out;
}

std::string StudyTable::to_markdown() const {
    std::ostringstream md;
    md << "### " << name << "\n\n"
       << "- What fails: " << what_fails << "\n- How it shows: " << how_it_shows
       << "\n- What Waxwork does: " << what_waxwork_does << "\n\n|";
    for (const auto& c : columns) md << " " << c << " |";
    md << "\n|";
    for (size_t i = 0; i < columns.size(); ++i) md << " --- |";
    md << "\n";
    for (const auto& row : rows) {
        md << "|";
        for (const Json& cell : row) {
            if (cell.is_string()) md << " " << cell.get<std::string>() << " |";
            else if (cell.is_number_float()) {
                char text[32];
                std::snprintf(text, sizeof text, "%.3g", cell.get<double>());
                md << " " << text << " |";
            } else if (cell.is_null()) md << " - |";
            else md << " " << cell.dump() << " |";
        }
        md << "\n";
    }
    return md.str();
}

StudyTable study_slivers(const StudySize& size) {
    StudyTable table;
    table.name = "slivers";
    table.what_fails =
        "TransCut's weights (Eq. 10) grow like the cotangent of a dihedral angle, so on slivers the matrix "
        "has entries orders of magnitude above the typical ones and its condition number grows";
    table.how_it_shows =
        "CG needs more iterations as the angle shrinks; in float the rounding of the large entries can leave a "
        "residual floor above the tolerance";
    table.what_waxwork_does =
        "weights are computed relative to each tet's first vertex, which keeps both forms and both precisions "
        "accurate down to 0.01 degrees on these meshes (the table); if float cannot reach the tolerance it "
        "reports AlgorithmError rather than a wrong image; double precision is the default; the meshers aim "
        "at 10 degrees (TetGen's bound away from the input triangles, CGAL's perturber and exuder) and "
        "relaxation keeps angles above 0.5 degrees, so slivers like these arrive in imported volumes";
    table.columns = {"flatness", "min_dihedral_deg", "precision", "form", "outcome", "iterations", "rel_error"};
    const int n = size.quick ? 6 : 8;
    const std::vector<double> flatness = size.quick ? std::vector<double>{0.1, 1e-3, 1e-4}
                                                    : std::vector<double>{0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4};
    for (double f : flatness) {
        const TetMesh mesh = sliver_box(n, f);
        const TetConnectivity connectivity = build_connectivity(mesh);
        add_precision_form_rows(table, {f, mesh_min_dihedral(mesh)}, mesh, connectivity, 1e-4);
    }
    return table;
}

StudyTable study_relaxation_guard(const StudySize& size) {
    StudyTable table;
    table.name = "relaxation guard (TransCut Fig. 9)";
    table.what_fails =
        "relaxing the vertices left on the cut-away side towards their one-ring average squeezes the tets "
        "between them and the cross-section flat";
    table.how_it_shows =
        "minimum dihedral angles near zero after relaxation, then the slivers' failure modes (see slivers)";
    table.what_waxwork_does =
        "a move is rejected when it would leave a tet of the vertex's star under 0.5 degrees (the paper's "
        "fix), so the relaxed mesh keeps every angle it had above the guard";
    table.columns = {"guard_deg", "vertices_moved", "min_dihedral_deg", "tets_under_0.5deg",
                     "precision",  "form",           "outcome",          "iterations",
                     "rel_error"};
    // An unstructured (TetGen) ball: a Kuhn cube's regular stars resist squeezing.
    MeshingOptions meshing;
    meshing.sizing.target_tets = size.quick ? 6000 : 20000;
    const TetMesh ball = tetrahedralize(make_icosphere(3, 10.0), meshing).mesh;
    for (double guard : {0.5, 0.0}) {
        TetMesh mesh = ball;
        const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 0.35, 0.2).normalized();
        const PlaneCut plane(normal, 1.3);
        remove_cut_away_tets(mesh, plane);
        const TetConnectivity connectivity = build_connectivity(mesh);
        RelaxationOptions relax;
        relax.max_iterations = 100;
        relax.min_dihedral_guard_deg = guard;
        const RelaxationReport report = relax_cut_vertices(mesh, connectivity, plane, relax);
        const std::vector<double> angles = min_dihedral_angles_deg(mesh);
        const auto under = std::count_if(angles.begin(), angles.end(), [](double a) { return a < 0.5; });
        add_precision_form_rows(table, {guard, report.vertices_moved, report.min_dihedral_deg, under}, mesh,
                                connectivity, 1e-4);
    }
    return table;
}

StudyTable study_material_extremes(const StudySize& size) {
    StudyTable table;
    table.name = "albedo extremes";
    table.what_fails =
        "with mu_a -> 0 (spectralon) the matrix loses its mass term and only the Robin boundary keeps it "
        "definite; with strong absorption (ketchup) the light decays over a diffusion length far below "
        "the tet size";
    table.how_it_shows =
        "high albedo: the solve still converges and the constant solution is exact; high absorption: the "
        "boundary layer is under-resolved and the error against the exact solution grows with the ratio "
        "of tet size to diffusion length (the table)";
    table.what_waxwork_does =
        "mu_a = 0 is allowed and tested (exact constant solution); the default mesh size follows the "
        "smallest diffusion length (h = l_d / 2, solver/mesh_resolution.h) so strongly absorbing materials "
        "get finer meshes near the surface, within the D/150 floor";
    table.columns = {"material", "channel", "mua_per_mm", "musp_per_mm", "diffusion_length_mm", "tet_size_mm",
                     "outcome",  "iterations", "rel_error_vs_exact"};
    constexpr double kRadius = 10.0;
    MeshingOptions meshing;
    meshing.sizing.target_tets = size.quick ? 6000 : 16000;
    const TetMesh mesh = tetrahedralize(make_icosphere(3, kRadius), meshing).mesh;
    const TetConnectivity connectivity = build_connectivity(mesh);
    const double tet_size = std::cbrt(total_volume(mesh) / static_cast<double>(mesh.tet_count()));
    for (const char* name : {"spectralon", "skimmilk", "marble", "skin1", "ketchup"}) {
        const TetMaterial preset = material_preset(name);
        // The preset's channel with the shortest diffusion length (the hardest one), in all three channels:
        // the analytic ball has one set of coefficients.
        size_t c = 0;
        for (size_t k = 1; k < 3; ++k)
            if (diffusion_length(preset.mua[k], preset.musp[k]) < diffusion_length(preset.mua[c], preset.musp[c])) c = k;
        const TetMaterial single{{preset.mua[c], preset.mua[c], preset.mua[c]},
                              {preset.musp[c], preset.musp[c], preset.musp[c]}, preset.eta};
        DiffusionOptions options;
        options.relative_tolerance = 1e-7;
        std::string outcome = "converged";
        int iterations = 0;
        double error = NAN;
        try {
            const BallComparison comparison =
                compare_with_analytic_ball(mesh, connectivity, single, kRadius, BallLight::Uniform, options);
            iterations = comparison.solution.iterations[0];
            error = comparison.relative_error;
        } catch (const AlgorithmError& e) {
            outcome = std::string("error: ") + e.what();
        }
        table.rows.push_back({name, std::string(1, "rgb"[c]), single.mua[0], single.musp[0], number(diffusion_length(single.mua[0], single.musp[0])),
                              tet_size, outcome, iterations, number(error)});
    }
    return table;
}

StudyTable study_thin_parts(const StudySize& size) {
    StudyTable table;
    table.name = "thin parts and long mean free paths";
    table.what_fails =
        "a part only one or two tets thick has no interior vertex across it, and a mean free path longer "
        "than a tet means the fluence changes within one tet in ways linear elements cannot follow";
    table.how_it_shows =
        "discretisation error against a twice-refined mesh; the solver itself stays stable (the matrix is "
        "as well conditioned as any other)";
    table.what_waxwork_does =
        "the default mesh size is capped at D/25 and follows the diffusion length, and TetGen's quality "
        "bound refines thin features; the table says how much accuracy a thin part costs at a given size";
    table.columns = {"thickness_tets", "mean_free_path_mm", "tet_size_mm", "outcome", "iterations",
                     "rel_error_vs_refined"};
    const int lateral = size.quick ? 6 : 12;
    const std::vector<int> thicknesses = size.quick ? std::vector<int>{1, 2} : std::vector<int>{1, 2, 4};
    for (int k : thicknesses)
        for (double musp : {10.0, 1.0, 0.1}) {
            const Eigen::Vector3d hi(lateral, lateral, k);  // 1 mm cells
            const TetMaterial material{{0.01, 0.01, 0.01}, {musp, musp, musp}, 1.3};
            // Light on the top face only: the light has to cross the slab.
            auto top_light = [](const TetMesh& mesh, const TetConnectivity& connectivity, double top) {
                std::vector<std::array<double, 3>> q(mesh.vertex_count(), {0, 0, 0});
                for (int32_t v : connectivity.boundary_vertices)
                    if (mesh.positions[v].z() > top - 1e-9) q[v] = {1, 1, 1};
                return q;
            };
            const std::array<int, 3> coarse_cells{lateral, lateral, k};
            const TetMesh coarse = make_box_mesh(coarse_cells, Eigen::Vector3d::Zero(), hi);
            const TetConnectivity coarse_connectivity = build_connectivity(coarse);
            const std::vector<TetMaterial> coarse_materials(coarse.tet_count(), material);
            const PathOutcome path = run_solver(coarse, coarse_connectivity, coarse_materials,
                                                top_light(coarse, coarse_connectivity, k), SolverPrecision::Double,
                                                StiffnessForm::Gradient, 1e-8);

            const std::array<int, 3> fine_cells{2 * lateral, 2 * lateral, 2 * k};
            const TetMesh fine = make_box_mesh(fine_cells, Eigen::Vector3d::Zero(), hi);
            const TetConnectivity fine_connectivity = build_connectivity(fine);
            const std::vector<TetMaterial> fine_materials(fine.tet_count(), material);
            const std::vector<double> fine_phi =
                direct_solution(fine, fine_connectivity, fine_materials, top_light(fine, fine_connectivity, k));
            std::vector<double> reference(coarse.vertex_count());
            for (int z = 0; z <= k; ++z)
                for (int y = 0; y <= lateral; ++y)
                    for (int x = 0; x <= lateral; ++x)
                        reference[box_vertex_index(coarse_cells, x, y, z)] =
                            fine_phi[box_vertex_index(fine_cells, 2 * x, 2 * y, 2 * z)];
            const double error = path.phi.empty() ? NAN : relative_error(path.phi, reference);
            table.rows.push_back({k, 1.0 / musp, 1.0, path.outcome, path.iterations, number(error)});
        }
    return table;
}

StudyTable study_kappa_contrast(const StudySize& size) {
    StudyTable table;
    table.name = "kappa contrast between neighbouring tets";
    table.what_fails =
        "painting a strongly scattering material next to a weakly scattering one makes neighbouring rows "
        "differ by the kappa ratio; Jacobi scaling removes the row scale but not the coupling";
    table.how_it_shows =
        "more iterations; the error estimate (from the Lanczos smallest Ritz value) must still bound the "
        "true error or the solver would stop early";
    table.what_waxwork_does =
        "Jacobi preconditioning plus the error-based stopping rule; the table checks the estimate against "
        "the true error at each contrast";
    table.columns = {"kappa_ratio", "precision", "outcome", "iterations", "estimated_error", "true_error",
                     "estimate_bounds_true"};
    const int n = size.quick ? 8 : 12;
    const TetMesh mesh = make_box_mesh({n, n, n}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(n));
    const TetConnectivity connectivity = build_connectivity(mesh);
    const auto q = boundary_light(mesh, connectivity, everywhere);
    for (double musp_ratio : {1.0, 10.0, 100.0, 1000.0}) {
        std::vector<TetMaterial> materials(mesh.tet_count(), kPlainMaterial);
        for (size_t t = 0; t < mesh.tet_count(); ++t) {
            double x = 0;
            for (int32_t v : mesh.tets[t]) x += mesh.positions[v].x() / 4;
            if (x > n / 2.0) materials[t].musp = {musp_ratio, musp_ratio, musp_ratio};
        }
        const double ratio = diffusion_coefficient(0.01, 1.0) / diffusion_coefficient(0.01, musp_ratio);
        const std::vector<double> reference = direct_solution(mesh, connectivity, materials, q);
        for (SolverPrecision precision : kPrecisions) {
            const PathOutcome path =
                run_solver(mesh, connectivity, materials, q, precision, StiffnessForm::Gradient, 1e-3);
            const double error = path.phi.empty() ? NAN : relative_error(path.phi, reference);
            table.rows.push_back({ratio, precision_name(precision), path.outcome, path.iterations,
                                  number(path.estimated_error), number(error),
                                  std::isfinite(error) ? Json(error <= path.estimated_error) : Json(nullptr)});
        }
    }
    return table;
}

StudyTable study_coarse_breakdown(const StudySize& size) {
    StudyTable table;
    table.name = "coarse levels near breakdown";
    table.what_fails =
        "the paper's coarse matrices (Eq. 17) are not symmetric and may be singular; BiCGSTAB on them can "
        "break down (rho or omega -> 0), stagnate or diverge";
    table.how_it_shows = "a coarse level's iterate is useless or non-finite";
    table.what_waxwork_does =
        "BiCGSTAB detects breakdown, stagnation, growth and non-finite values; the level is skipped (its "
        "start vector passed on unchanged) and the reason recorded; the level-0 CG guarantees the accuracy";
    table.columns = {"fault", "levels", "fallbacks", "reasons", "fine_iterations", "rel_error", "finite"};
    const int n = size.quick ? 10 : 14;
    const TetMesh mesh = make_box_mesh({n, n, n}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(n));
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<TetMaterial> materials(mesh.tet_count(), kPlainMaterial);
    const auto q = boundary_light(mesh, connectivity, everywhere);
    const DiffusionMatrix matrix = assemble_diffusion_matrix(mesh, connectivity, materials);
    std::vector<double> b(matrix.size());
    diffusion_right_hand_side(matrix, q, 0, b);
    const std::vector<double> reference = direct_solution(mesh, connectivity, materials, q);

    HierarchyOptions hierarchy_options;
    hierarchy_options.min_coarse_vertices = 100;
    const MultiresSolver pristine(matrix, mesh.positions, hierarchy_options);
    using Fault = void (*)(MultiresHierarchy&);
    const std::pair<const char*, Fault> faults[] = {
        {"none", [](MultiresHierarchy&) {}},
        {"coarsest level zero (singular)",
         [](MultiresHierarchy& h) { std::fill(h.levels.back().values[0].begin(), h.levels.back().values[0].end(), 0.0); }},
        {"level 1 negated (indefinite)",
         [](MultiresHierarchy& h) {
             for (double& v : h.levels[1].values[0]) v = -v;
         }},
        {"level 1 row zero", [](MultiresHierarchy& h) {
             HierarchyLevel& level = h.levels[1];
             const size_t row = level.size() / 2;
             for (int32_t k = level.offsets[row]; k < level.offsets[row + 1]; ++k) level.values[0][k] = 0;
         }},
        {"level 1 NaN entry", [](MultiresHierarchy& h) { h.levels[1].values[0][0] = std::nan(""); }},
    };
    for (const auto& [name, fault] : faults) {
        MultiresSolver solver = pristine;
        if (solver.hierarchy().level_count() < 2) break;
        fault(solver.hierarchy());
        MultiresSolveOptions options;
        options.relative_tolerance = 1e-6;
        std::vector<double> x(matrix.size());
        std::string reasons;
        MultiresSolveReport report;
        try {
            report = solver.solve(b, 0, x, options);
        } catch (const AlgorithmError& e) {
            reasons = std::string("error: ") + e.what();
        }
        if (reasons.empty()) reasons = report.fallback_reasons();
        const bool finite = std::all_of(x.begin(), x.end(), [](double v) { return std::isfinite(v); });
        double error = 0, norm = 0;
        for (size_t v = 0; v < x.size(); ++v) {
            error += (x[v] - reference[v]) * (x[v] - reference[v]);
            norm += reference[v] * reference[v];
        }
        table.rows.push_back({name, solver.hierarchy().level_count(), report.fallbacks(),
                              reasons.empty() ? "-" : reasons, report.fine.iterations,
                              number(finite ? std::sqrt(error / norm) : NAN), finite});
    }
    return table;
}

StudyTable study_multigrid_slivers(const StudySize& size) {
    StudyTable table;
    table.name = "slivers, multigrid";
    table.what_fails =
        "the multigrid V-cycle's coarse operators drop small Galerkin entries and add them to the diagonal "
        "with their signs (row-sum lumping); on slivers Eq. 10's weights include large positive "
        "off-diagonals, and the lumped coarse operators can lose positive definiteness";
    table.how_it_shows = "the setup finds a non-positive diagonal or cannot factorise the coarsest level";
    table.what_waxwork_does =
        "the setup is redone with absolute lumping (positive definite by construction), and MG-CG converges; "
        "should a V-cycle still fail, the live editor solves with Jacobi CG and says why";
    table.columns = {"cells", "flatness", "min_dihedral_deg", "row_sum_setup", "lumping", "outcome", "iterations",
                     "rel_error"};
    const std::vector<int> cells = size.quick ? std::vector<int>{10} : std::vector<int>{10, 16};
    const std::vector<double> flatness = size.quick ? std::vector<double>{1e-3, 1e-5}
                                                    : std::vector<double>{1e-2, 1e-3, 1e-4, 1e-5};
    const TetMaterial marble = material_preset("marble");  // the material the failure was found with
    for (const int n : cells)
        for (const double f : flatness) {
            const TetMesh mesh = sliver_box(n, f);
            const TetConnectivity connectivity = build_connectivity(mesh);
            const std::vector<TetMaterial> materials(mesh.tet_count(), marble);
            const DiffusionMatrix matrix = assemble_diffusion_matrix(mesh, connectivity, materials);
            const auto q = boundary_light(mesh, connectivity, everywhere);
            std::vector<double> b(matrix.size());
            diffusion_right_hand_side(matrix, q, 0, b);
            const DirectSolver direct(to_eigen_sparse(matrix, 0));
            const Eigen::VectorXd exact =
                direct.solve(Eigen::Map<const Eigen::VectorXd>(b.data(), static_cast<Eigen::Index>(b.size())));
            const MultiresHierarchy hierarchy = build_multires_hierarchy(matrix, mesh.positions);
            std::string row_sum_setup = "ok";
            try {
                MultigridOptions strict;
                strict.fall_back_to_absolute = false;
                const MultigridPreconditioner probe(hierarchy, strict);
            } catch (const AlgorithmError& e) {
                row_sum_setup = std::string("error: ") + e.what();
            }
            std::string lumping = "-", outcome;
            int iterations = 0;
            double error = NAN;
            try {
                MultigridPreconditioner mg(hierarchy);
                lumping = mg.lumping() == DropLumping::RowSum ? "row-sum" : "absolute";
                std::vector<double> x(b.size(), 0.0);
                ConjugateGradientOptions cg;
                cg.relative_tolerance = 1e-6;
                cg.max_iterations = 2000;
                const ConjugateGradientResult result = solve_multigrid_cg(mg, 0, b, x, cg);
                outcome = result.converged ? "converged" : "not converged in 2000";
                iterations = result.iterations;
                error = (Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size())) - exact).norm() /
                        exact.norm();
            } catch (const AlgorithmError& e) {
                outcome = std::string("error: ") + e.what();
            }
            table.rows.push_back(
                {n, f, mesh_min_dihedral(mesh), row_sum_setup, lumping, outcome, iterations, number(error)});
        }
    return table;
}

std::vector<StudyTable> run_stability_studies(const StudySize& size) {
    return {study_slivers(size),        study_relaxation_guard(size), study_material_extremes(size),
            study_thin_parts(size),     study_kappa_contrast(size),   study_coarse_breakdown(size),
            study_multigrid_slivers(size)};
}

}  // namespace waxwork
