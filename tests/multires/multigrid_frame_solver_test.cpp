#include "base/error.h"
#include "multires/multigrid_cg.h"
#include "multires/multigrid_frame_solver.h"
#include "multires/multigrid_preconditioner.h"
#include "solver/lighting.h"
#include "multires_test_systems.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace waxwork {
namespace {

using testing::small_levels;

using testing::reference_solution;
using testing::relative_error;

FrameSolverOptions frame_options(int64_t min_coarse, double tolerance) {
    FrameSolverOptions options;
    options.hierarchy = small_levels(min_coarse);
    options.relative_tolerance = tolerance;
    return options;
}

using testing::spans;


TEST(MultigridPreconditioner, ApplyRgbEqualsThreeApplyCalls) {
    const auto s = testing::make_test_system(9);
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(50));
    ASSERT_GE(h.level_count(), 3u);
    const size_t n = h.levels[0].size();
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<double> r(3 * n), z(3 * n);
    for (double& v : r) v = u(rng);
    for (bool single : {true, false}) {
        MultigridOptions options;
        options.single_precision = single;
        MultigridPreconditioner mg(h, options);
        mg.apply_rgb(r, z);
        for (int c = 0; c < 3; ++c) {
            std::vector<double> rc(n), zc(n);
            for (size_t i = 0; i < n; ++i) rc[i] = r[3 * i + static_cast<size_t>(c)];
            mg.apply(c, rc, zc);
            size_t differing = 0;
            for (size_t i = 0; i < n; ++i) differing += zc[i] != z[3 * i + static_cast<size_t>(c)] ? 1 : 0;
            EXPECT_EQ(differing, 0u) << "channel " << c << " single " << single;
        }
    }
    MultigridPreconditioner mg(h);
    std::vector<double> wrong(3 * n - 1);
    EXPECT_THROW(mg.apply_rgb(wrong, z), InvalidArgumentError);
}

TEST(MultigridFrameSolver, ConvergesToTheDoublePrecisionSolution) {
    const auto s = testing::make_test_system(12);  // 2197 vertices
    MultigridFrameSolver solver(s.matrix, s.mesh.positions, frame_options(100, 1e-9));
    ASSERT_GE(solver.hierarchy().level_count(), 3u);
    solver.set_right_hand_side(spans(s.b));
    FrameStep step;
    int frames = 0;
    for (; frames < 20 && !step.converged; ++frames) step = solver.step(5);
    EXPECT_TRUE(step.converged);
    for (int c = 0; c < 3; ++c) {
        EXPECT_LE(step.estimated_relative_error[static_cast<size_t>(c)], 1e-9);
        const auto reference = reference_solution(s.matrix, s.b[static_cast<size_t>(c)], c);
        EXPECT_LT(relative_error(solver.phi(c), reference), 1e-7) << "channel " << c;
    }
}

// Asked for less than double can give, the solver stops early at its floor and says so: the estimates
// from its periodically recomputed residual stop halving. It does not spend its budget.
TEST(MultigridFrameSolver, StopsAtDoublesFloorInsteadOfSpendingItsBudget) {
    const auto s = testing::make_test_system(12);
    MultigridFrameSolver solver(s.matrix, s.mesh.positions, frame_options(100, 1e-18));
    solver.set_right_hand_side(spans(s.b));
    constexpr int kBudget = 5000;
    const FrameStep step = solver.step(kBudget);
    EXPECT_FALSE(step.converged);
    EXPECT_TRUE(step.at_precision_floor);
    EXPECT_LT(step.vcycles, 500);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(step.estimated_relative_error[static_cast<size_t>(c)], 1e-18);
        const auto reference = reference_solution(s.matrix, s.b[static_cast<size_t>(c)], c);
        EXPECT_LT(relative_error(solver.phi(c), reference), 1e-9) << "channel " << c;
    }
}

// The live editor converges a scene its frames left at a looser tolerance: a tighter tolerance set later
// makes step() continue from where it stopped, to the tighter error.
// Built on a given hierarchy (a rebuild's), the solver is the one it builds itself on the same
// hierarchy; a hierarchy of another size or other options is refused.
TEST(MultigridFrameSolver, TakesAHierarchyBuiltForItsMatrix) {
    const auto s = testing::make_test_system(8);
    FrameSolverOptions options;
    MultigridFrameSolver own(s.matrix, s.mesh.positions, options);
    MultigridFrameSolver given(s.matrix, build_multires_hierarchy(s.matrix, s.mesh.positions, options.hierarchy), options);
    const std::array<std::span<const double>, 3> b = {s.b[0], s.b[1], s.b[2]};
    own.set_right_hand_side(b);
    given.set_right_hand_side(b);
    own.step(3);
    given.step(3);
    for (int c = 0; c < 3; ++c) {
        const std::span<const double> x = own.phi(c), y = given.phi(c);
        EXPECT_TRUE(std::equal(x.begin(), x.end(), y.begin(), y.end())) << "channel " << c;
    }
    const auto small = testing::make_test_system(4);
    EXPECT_THROW(MultigridFrameSolver(s.matrix, build_multires_hierarchy(small.matrix, small.mesh.positions), options),
                 InvalidArgumentError);
    HierarchyOptions other;
    other.seed = 5;
    EXPECT_THROW(MultigridFrameSolver(s.matrix, build_multires_hierarchy(s.matrix, s.mesh.positions, other), options),
                 InvalidArgumentError);
}

