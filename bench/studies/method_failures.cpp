#include "bench/studies/method_failures.h"

#include "base/error.h"
#include "solver/methods/fvm.h"
#include "solver/reference/analytic_ball.h"
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

std::vector<StudyTable> run_method_failure_studies(const StudySize& size) {
    return {study_fvm_non_delaunay(size), study_fd_cuts(size), study_lbm_relaxation(size),
            study_dipole_thin_parts(size)};
}

}  // namespace waxwork
