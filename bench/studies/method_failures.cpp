#include "bench/studies/method_failures.h"

#include "bench/studies/accuracy_study.h"

#include "base/error.h"
#include "solver/diffusion_solve.h"
#include "solver/material.h"
#include "solver/methods/dipole.h"
#include "solver/methods/fd.h"
#include "solver/methods/fvm.h"
#include "solver/methods/lbm.h"
#include "solver/reference/analytic_ball.h"
#include "tetops/box_mesh.h"
#include "tetops/connectivity.h"
#include "tetops/fracture.h"
#include "tetops/sliver_maker.h"

#include <cmath>
#include <cstdio>
#include <span>
#include <string>

namespace waxwork {
namespace {

constexpr double kBallRadius = kStudyBallRadiusMm;
const TetMaterial& kBallMaterial = kStudyBallMaterial;

std::string percent(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g%%", 100 * value);
    return text;
}

}  // namespace

StudyTable study_fvm_non_delaunay(const StudySize& size) {
    StudyTable table;
    table.name = "fvm on a non-Delaunay mesh";
    table.what_fails =
        "the circumcentric Voronoi dual of a tet mesh that is not Delaunay has negative face areas (dual "
        "coefficients) and cells of negative volume, so the finite-volume matrix of Kang & Kim is no longer an "
        "M-matrix";
    table.how_it_shows =
        "kept as they are, Jacobi relaxation diverges and CG meets a non-positive direction; clamped, both "
        "converge but the operator is wrong on those edges and the error grows as the slivers flatten";
    table.what_waxwork_does =
        "negative coefficients and cell volumes are clamped to zero and every solve warns with their count and "
        "fraction (a normal TetGen mesh has a few: the ball 6 of 22,235); TransCut's cotangent weights on the "
        "same mesh are unaffected by the Delaunay property";
    table.columns = {"sliver_height", "moved_vertices", "non_delaunay_faces", "negative_coefficients",
                     "kept_relaxation", "kept_cg", "clamped_error", "transcut_error"};
    const std::vector<double> heights = size.quick ? std::vector<double>{1.0, 0.1} : std::vector<double>{1.0, 0.1, 1e-2, 1e-3};
    for (double height : heights) {
        TetMesh mesh = study_ball_mesh(3, size.quick ? 6000 : 16000);
        size_t moved = 0;
        if (height < 1) moved = flatten_into_slivers(mesh, build_connectivity(mesh), 60, height).size();
        const TetConnectivity connectivity = build_connectivity(mesh);
        const std::vector<TetMaterial> materials(mesh.tet_count(), kBallMaterial);
        const std::vector<std::array<double, 3>> q =
            ball_light(mesh, connectivity, BallLight::Directional, kBallMaterial.eta);
        const MethodProblem problem{mesh, connectivity, materials, q, 1.0};
        const FvmDualStatistics statistics = assemble_fvm_system(problem, NegativeDualCoefficients::Keep).statistics;
        auto error_of = [&](const MethodSolution& solution) {
            return ball_relative_error(mesh, connectivity, kBallMaterial, kBallRadius, BallLight::Directional, 1.0,
                                       solution.phi);
        };
        auto kept = [&](FvmSolver solver) -> std::string {
            FvmOptions options;
            options.solver = solver;
            options.negative_coefficients = NegativeDualCoefficients::Keep;
            try {
                return percent(error_of(solve_fvm(problem, options)));
            } catch (const AlgorithmError& e) {
                return std::string("fails: ") + e.what();
            }
        };
        FvmOptions clamped;
        clamped.solver = FvmSolver::Cg;
        DiffusionOptions transcut;
        transcut.relative_tolerance = 1e-7;
        const double transcut_error =
            compare_with_analytic_ball(mesh, connectivity, kBallMaterial, kBallRadius, BallLight::Directional, transcut)
                .relative_error;
        table.rows.push_back({height, moved,
                              std::to_string(statistics.non_delaunay_faces) + " of " +
                                  std::to_string(statistics.interior_faces),
                              std::to_string(statistics.negative_edges) + " of " + std::to_string(statistics.edges),
                              kept(FvmSolver::Relaxation), kept(FvmSolver::Cg), percent(error_of(solve_fvm(problem, clamped))),
                              percent(transcut_error)});
    }
    return table;
}

StudyTable study_fd_cuts(const StudySize& size) {
    StudyTable table;
    table.name = "fd on cut and thin volumes";
    table.what_fails =
        "QuadGraph's finite differences live on a graph precomputed from the volume, which a cut cannot update; "
        "Waxwork's grid is rebuilt from the volume at every solve, and a link between two cells counts only if "
        "it crosses no boundary face, so cuts and cracks narrower than a cell separate the light as they should; "
        "what a grid still cannot see is a part thinner than a cell, which has no cell centre inside it";
    table.how_it_shows =
        "phi against TransCut on the same volume (relative L2 over every vertex): a ball broken along a plane, "
        "lit everywhere (crack faces included), and a 4 mm block beside a 0.15 mm plate, at cell sizes above and "
        "below the plate's thickness";
    table.what_waxwork_does =
        "fractured and cut volumes solve without a warning; vertices of parts without a cell keep phi = 0 and "
        "the solve warns with their count; a volume with no cell at all is an error";
    table.columns = {"case", "cell_mm", "cells", "outcome", "relative_error_vs_transcut", "warnings"};
    auto run = [&](const std::string& what, const TetMesh& mesh, double cell_mm) {
        const TetConnectivity connectivity = build_connectivity(mesh);
        const std::vector<TetMaterial> materials(mesh.tet_count(), kBallMaterial);
        std::vector<std::array<double, 3>> q(mesh.vertex_count(), {0, 0, 0});
        for (int32_t v : connectivity.boundary_vertices) q[v] = {1, 1, 1};
        std::vector<nlohmann::json> row = {what, cell_mm};
        try {
            FdOptions options;
            options.cell_size_mm = cell_mm;
            const MethodSolution solution = solve_fd({mesh, connectivity, materials, q, 1.0}, options);
            DiffusionOptions transcut;
            transcut.relative_tolerance = 1e-8;
            const DiffusionSolution reference = solve_diffusion(mesh, connectivity, materials, q, transcut);
            double error = 0, norm = 0;
            for (size_t v = 0; v < mesh.vertex_count(); ++v) {
                error += std::pow(solution.phi[v][0] - reference.phi[v][0], 2);
                norm += std::pow(reference.phi[v][0], 2);
            }
            std::string warnings;
            for (const std::string& w : solution.warnings) warnings += (warnings.empty() ? "" : "; ") + w;
            row.insert(row.end(), {solution.unknowns, "solved", percent(std::sqrt(error / norm)), warnings});
        } catch (const Error& e) {
            row.insert(row.end(), {0, std::string("error: ") + e.what(), "-", ""});
        }
        table.rows.push_back(row);
    };
    TetMesh broken = study_ball_mesh(3, size.quick ? 3000 : 8000);
    run("ball (R = 10 mm), whole", broken, 0.5);
    const Eigen::Vector4d plane(0, 0, 1, 0.3);
    fracture_planes(broken, std::span<const Eigen::Vector4d>(&plane, 1));
    run("ball broken along z = 0.3 mm", broken, 0.5);
    const TetMesh block_and_plate =
        join_meshes(make_box_mesh({4, 4, 4}, Eigen::Vector3d::Zero(), Eigen::Vector3d(4, 4, 4)),
               make_box_mesh({4, 4, 1}, Eigen::Vector3d(0, 0, 4.3), Eigen::Vector3d(4, 4, 4.45)));
    for (double cell : size.quick ? std::vector<double>{0.5, 0.1} : std::vector<double>{1.0, 0.5, 0.25, 0.1})
        run("4 mm block and a 0.15 mm plate", block_and_plate, cell);
    run("a 1 mm tet alone", make_tet_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 1, 2, 3}}), 2.0);
    return table;
}