TEST(MultigridFrameSolver, ATighterToleranceContinuesTheSolve) {
    const auto s = testing::make_test_system(10);
    MultigridFrameSolver solver(s.matrix, s.mesh.positions, frame_options(100, 1e-2));
    solver.set_right_hand_side(spans(s.b));
    FrameStep step = testing::step_until_converged(solver, 2, 20);
    ASSERT_TRUE(step.converged);
    const auto reference = reference_solution(s.matrix, s.b[0], 0);
    const double loose = relative_error(solver.phi(0), reference);
    EXPECT_TRUE(solver.step(1).converged);  // still within the loose tolerance
    solver.set_relative_tolerance(1e-8);
    step = solver.step(1);
    EXPECT_FALSE(step.converged);
    EXPECT_EQ(step.vcycles, 1);
    if (!step.converged) step = testing::step_until_converged(solver, 2, 50);
    EXPECT_TRUE(step.converged);
    EXPECT_LT(relative_error(solver.phi(0), reference), std::min(1e-6, 0.01 * loose));
    EXPECT_THROW(solver.set_relative_tolerance(0), InvalidArgumentError);
    EXPECT_THROW(solver.set_relative_tolerance(std::nan("")), InvalidArgumentError);
}

// The budget the live editor gives a frame after the light moved (bench/multires_bench.cpp,
// BM_LightTurn10Degrees mode 3, times it on spot).
constexpr int kLightTurnBudget = 1;

TEST(MultigridFrameSolver, WarmStartAfterALightTurnIsWithinOnePercentInOneVcycle) {
    const auto s = testing::make_test_system(12);
    MultigridFrameSolver solver(s.matrix, s.mesh.positions, frame_options(100, 1e-2));
    const auto before = testing::light_rhs(s, 0), after = testing::light_rhs(s, 10);
    solver.set_right_hand_side(spans(before));
    // The previous frames: converged on the old light.
    FrameStep step = testing::step_until_converged(solver, 4, 20);
    ASSERT_TRUE(step.converged);
    std::array<std::vector<double>, 3> reference;
    for (int c = 0; c < 3; ++c) {
        const auto cu = static_cast<size_t>(c);
        reference[cu] = reference_solution(s.matrix, after[cu], c);
        ASSERT_GT(relative_error(solver.phi(c), reference[cu]), 2e-2) << "the turn must change the solution";
    }
    solver.set_right_hand_side(spans(after));
    step = solver.step(kLightTurnBudget);
    EXPECT_EQ(step.vcycles, kLightTurnBudget);
    for (int c = 0; c < 3; ++c)
        EXPECT_LT(relative_error(solver.phi(c), reference[static_cast<size_t>(c)]), 1e-2) << "channel " << c;
    // More frames on the same light continue the solve down to the tolerance.
    for (int frames = 0; frames < 10 && !step.converged; ++frames) step = solver.step(kLightTurnBudget);
    EXPECT_TRUE(step.converged);
}

TEST(MultigridFrameSolver, IsDeterministicAcrossThreadCounts) {
    const auto s = testing::make_test_system(10);
    auto run = [&] {
        MultigridFrameSolver solver(s.matrix, s.mesh.positions, frame_options(50, 1e-6));
        solver.set_right_hand_side(spans(s.b));
        solver.step(3);
        std::array<std::vector<double>, 3> phi;
        for (int c = 0; c < 3; ++c) phi[static_cast<size_t>(c)].assign(solver.phi(c).begin(), solver.phi(c).end());
        return phi;
    };
    const auto many = run();
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_EQ(many, run());
}

TEST(MultigridFrameSolver, FollowsPaintedValues) {
    auto s = testing::make_test_system(8);
    MultigridFrameSolver solver(s.matrix, s.mesh.positions, frame_options(30, 1e-8));
    testing::expect_follows_painted_values(solver, s, 1e-6);
}

TEST(MultigridFrameSolver, RejectsBadInput) {
    const auto s = testing::make_test_system(5);
    MultigridFrameSolver solver(s.matrix, s.mesh.positions, frame_options(20, 1e-2));
    testing::expect_refuses_steps_without_a_valid_b(solver, s);
    solver.set_right_hand_side(spans(s.b));
    EXPECT_THROW(solver.step(0), InvalidArgumentError);
    EXPECT_THROW((void)solver.phi(3), InvalidArgumentError);
    testing::expect_zero_b_solved_at_once(solver);
}

}  // namespace
}  // namespace waxwork
