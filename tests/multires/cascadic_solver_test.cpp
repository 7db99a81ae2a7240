#include "base/error.h"
#include "multires/cascadic_solver.h"
#include "multires/multires_solver.h"
#include "solver/reference/reference_solvers.h"
#include "multires_test_systems.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace waxwork {
namespace {

using testing::reference_solution;
using testing::relative_error;
using testing::small_levels;
using testing::all_finite;
using testing::dense;

// With two levels and exact Galerkin products the pass's start is P y with P^T A P y = P^T b: the
// element of range(P) closest to the solution in the energy norm, so its error is A-orthogonal to
// range(P). Computed densely here and compared; the Eq. 17 start (the paper's pass with its coarsest
// level solved to 1e-12) is not orthogonal, and is further from the solution in the energy norm.
TEST(CascadicSolver, TwoLevelStartIsTheEnergyProjectionOfTheSolution) {
    const auto s = testing::make_test_system(6);  // 343 vertices
    HierarchyOptions options = small_levels(20);
    options.max_levels = 2;
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, options);
    ASSERT_EQ(h.level_count(), 2u);
    MultigridOptions exact;
    exact.drop_tolerance = 0;
    MultigridPreconditioner operators(h, exact);
    CascadicSolver solver(operators);
    const auto coarse = static_cast<Eigen::Index>(h.levels[1].size());
    const Eigen::MatrixXd p = dense(h.levels[0].interpolation, coarse);
    for (int channel = 0; channel < 3; ++channel) {
        const auto& b = s.b[static_cast<size_t>(channel)];
        const Eigen::MatrixXd a = dense(h.levels[0].view(channel));
        const Eigen::Map<const Eigen::VectorXd> bm(b.data(), static_cast<Eigen::Index>(b.size()));
        const Eigen::VectorXd solution = a.ldlt().solve(bm);
        const Eigen::VectorXd projection = p * (p.transpose() * a * p).ldlt().solve(p.transpose() * bm);

        std::vector<double> start(b.size());
        const CascadicReport report = solver.coarse_pass(b, channel, start, {});
        ASSERT_EQ(report.coarse_levels.size(), 1u);  // the coarsest, solved exactly
        const Eigen::Map<const Eigen::VectorXd> x(start.data(), static_cast<Eigen::Index>(start.size()));
        EXPECT_LT((x - projection).norm(), 1e-10 * projection.norm()) << "channel " << channel;
        const Eigen::VectorXd orthogonality = p.transpose() * a * (solution - x);
        EXPECT_LT(orthogonality.norm(), 1e-10 * (p.transpose() * bm).norm()) << "channel " << channel;

        MultiresSolver paper(h);
        std::vector<double> eq17(b.size());
        MultiresSolveOptions paper_options;
        paper_options.coarsest_tolerance = 1e-12;
        paper_options.max_iterations = 0;  // the coarse pass alone
        paper.solve(b, channel, eq17, paper_options);
        const Eigen::Map<const Eigen::VectorXd> y(eq17.data(), static_cast<Eigen::Index>(eq17.size()));
        const auto energy = [&](const Eigen::VectorXd& e) { return std::sqrt(e.dot(a * e)); };
        EXPECT_GT((p.transpose() * a * (solution - y)).norm(), 1e-6 * (p.transpose() * bm).norm());
        EXPECT_LT(energy(solution - x), energy(solution - y)) << "channel " << channel;
    }
}

TEST(CascadicSolver, ConvergesToTheLevel0Solution) {
    const auto s = testing::make_test_system(12);  // 2197 vertices
    for (const InterpolationWeights weights : {InterpolationWeights::InverseEdgeLength, InterpolationWeights::LinearExact}) {
        HierarchyOptions hierarchy_options = small_levels(100);
        hierarchy_options.weights = weights;
        const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, hierarchy_options);
        ASSERT_GE(h.level_count(), 3u);
        MultigridPreconditioner operators(h);
        CascadicSolver solver(operators);
        for (int channel = 0; channel < 3; ++channel) {
            const auto& b = s.b[static_cast<size_t>(channel)];
            const auto reference = reference_solution(s.matrix, b, channel);
            std::vector<double> x(b.size(), 123.0);  // ignored: a cold solve
            CascadicOptions options;
            options.relative_tolerance = 1e-9;
            const CascadicReport report = solver.solve(b, channel, x, options);
            EXPECT_TRUE(report.fine.converged);
            EXPECT_LT(relative_error(x, reference), 1e-7) << "channel " << channel;
            ASSERT_EQ(report.coarse_levels.size(), h.level_count() - 1);
            EXPECT_EQ(report.coarse_levels.front().level, static_cast<int>(h.level_count() - 1));
            for (const CascadicLevelReport& level : report.coarse_levels) EXPECT_FALSE(level.skipped) << level.reason;
        }
    }
}