StudyTable study_lbm_relaxation(const StudySize& size) {
    StudyTable table;
    table.name = "lbm outside its stable range";
    table.what_fails =
        "lattice-Boltzmann diffusion (Bernabei et al.) relaxes with time tau: the diffusion coefficient "
        "c_s^2 (tau - 1/2) dx^2 / dt needs tau > 1/2, tau near 1/2 makes populations negative while iterating, "
        "large tau trades accuracy for speed, and the paper's explicit absorption mu_a dt per step turns "
        "populations negative above 1 - 1/tau and diverges above 2 - 1/tau";
    table.how_it_shows =
        "the ball (R = 10 mm, 1 mm cells, directional light) against the analytic solution, and a strongly "
        "absorbing ball (mu_a 0.5, mu_s' 1 per mm) with the paper's explicit absorption";
    table.what_waxwork_does =
        "tau <= 1/2 and explicit absorption beyond 2 - 1/tau are errors; tau under 1 or above 2, cells "
        "coarser than the diffusion length and explicit absorption beyond 1 - 1/tau are warnings; by default "
        "tau = 1 for the most diffusive material (dt chosen from it) and absorption is implicit, positive at "
        "any mu_a dt";
    table.columns = {"case", "steps", "outcome", "error_vs_analytic", "warnings"};
    const TetMesh mesh = study_ball_mesh(3, size.quick ? 3000 : 8000);
    const TetConnectivity connectivity = build_connectivity(mesh);
    auto run = [&](const std::string& what, const TetMaterial& material, const LbmOptions& options, bool exact) {
        const std::vector<TetMaterial> materials(mesh.tet_count(), material);
        const std::vector<std::array<double, 3>> q = ball_light(mesh, connectivity, BallLight::Directional, material.eta);
        std::vector<nlohmann::json> row = {what};
        try {
            const MethodSolution solution = solve_lbm({mesh, connectivity, materials, q, 1.0}, options);
            std::string warnings;
            for (const std::string& w : solution.warnings) warnings += (warnings.empty() ? "" : "; ") + w;
            row.insert(row.end(), {solution.iterations[0], "converged",
                                   exact ? nlohmann::json(percent(ball_relative_error(mesh, connectivity, material,
                                                                                      kBallRadius, BallLight::Directional,
                                                                                      1.0, solution.phi)))
                                         : nlohmann::json("-"),
                                   warnings});
        } catch (const Error& e) {
            row.insert(row.end(), {0, std::string("error: ") + e.what(), "-", ""});
        }
        table.rows.push_back(row);
    };
    const std::vector<double> taus = size.quick ? std::vector<double>{0.45, 0.6, 1.0, 4.0}
                                                : std::vector<double>{0.45, 0.55, 0.7, 1.0, 2.0, 4.0, 8.0};
    for (double tau : taus) {
        LbmOptions options;
        options.cell_size_mm = 1.0;
        options.tau = tau;
        char what[48];
        std::snprintf(what, sizeof what, "tau %.3g", tau);
        run(what, kBallMaterial, options, true);
    }
    // sigma_tr dx = 1.5 at 1 mm cells: the explicit absorption per step a = mu_a dt.
    const TetMaterial absorbing{{0.5, 0.5, 0.5}, {1.0, 1.0, 1.0}, 1.3};
    for (const auto& [tau, explicit_absorption] : std::vector<std::pair<double, bool>>{{1.0, true}, {1.0, false}, {0.6, true}}) {
        LbmOptions options;
        options.cell_size_mm = 1.0;
        options.tau = tau;
        options.explicit_absorption = explicit_absorption;
        char what[96];
        std::snprintf(what, sizeof what, "mu_a 0.5, tau %.3g, %s absorption", tau, explicit_absorption ? "explicit" : "implicit");
        run(what, absorbing, options, true);
    }
    return table;
}

