#include "bench/studies/method_failures.h"

#include "base/error.h"
#include "solver/diffusion_solve.h"
#include "solver/material.h"
#include "solver/methods/dipole.h"
#include "solver/methods/fvm.h"
#include "solver/reference/analytic_ball.h"
#include "tetops/box_mesh.h"
#include "tetops/connectivity.h"
#include "tetops/icosphere.h"
#include "tetops/sliver_maker.h"
#include "tetops/tetrahedralize.h"

#include <cstdio>
#include <string>

namespace waxwork {
namespace {

constexpr double kBallRadius = 10.0;  // mm, one model unit per mm
const TetMaterial kBallMaterial{{0.01, 0.01, 0.01}, {1.0, 1.0, 1.0}, 1.3};

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
        MeshingOptions meshing;
        meshing.sizing.target_tets = size.quick ? 6000 : 16000;
        TetMesh mesh = tetrahedralize(make_icosphere(3, kBallRadius), meshing).mesh;
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