// The schedule: level 1 gets level_iterations, each coarser one growth times more, up to the cap; and
// the pass's start is far closer than the paper's pass's and saves level-0 iterations to a true 1%
// against it and against Jacobi CG from zero.
TEST(CascadicSolver, CoarserLevelsGetMoreIterationsAndTheStartSavesLevel0Work) {
    const auto s = testing::make_test_system(16);  // 4913 vertices
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(60));
    ASSERT_GE(h.level_count(), 4u);
    MultigridPreconditioner operators(h);
    CascadicSolver solver(operators);
    const auto& b = s.b[0];  // the weakest absorption: the slowest channel
    const auto reference = reference_solution(s.matrix, b, 0);
    CascadicOptions options;
    options.level_iterations = 3;
    options.growth = 2;
    options.max_level_iterations = 10;
    std::vector<double> start(b.size());
    const CascadicReport pass = solver.coarse_pass(b, 0, start, options);
    for (const CascadicLevelReport& level : pass.coarse_levels) {
        if (level.level == static_cast<int>(h.level_count() - 1)) {
            EXPECT_EQ(level.iterations, 0);  // solved exactly
        } else {
            const int expected = std::min(10, static_cast<int>(std::lround(3 * std::pow(2.0, level.level - 1))));
            EXPECT_EQ(level.iterations, expected) << "level " << level.level;
        }
    }

    MultiresSolver paper(h);
    std::vector<double> paper_start(b.size());
    MultiresSolveOptions paper_options;
    paper_options.max_iterations = 0;
    paper.solve(b, 0, paper_start, paper_options);
    const double cascadic_error = relative_error(start, reference), paper_error = relative_error(paper_start, reference);
    EXPECT_LT(cascadic_error, 0.5 * paper_error);

    // Level-0 Jacobi CG iterations to a true 1% from each start (the measure of the solver comparison).
    const auto iterations_to_1_percent = [&](const std::vector<double>& from) {
        for (int k = 0; k < 1000; ++k) {
            std::vector<double> x = from;
            solve_jacobi_cg<double>(h.levels[0].view(0), b, x, exact_iteration_count(k));
            if (relative_error(x, reference) <= 0.01) return k;
        }
        return 1000;
    };
    const int from_zero = iterations_to_1_percent(std::vector<double>(b.size(), 0.0));
    const int from_paper = iterations_to_1_percent(paper_start);
    const int from_cascadic = iterations_to_1_percent(start);
    std::printf("start error: cascadic %.2f%%, paper's pass %.2f%%; level-0 iterations to 1%%: from zero %d, paper's "
                "start %d, cascadic start %d\n",
                100 * cascadic_error, 100 * paper_error, from_zero, from_paper, from_cascadic);
    // Measured: 35 from zero, 31 from the paper's start, 21 from the cascadic start (start errors 48%
    // and 15%). Asserted: fewer than from the paper's start, and at least a third fewer than from zero.
    EXPECT_LT(from_cascadic, from_paper);
    EXPECT_LE(3 * from_cascadic, 2 * from_zero);

    options.relative_tolerance = 1e-6;
    std::vector<double> x(b.size());
    const CascadicReport report = solver.solve(b, 0, x, options);
    EXPECT_TRUE(report.fine.converged);
    EXPECT_LT(relative_error(x, reference), 1e-5);
}

TEST(CascadicSolver, OneLevelIsSolvedExactly) {
    const auto s = testing::make_test_system(3);
    HierarchyOptions options;
    options.min_coarse_vertices = 1000000;  // nothing to coarsen: level 0 is the coarsest
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, options);
    ASSERT_EQ(h.level_count(), 1u);
    MultigridPreconditioner operators(h);
    CascadicSolver solver(operators);
    const auto reference = reference_solution(s.matrix, s.b[1], 1);
    std::vector<double> x(reference.size());
    const CascadicReport report = solver.solve(s.b[1], 1, x);
    EXPECT_TRUE(report.coarse_levels.empty());
    EXPECT_LT(relative_error(x, reference), 1e-10);
    EXPECT_LE(report.fine.iterations, 3);  // a cold CG's estimate confirms over three steps (conjugate_gradient.h)
}