StudyTable study_dipole_thin_parts(const StudySize& size) {
    StudyTable table;
    table.name = "dipole on thin parts";
    table.what_fails =
        "the dipole profile (Jensen et al.; Maisch & Ropinski's surface method) assumes a semi-infinite medium "
        "behind every surface point, so light that crosses a part thinner than a few diffusion lengths is "
        "taken for light scattered back along the surface";
    table.how_it_shows =
        "the unlit side of a slab lit from one side is far too dark (phi at the centre of the unlit face, "
        "against TransCut on the same mesh); the error grows as the slab thins";
    table.what_waxwork_does =
        "a warning names the share of the surface closer than 3 diffusion lengths to a back side (the "
        "thickness measured to each vertex's nearest back-side vertex) and points to --method transcut; the "
        "light is not corrected (the paper's remedy, a thickness-dependent multipole, is not built)";
    table.columns = {"thickness_mm", "diffusion_lengths", "unlit_dipole_over_transcut", "unlit_error_of_lit_side",
                     "thin_surface_share", "warning"};
    const TetMaterial material{{0.01, 0.01, 0.01}, {1.0, 1.0, 1.0}, 1.3};
    const std::vector<int> thicknesses = size.quick ? std::vector<int>{8, 2} : std::vector<int>{16, 8, 4, 2};
    for (int thickness : thicknesses) {
        const std::array<int, 3> cells{30, 30, thickness};
        const TetMesh mesh = make_box_mesh(cells, Eigen::Vector3d::Zero(), Eigen::Vector3d(30, 30, thickness));
        const TetConnectivity connectivity = build_connectivity(mesh);
        const std::vector<TetMaterial> materials(mesh.tet_count(), material);
        std::vector<std::array<double, 3>> q(mesh.vertex_count(), {0, 0, 0});
        for (int32_t v : connectivity.boundary_vertices)
            if (mesh.positions[v].z() > thickness - 1e-9) q[v] = {1, 1, 1};
        DipoleDiagnostics diagnostics;
        const MethodSolution dipole = solve_dipole({mesh, connectivity, materials, q, 1.0}, {}, &diagnostics);
        DiffusionOptions options;
        options.relative_tolerance = 1e-6;
        const DiffusionSolution transcut = solve_diffusion(mesh, connectivity, materials, q, options);
        const int32_t unlit = box_vertex_index(cells, 15, 15, 0), lit = box_vertex_index(cells, 15, 15, thickness);
        table.rows.push_back(
            {thickness, thickness * effective_transport_coefficient(material.mua[0], material.musp[0]),
             dipole.phi[unlit][0] / transcut.phi[unlit][0],
             percent((dipole.phi[unlit][0] - transcut.phi[unlit][0]) / transcut.phi[lit][0]),
             percent(diagnostics.thin_area_fraction), dipole.warnings.empty() ? "" : dipole.warnings.front()});
    }
    return table;
}

std::vector<StudyTable> run_method_failure_studies(const StudySize& size) {
    return {study_fvm_non_delaunay(size), study_fd_cuts(size), study_lbm_relaxation(size),
            study_dipole_thin_parts(size)};
}

}  // namespace waxwork
