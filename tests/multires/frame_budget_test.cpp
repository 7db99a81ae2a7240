// Millisecond frame budgets (solver/frame_budget.h) in the multires per-frame solvers, on a fake clock:
// MultiresSolver::solve_frame and MultigridFrameSolver::step stop where the deadline says, equal to the
// iteration-budget run of that length bit for bit, and successive timed frames converge.
#include "base/error.h"
#include "multires/multigrid_frame_solver.h"
#include "multires/multires_solver.h"
#include "multires_test_systems.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

namespace waxwork {
namespace {

using testing::relative_error;

// Advances `step` ms at every read (the first read returns 0).
MillisecondClock fake_clock(double step) {
    return [now = std::make_shared<double>(0.0), step] {
        const double t = *now;
        *now += step;
        return t;
    };
}

// Reads before iteration k + 1 return k * step: a deadline of `ms` lets ceil(ms / step) run.
int iterations_within(double ms, double step) { return static_cast<int>(std::ceil(ms / step)); }

using testing::spans;

// sqrt(e . M e) / sqrt(x* . M x*) for e = x - x*: the norm CG lowers at every iteration.
double energy_error(const DiffusionMatrix& m, int channel, std::span<const double> x, std::span<const double> exact) {
    const CsrMatrixView<double> view{m.size(), m.offsets.data(), m.columns.data(),
                                     m.values[static_cast<size_t>(channel)].data()};
    std::vector<double> e(x.size()), me(x.size()), mx(x.size());
    for (size_t i = 0; i < x.size(); ++i) e[i] = x[i] - exact[i];
    multiply<double>(view, e, me);
    multiply<double>(view, exact, mx);
    double num = 0, den = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        num += e[i] * me[i];
        den += exact[i] * mx[i];
    }
    return std::sqrt(num / den);
}

TEST(MultiresFrameBudget, SolveFrameStopsAtTheDeadlineLikeAnIterationBudget) {
    const auto s = testing::make_test_system(10);
    MultiresSolver timed(s.matrix, s.mesh.positions, testing::small_levels(100));
    MultiresSolver counted(s.matrix, s.mesh.positions, testing::small_levels(100));
    MultiresSolveOptions options;
    options.relative_tolerance = 1e-12;  // not reached in these frames
    const double step = 1.0;
    // The first frame runs the coarse-to-fine pass whole (no clock reads), then the level-0 CG until the
    // deadline; the next frames are level-0 CG only.
    for (const double ms : {6.5, 3.2, 9.9}) {
        const int expected = iterations_within(ms, step);
        MultiresSolveReport timed_report, counted_report;
        const std::span<const double> x_timed =
            timed.solve_frame(s.b[1], 1, FrameBudget::milliseconds(ms), &timed_report, options, fake_clock(step));
        const std::span<const double> x_counted = counted.solve_frame(s.b[1], 1, expected, &counted_report, options);
        EXPECT_EQ(timed_report.fine.iterations, expected) << ms;
        EXPECT_EQ(timed_report.coarse_levels.size(), counted_report.coarse_levels.size());
        for (size_t l = 0; l < timed_report.coarse_levels.size(); ++l)
            EXPECT_EQ(timed_report.coarse_levels[l].iterations, counted_report.coarse_levels[l].iterations);
        EXPECT_TRUE(std::equal(x_timed.begin(), x_timed.end(), x_counted.begin(), x_counted.end()))
            << "not bit-identical at " << ms << " ms";
    }
}

TEST(MultiresFrameBudget, FirstFrameRunsTheCoarsePassWholeThenOneIteration) {
    const auto s = testing::make_test_system(10);
    MultiresSolver solver(s.matrix, s.mesh.positions, testing::small_levels(100));
    MultiresSolveOptions options;
    options.relative_tolerance = 1e-12;
    MultiresSolveReport report;
    // Every read is past the 1 ms deadline: the coarse pass still runs to its own tolerances, and the
    // level-0 CG runs its one iteration.
    solver.solve_frame(s.b[0], 0, FrameBudget::milliseconds(1), &report, options, fake_clock(50));
    ASSERT_FALSE(report.coarse_levels.empty());
    MultiresSolver unlimited(s.matrix, s.mesh.positions, testing::small_levels(100));
    MultiresSolveReport reference;
    unlimited.solve_frame(s.b[0], 0, 1, &reference, options);
    ASSERT_EQ(report.coarse_levels.size(), reference.coarse_levels.size());
    for (size_t l = 0; l < report.coarse_levels.size(); ++l)
        EXPECT_EQ(report.coarse_levels[l].iterations, reference.coarse_levels[l].iterations);
    EXPECT_EQ(report.fine.iterations, 1);
}

TEST(MultiresFrameBudget, IterationLimitAndTimeLimitWhicheverComesFirst) {
    const auto s = testing::make_test_system(8);
    MultiresSolver solver(s.matrix, s.mesh.positions, testing::small_levels(100));
    MultiresSolveOptions options;
    options.relative_tolerance = 1e-12;
    MultiresSolveReport report;
    solver.solve_frame(s.b[0], 0, FrameBudget::milliseconds(100, 3), &report, options, fake_clock(1));
    EXPECT_EQ(report.fine.iterations, 3);
    solver.solve_frame(s.b[0], 0, FrameBudget::milliseconds(2.5, 30), &report, options, fake_clock(1));
    EXPECT_EQ(report.fine.iterations, iterations_within(2.5, 1));
    // An iteration-only budget is the int overload.
    MultiresSolver a(s.matrix, s.mesh.positions, testing::small_levels(100)), b(s.matrix, s.mesh.positions, testing::small_levels(100));
    const auto xa = a.solve_frame(s.b[2], 2, FrameBudget::iterations(4), nullptr, options);
    const auto xb = b.solve_frame(s.b[2], 2, 4, nullptr, options);
    EXPECT_TRUE(std::equal(xa.begin(), xa.end(), xb.begin(), xb.end()));
}

TEST(MultiresFrameBudget, SuccessiveTimedFramesConverge) {
    const auto s = testing::make_test_system(10);
    MultiresSolver solver(s.matrix, s.mesh.positions, testing::small_levels(100));
    MultiresSolveOptions options;
    options.relative_tolerance = 1e-4;
    const auto exact = testing::reference_solution(s.matrix, s.b[0], 0);
    double previous = std::numeric_limits<double>::infinity();
    int frames = 0;
    std::span<const double> x;
    for (; frames < 200; ++frames) {
        MultiresSolveReport report;
        x = solver.solve_frame(s.b[0], 0, FrameBudget::milliseconds(1.5), &report, options, fake_clock(1));
        EXPECT_LE(report.fine.iterations, iterations_within(1.5, 1));
        const double now = energy_error(s.matrix, 0, x, exact);
        EXPECT_LT(now, previous) << "frame " << frames;
        previous = now;
        if (relative_error(x, exact) < 0.01) break;
    }
    EXPECT_LT(relative_error(x, exact), 0.01) << "after " << frames << " frames";
}

FrameSolverOptions frame_options(double tolerance) {
    FrameSolverOptions options;
    options.hierarchy = testing::small_levels(100);
    options.relative_tolerance = tolerance;
    return options;
}

TEST(MultigridFrameBudget, StepStopsAtTheDeadlineLikeAVcycleBudget) {
    const auto s = testing::make_test_system(10);
    MultigridFrameSolver timed(s.matrix, s.mesh.positions, frame_options(1e-14));
    MultigridFrameSolver counted(s.matrix, s.mesh.positions, frame_options(1e-14));
    timed.set_right_hand_side(spans(s.b));
    counted.set_right_hand_side(spans(s.b));
    const double step = 2.0;
    for (const double ms : {5.0, 3.0, 7.5}) {
        const int expected = iterations_within(ms, step);
        const FrameStep a = timed.step(FrameBudget::milliseconds(ms), fake_clock(step));
        const FrameStep b = counted.step(expected);
        EXPECT_EQ(a.vcycles, expected) << ms;
        EXPECT_FALSE(a.converged);
        EXPECT_EQ(a.estimated_relative_error, b.estimated_relative_error);
        for (int c = 0; c < 3; ++c) {
            const auto pa = timed.phi(c), pb = counted.phi(c);
            EXPECT_TRUE(std::equal(pa.begin(), pa.end(), pb.begin(), pb.end()))
                << "channel " << c << ", " << ms << " ms";
        }
    }
    // A V-cycle limit below the time limit wins; an expired deadline still runs one V-cycle.
    EXPECT_EQ(timed.step(FrameBudget::milliseconds(100, 2), fake_clock(1)).vcycles, 2);
    EXPECT_EQ(timed.step(FrameBudget::milliseconds(0.5), fake_clock(1)).vcycles, 1);
}

TEST(MultigridFrameBudget, SuccessiveTimedFramesConverge) {
    const auto s = testing::make_test_system(10);
    MultigridFrameSolver solver(s.matrix, s.mesh.positions, frame_options(1e-6));
    solver.set_right_hand_side(spans(s.b));
    std::array<std::vector<double>, 3> exact;
    for (size_t c = 0; c < 3; ++c)
        exact[c] = testing::reference_solution(s.matrix, s.b[c], static_cast<int>(c));
    // CG lowers each channel's energy-norm error at every update, so their maximum falls frame by frame.
    auto worst = [&](bool energy) {
        double e = 0;
        for (int c = 0; c < 3; ++c) {
            const auto& x = exact[static_cast<size_t>(c)];
            e = std::max(e, energy ? energy_error(s.matrix, c, solver.phi(c), x) : relative_error(solver.phi(c), x));
        }
        return e;
    };
    double previous = worst(true);
    int frames = 0;
    for (; frames < 50 && worst(false) >= 0.01; ++frames) {
        const FrameStep step = solver.step(FrameBudget::milliseconds(0.5), fake_clock(1));  // one V-cycle
        EXPECT_EQ(step.vcycles, 1);
        const double now = worst(true);
        EXPECT_LT(now, previous) << "frame " << frames;
        previous = now;
    }
    EXPECT_LT(worst(false), 0.01) << "after " << frames << " frames";
    EXPECT_GT(frames, 1);
}

TEST(FrameBudgetValidation, SolversRejectInvalidBudgets) {
    const auto s = testing::make_test_system(6);
    MultiresSolver multires(s.matrix, s.mesh.positions, testing::small_levels(100));
    MultigridFrameSolver multigrid(s.matrix, s.mesh.positions, frame_options(1e-3));
    multigrid.set_right_hand_side(spans(s.b));
    for (const FrameBudget& bad : {FrameBudget{0, 0}, FrameBudget{-2, 5}, FrameBudget{0, std::nan("")},
                                   FrameBudget{0, -1}}) {
        EXPECT_THROW(multires.solve_frame(s.b[0], 0, bad), InvalidArgumentError);
        EXPECT_THROW(multigrid.step(bad), InvalidArgumentError);
    }
}

}  // namespace
}  // namespace waxwork