TEST(CascadicSolver, IsDeterministicAcrossThreadCounts) {
    const auto s = testing::make_test_system(10);
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(50));
    std::vector<double> xa(s.b[1].size()), xb(s.b[1].size());
    {
        MultigridPreconditioner operators(h);
        CascadicSolver(operators).solve(s.b[1], 1, xa);
    }
    {
        const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
        MultigridPreconditioner operators(h);
        CascadicSolver(operators).solve(s.b[1], 1, xb);
    }
    EXPECT_EQ(xa, xb);
}

TEST(CascadicSolver, RejectsBadInputWithTypedErrors) {
    const auto s = testing::make_test_system(4);
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(20));
    MultigridPreconditioner operators(h);
    CascadicSolver solver(operators);
    std::vector<double> x(s.b[0].size()), wrong(3);
    EXPECT_THROW(solver.solve(s.b[0], 3, x), InvalidArgumentError);
    EXPECT_THROW(solver.solve(wrong, 0, x), InvalidArgumentError);
    EXPECT_THROW(solver.solve(s.b[0], 0, wrong), InvalidArgumentError);
    for (const auto& bad : {CascadicOptions{.level_iterations = -1}, CascadicOptions{.growth = 0.5},
                            CascadicOptions{.growth = std::numeric_limits<double>::quiet_NaN()},
                            CascadicOptions{.max_level_iterations = -2}, CascadicOptions{.relative_tolerance = 0},
                            CascadicOptions{.relative_tolerance = 1.5}, CascadicOptions{.max_iterations = -1}})
        EXPECT_THROW(solver.solve(s.b[0], 0, x, bad), InvalidArgumentError);
    // A non-finite right-hand side is refused before any level runs: no NaN comes back as a result.
    std::vector<double> nan_b = s.b[0];
    nan_b[nan_b.size() / 2] = std::nan("");
    EXPECT_THROW(solver.solve(nan_b, 0, x), AlgorithmError);
    EXPECT_THROW(solver.coarse_pass(nan_b, 0, x), AlgorithmError);
}

// A level CG cannot iterate on (here [[1, 2], [2, 1]], indefinite: p.Mp < 0 along (1, -1)) keeps its
// start and says why; a positive definite one iterates.
TEST(CascadicSolver, ALevelCgRefusesKeepsItsStart) {
    const std::vector<int32_t> offsets = {0, 2, 4}, columns = {0, 1, 0, 1};
    const std::vector<double> indefinite = {1, 2, 2, 1}, definite = {2, -1, -1, 2};
    const std::vector<double> b = {1, -1};
    std::vector<double> x = {0.25, 0.5};
    const CascadicLevelReport refused = iterate_level({2, offsets.data(), columns.data(), indefinite.data()}, b, x, 5);
    EXPECT_TRUE(refused.skipped);
    EXPECT_FALSE(refused.reason.empty());
    EXPECT_EQ(x, (std::vector<double>{0.25, 0.5}));
    const CascadicLevelReport iterated = iterate_level({2, offsets.data(), columns.data(), definite.data()}, b, x, 5);
    EXPECT_FALSE(iterated.skipped);
    EXPECT_GE(iterated.iterations, 1);
    EXPECT_NEAR(x[0], 1.0 / 3.0, 1e-12);  // [[2, -1], [-1, 2]] x = (1, -1): x = (1/3, -1/3)
    EXPECT_NEAR(x[1], -1.0 / 3.0, 1e-12);
}

// Slivers (as MultigridPreconditioner.SliversFallBackToAbsoluteLumpingAndStillConverge): the operators
// fall back to absolute lumping and the cascadic solve still reaches the direct solution.
TEST(CascadicSolver, SliverVolumeConverges) {
    const testing::SliverSystem s = testing::make_sliver_system();
    const std::vector<double>& b = s.b;
    const MultiresHierarchy& h = s.hierarchy;
    ASSERT_GE(h.level_count(), 2u);
    MultigridPreconditioner operators(h);
    EXPECT_EQ(operators.lumping(), DropLumping::Absolute);
    CascadicSolver solver(operators);
    const Eigen::VectorXd exact = refined_direct_solution(
        to_eigen_sparse(s.matrix, 0), Eigen::Map<const Eigen::VectorXd>(b.data(), static_cast<Eigen::Index>(b.size())));
    std::vector<double> x(b.size());
    CascadicOptions options;
    options.relative_tolerance = 1e-9;
    options.max_iterations = 20000;
    const CascadicReport report = solver.solve(b, 0, x, options);
    EXPECT_TRUE(report.fine.converged);
    EXPECT_TRUE(all_finite(x));
    EXPECT_LT(relative_error(x, std::vector<double>(exact.data(), exact.data() + exact.size())), 1e-6);
}

}  // namespace
}  // namespace waxwork
