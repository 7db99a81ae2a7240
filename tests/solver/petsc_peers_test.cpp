// The PETSc peers (solver/petsc_peers.h): CG with GAMG and with hypre BoomerAMG solve lit diffusion
// systems to their tolerance and agree with the direct solution and Waxwork's own CG; an iteration cap
// is exact; a rebuild on the same values gives the same solver; bad input throws typed errors. In a
// build without PETSc the tests are skipped with the reason.
#include "solver/petsc_peers.h"

#include <gtest/gtest.h>

#ifdef WAXWORK_HAVE_PETSC

#include "base/error.h"
#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "solver/reference/reference_solvers.h"
#include "lit_block_system.h"
#include "solver_test_meshes.h"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace waxwork {
namespace {

constexpr std::array<PetscPeer, 2> kPeers = {PetscPeer::CgGamg, PetscPeer::CgBoomerAmg};

// A lit system with the right-hand side of all three channels.
struct RgbSystem {
    test::LitBlockSystem system;
    std::array<std::vector<double>, 3> b;

    explicit RgbSystem(TetMesh mesh) : system(std::move(mesh)) {
        const double top = bounding_box(system.mesh)[1].z();
        std::vector<std::array<double, 3>> q(system.mesh.vertex_count(), {0, 0, 0});
        for (size_t v = 0; v < system.mesh.vertex_count(); ++v)
            if (system.mesh.positions[v].z() > top - 1e-9) q[v] = {1.0, 0.6, 0.3};
        for (int c = 0; c < 3; ++c) {
            b[static_cast<size_t>(c)].resize(system.mesh.vertex_count());
            diffusion_right_hand_side(system.matrix, q, c, b[static_cast<size_t>(c)]);
        }
    }
    Eigen::VectorXd direct(int c) const {
        const std::vector<double>& bc = b[static_cast<size_t>(c)];
        return DirectSolver(to_eigen_sparse(system.matrix, c))
            .solve(Eigen::Map<const Eigen::VectorXd>(bc.data(), static_cast<Eigen::Index>(bc.size())));
    }
};

double relative_difference(const std::vector<double>& x, const Eigen::VectorXd& reference) {
    const Eigen::Map<const Eigen::VectorXd> v(x.data(), static_cast<Eigen::Index>(x.size()));
    return (v - reference).norm() / reference.norm();
}

void expect_peers_solve(const RgbSystem& s, const char* mesh_name) {
    const DiffusionMatrix& matrix = s.system.matrix;
    for (const PetscPeer peer : kPeers) {
        PetscPeerSolver solver(matrix, peer);
        EXPECT_EQ(solver.size(), matrix.size());
        EXPECT_GT(solver.setup_times().conversion_ms, 0.0);
        EXPECT_GT(solver.setup_times().preconditioner_ms, 0.0);
        for (int c = 0; c < 3; ++c) {
            const auto sc = static_cast<size_t>(c);
            std::vector<double> x(matrix.size(), -1.0);  // overwritten: the solve starts from zero
            PetscSolveOptions options;
            options.relative_tolerance = 1e-10;
            const PetscSolveReport report = solver.solve(c, s.b[sc], x, options);
            EXPECT_TRUE(report.converged) << petsc_peer_name(peer) << " " << mesh_name << " channel " << c << ": "
                                          << report.reason;
            EXPECT_EQ(report.reason, "CONVERGED_RTOL");
            // An AMG-preconditioned CG needs tens of iterations at most here (Jacobi CG needs hundreds).
            EXPECT_GT(report.iterations, 0);
            EXPECT_LT(report.iterations, 60) << petsc_peer_name(peer) << " " << mesh_name;
            const double b_norm = Eigen::Map<const Eigen::VectorXd>(s.b[sc].data(), static_cast<Eigen::Index>(matrix.size())).norm();
            EXPECT_LE(report.residual_norm, 1e-10 * b_norm);
            const Eigen::VectorXd direct = s.direct(c);
            EXPECT_LT(relative_difference(x, direct), 1e-7) << petsc_peer_name(peer) << " " << mesh_name << " channel " << c;

            // Waxwork's own Jacobi CG to 1e-8 lands on the same solution.
            std::vector<double> own(matrix.size(), 0.0);
            ConjugateGradientOptions cg;
            cg.relative_tolerance = 1e-8;
            const CsrMatrixView<double> view{matrix.size(), matrix.offsets.data(), matrix.columns.data(),
                                             matrix.values[sc].data()};
            ASSERT_TRUE(solve_jacobi_cg<double>(view, s.b[sc], own, cg).converged);
            const Eigen::Map<const Eigen::VectorXd> own_v(own.data(), static_cast<Eigen::Index>(own.size()));
            EXPECT_LT(relative_difference(x, own_v), 1e-6) << petsc_peer_name(peer) << " " << mesh_name;
        }
    }
}

TEST(PetscPeers, SolveABoxToTheToleranceAndAgreeWithDirectAndCg) {
    const RgbSystem s(test::make_cube_mesh(8, 2.0));
    expect_peers_solve(s, "box");
}

TEST(PetscPeers, SolveABallToTheToleranceAndAgreeWithDirectAndCg) {
    const RgbSystem s(test::make_ball_mesh(2, 4000, 10.0));
    expect_peers_solve(s, "ball");
}

// With tolerance 0 a cap runs exactly that many iterations (the comparison's curves rely on it), cap 0
// is the zero start, and the error falls with the cap.
TEST(PetscPeers, IterationCapIsExact) {
    const RgbSystem s(test::make_cube_mesh(6, 2.0));
    const Eigen::VectorXd direct = s.direct(1);
    for (const PetscPeer peer : kPeers) {
        const PetscPeerSolver solver(s.system.matrix, peer);
        PetscSolveOptions options;
        options.relative_tolerance = 0;
        std::vector<double> x(s.system.matrix.size(), 1.0);
        options.max_iterations = 0;
        PetscSolveReport report = solver.solve(1, s.b[1], x, options);
        EXPECT_EQ(report.iterations, 0);
        EXPECT_FALSE(report.converged);
        for (const double v : x) ASSERT_EQ(v, 0.0);
        double previous = std::numeric_limits<double>::infinity();
        for (const int cap : {1, 3, 6}) {
            options.max_iterations = cap;
            report = solver.solve(1, s.b[1], x, options);
            EXPECT_EQ(report.iterations, cap) << petsc_peer_name(peer);
            EXPECT_FALSE(report.converged);
            EXPECT_EQ(report.reason, "DIVERGED_ITS");
            const double error = relative_difference(x, direct);
            EXPECT_LT(error, previous) << petsc_peer_name(peer) << " cap " << cap;
            previous = error;
        }
    }
}

// A rebuild on the same values sets the preconditioner up again and solves exactly as before.
TEST(PetscPeers, RebuildOnTheSameValuesSolvesTheSame) {
    const RgbSystem s(test::make_cube_mesh(6, 2.0));
    for (const PetscPeer peer : kPeers) {
        PetscPeerSolver solver(s.system.matrix, peer);
        PetscSolveOptions options;
        options.relative_tolerance = 1e-9;
        std::vector<double> before(s.system.matrix.size()), after(s.system.matrix.size());
        const int iterations = solver.solve(2, s.b[2], before, options).iterations;
        solver.rebuild(s.system.matrix);
        EXPECT_GT(solver.setup_times().preconditioner_ms, 0.0);
        EXPECT_EQ(solver.solve(2, s.b[2], after, options).iterations, iterations) << petsc_peer_name(peer);
        for (size_t i = 0; i < before.size(); ++i) ASSERT_NEAR(after[i], before[i], 1e-12 * std::abs(before[i]) + 1e-300);
    }
}

TEST(PetscPeers, BadInputThrowsTypedErrors) {
    const RgbSystem s(test::make_cube_mesh(3, 2.0));
    const DiffusionMatrix& matrix = s.system.matrix;
    EXPECT_THROW(PetscPeerSolver(DiffusionMatrix{}, PetscPeer::CgGamg), InvalidArgumentError);
    DiffusionMatrix broken = matrix;
    broken.values[1][3] = std::nan("");
    EXPECT_THROW(PetscPeerSolver(broken, PetscPeer::CgBoomerAmg), InvalidArgumentError);
    broken = matrix;
    broken.columns[0] = static_cast<int32_t>(matrix.size());
    EXPECT_THROW(PetscPeerSolver(broken, PetscPeer::CgGamg), InvalidArgumentError);
    broken = matrix;
    broken.values[2].pop_back();
    EXPECT_THROW(PetscPeerSolver(broken, PetscPeer::CgGamg), InvalidArgumentError);

    PetscPeerSolver solver(matrix, PetscPeer::CgBoomerAmg);
    std::vector<double> x(matrix.size());
    const PetscSolveOptions ok;
    EXPECT_THROW(solver.solve(3, s.b[0], x, ok), InvalidArgumentError);
    EXPECT_THROW(solver.solve(-1, s.b[0], x, ok), InvalidArgumentError);
    std::vector<double> short_b(matrix.size() - 1, 1.0);
    EXPECT_THROW(solver.solve(0, short_b, x, ok), InvalidArgumentError);
    std::vector<double> nan_b = s.b[0];
    nan_b[0] = std::nan("");
    EXPECT_THROW(solver.solve(0, nan_b, x, ok), InvalidArgumentError);
    PetscSolveOptions bad = ok;
    bad.max_iterations = -1;
    EXPECT_THROW(solver.solve(0, s.b[0], x, bad), InvalidArgumentError);
    bad = ok;
    bad.relative_tolerance = 1.5;
    EXPECT_THROW(solver.solve(0, s.b[0], x, bad), InvalidArgumentError);
    // A rebuild needs the pattern it was built on.
    const RgbSystem other(test::make_cube_mesh(4, 2.0));
    EXPECT_THROW(solver.rebuild(other.system.matrix), InvalidArgumentError);
    // The solver still works after the rejected calls.
    EXPECT_TRUE(solver.solve(0, s.b[0], x, ok).converged);
}

TEST(PetscPeers, SettingsAreRecorded) {
    EXPECT_STREQ(petsc_peer_name(PetscPeer::CgGamg), "petsc_cg_gamg");
    EXPECT_STREQ(petsc_peer_name(PetscPeer::CgBoomerAmg), "petsc_cg_boomeramg");
    const auto hypre = petsc_peer_settings(PetscPeer::CgBoomerAmg);
    auto value = [&](const std::string& key) {
        for (const auto& [k, v] : hypre)
            if (k == key) return v;
        return std::string("(unset)");
    };
    EXPECT_EQ(value("pc_hypre_boomeramg_coarsen_type"), "HMIS");
    EXPECT_EQ(value("pc_hypre_boomeramg_interp_type"), "ext+i");
    EXPECT_EQ(value("pc_hypre_boomeramg_strong_threshold"), "0.25");
    EXPECT_EQ(value("pc_hypre_boomeramg_agg_nl"), "1");
    EXPECT_EQ(value("pc_hypre_boomeramg_relax_type_down"), "l1-Gauss-Seidel");
    EXPECT_EQ(petsc_version().rfind("PETSc 3.", 0), 0u);
    EXPECT_TRUE(petsc_unavailable_reason().empty());
}

}  // namespace
}  // namespace waxwork

#else

TEST(PetscPeers, NotBuilt) {
    EXPECT_FALSE(waxwork::petsc_unavailable_reason().empty());
    GTEST_SKIP() << "PETSc peers not built: " << waxwork::petsc_unavailable_reason();
}

#endif
