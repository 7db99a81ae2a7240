// Frame budgets (solver/frame_budget.h): validation, deadlines on an injected clock, Jacobi CG stopping
// at a deadline exactly where an iteration budget would, and the GPU's iteration-time predictor
// (solver/iteration_time_predictor.h) on synthetic timings. No real clock is timed here.
#include "base/error.h"
#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "solver/frame_budget.h"
#include "solver/iteration_time_predictor.h"
#include "solver/material.h"
#include "lit_block_system.h"
#include "solver_test_meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>

namespace waxwork {
namespace {

// A clock that advances `step` milliseconds at every read (the first read returns 0), counting reads.
struct FakeClock {
    std::shared_ptr<double> now = std::make_shared<double>(0.0);
    std::shared_ptr<int> reads = std::make_shared<int>(0);
    double step = 1.0;
    MillisecondClock clock() const {
        return [now = now, reads = reads, step = step] {
            ++*reads;
            const double t = *now;
            *now += step;
            return t;
        };
    }
};

void expect_invalid(const FrameBudget& budget, const std::string& field) {
    try {
        validate(budget);
        ADD_FAILURE() << "accepted " << budget.max_iterations << " iterations, " << budget.max_milliseconds << " ms";
    } catch (const InvalidArgumentError& e) {
        EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
}

TEST(FrameBudget, ValidationNamesTheField) {
    const double inf = std::numeric_limits<double>::infinity();
    expect_invalid({-1, 0}, "max_iterations");
    expect_invalid({-1, 5}, "max_iterations");
    expect_invalid({0, std::nan("")}, "max_milliseconds");
    expect_invalid({10, std::nan("")}, "max_milliseconds");
    expect_invalid({0, -2}, "max_milliseconds");
    expect_invalid({0, 0}, "neither");
    expect_invalid({0, inf}, "neither");
    EXPECT_NO_THROW(validate(FrameBudget::iterations(1)));
    EXPECT_NO_THROW(validate(FrameBudget::milliseconds(0.5)));
    EXPECT_NO_THROW(validate(FrameBudget::milliseconds(10, 3)));
    EXPECT_NO_THROW(validate(FrameBudget{7, inf}));  // infinity: no time limit, the iterations bound it
    EXPECT_FALSE(FrameBudget::iterations(5).limits_time());
    EXPECT_TRUE(FrameBudget::milliseconds(5).limits_time());
    EXPECT_FALSE(FrameBudget::milliseconds(5).limits_iterations());
}

TEST(FrameDeadline, ExpiresOnTheInjectedClock) {
    FakeClock fake;
    fake.step = 1.0;
    const FrameDeadline deadline = FrameDeadline::after(2.5, fake.clock());  // read 0: ends at 2.5
    EXPECT_TRUE(deadline.bounded());
    EXPECT_FALSE(deadline.expired());  // 1
    EXPECT_FALSE(deadline.expired());  // 2
    EXPECT_TRUE(deadline.expired());   // 3
    EXPECT_EQ(*fake.reads, 4);

    // No time limit: never expires and never reads the clock.
    FakeClock idle;
    for (const FrameDeadline& none : {FrameDeadline{}, FrameDeadline::after(0, idle.clock()),
                                      FrameDeadline::of(FrameBudget::iterations(4), idle.clock())}) {
        EXPECT_FALSE(none.bounded());
        EXPECT_FALSE(none.expired());
        EXPECT_TRUE(std::isinf(none.remaining()));
        EXPECT_FALSE(none.share(3).bounded());
    }
    EXPECT_EQ(*idle.reads, 0);
}

TEST(FrameDeadline, SharesSplitWhatIsLeft) {
    FakeClock fake;
    fake.step = 0;  // a frozen clock: shares are exact
    const FrameDeadline frame = FrameDeadline::after(12, fake.clock());
    EXPECT_DOUBLE_EQ(frame.share(3).remaining(), 4.0);
    EXPECT_DOUBLE_EQ(frame.share(1).remaining(), 12.0);
    *fake.now = 9;  // 3 ms left: the last two channels split them
    EXPECT_DOUBLE_EQ(frame.share(2).remaining(), 1.5);
    *fake.now = 20;  // past the deadline: every share is expired too
    EXPECT_TRUE(frame.share(2).expired());
}

// A lit cube of marble, 16 mm.
struct CubeSystem : test::LitBlockSystem {
    CubeSystem() : LitBlockSystem(test::make_cube_mesh(8, 2.0)) {}
};

TEST(FrameBudget, JacobiCgStopsAtTheDeadlineLikeAnIterationBudget) {
    const CubeSystem s;
    for (const double budget_ms : {6.5, 11.2}) {
        FakeClock fake;
        fake.step = 1.0;  // one read per iteration after the first: iteration k+1 starts at time k
        ConjugateGradientOptions timed;
        timed.relative_tolerance = 1e-10;  // not reached in these few iterations
        timed.max_iterations = 10000;
        timed.deadline = FrameDeadline::after(budget_ms, fake.clock());
        std::vector<double> x_timed(s.b.size(), 0.0);
        const ConjugateGradientResult r_timed = solve_jacobi_cg<double>(s.view(), s.b, x_timed, timed);
        const int expected = static_cast<int>(std::ceil(budget_ms / fake.step));
        EXPECT_EQ(r_timed.iterations, expected) << budget_ms;
        EXPECT_FALSE(r_timed.converged);

        ConjugateGradientOptions counted;
        counted.relative_tolerance = timed.relative_tolerance;
        counted.max_iterations = expected;
        std::vector<double> x_counted(s.b.size(), 0.0);
        const ConjugateGradientResult r_counted = solve_jacobi_cg<double>(s.view(), s.b, x_counted, counted);
        EXPECT_EQ(r_counted.iterations, expected);
        EXPECT_EQ(x_timed, x_counted) << "not bit-identical at " << budget_ms << " ms";
        EXPECT_EQ(r_timed.estimated_relative_error, r_counted.estimated_relative_error);
    }
}

TEST(FrameBudget, JacobiCgRunsOneIterationPastAnExpiredDeadline) {
    const CubeSystem s;
    FakeClock fake;
    fake.step = 100;  // every read is far past the 1 ms deadline
    ConjugateGradientOptions options;
    options.relative_tolerance = 1e-10;
    options.deadline = FrameDeadline::after(1, fake.clock());
    (void)options.deadline.expired();  // the frame's time is already spent
    std::vector<double> x(s.b.size(), 0.0);
    EXPECT_EQ(solve_jacobi_cg<double>(s.view(), s.b, x, options).iterations, 1);
    EXPECT_GT(std::abs(x[0]) + std::abs(x[x.size() - 1]), 0.0);  // progress was made
}

TEST(FrameBudget, SuccessiveTimedFramesConverge) {
    // Warm-started frames of a few (fake) milliseconds each reach 1% of the solution to 1e-10. CG
    // lowers the energy norm of the error at every iteration, warm restarts included, so it falls frame
    // by frame (the l2 error need not be monotonic).
    const CubeSystem s;
    ConjugateGradientOptions exact_options;
    exact_options.relative_tolerance = 1e-10;
    std::vector<double> exact(s.b.size(), 0.0);
    ASSERT_TRUE(solve_jacobi_cg<double>(s.view(), s.b, exact, exact_options).converged);
    auto l2_error = [&](const std::vector<double>& x) {
        double e = 0, n = 0;
        for (size_t i = 0; i < x.size(); ++i) {
            e += (x[i] - exact[i]) * (x[i] - exact[i]);
            n += exact[i] * exact[i];
        }
        return std::sqrt(e / n);
    };
    auto energy_error = [&](const std::vector<double>& x) {
        std::vector<double> e(x.size()), me(x.size());
        for (size_t i = 0; i < x.size(); ++i) e[i] = x[i] - exact[i];
        multiply<double>(s.view(), e, me);
        double sum = 0;
        for (size_t i = 0; i < x.size(); ++i) sum += e[i] * me[i];
        return std::sqrt(sum);
    };
    std::vector<double> x(s.b.size(), 0.0);
    double hint = 0, previous = energy_error(x);
    int frames = 0;
    for (; frames < 200 && l2_error(x) > 0.01; ++frames) {
        FakeClock fake;
        ConjugateGradientOptions frame;
        frame.relative_tolerance = 1e-4;
        frame.smallest_eigenvalue_hint = hint;
        frame.deadline = FrameDeadline::after(3.5, fake.clock());
        const ConjugateGradientResult r = solve_jacobi_cg<double>(s.view(), s.b, x, frame);
        EXPECT_LE(r.iterations, 4);  // ceil(3.5 ms / 1 ms per read)
        hint = r.smallest_eigenvalue_estimate;
        const double now = energy_error(x);
        EXPECT_LT(now, previous) << "frame " << frames;
        previous = now;
    }
    EXPECT_LT(l2_error(x), 0.01) << "after " << frames << " frames";
    EXPECT_GT(frames, 1);  // it took several frames, each stopped by its deadline
}

TEST(IterationTimePredictor, FirstFrameUsesTheLimitOrTheDefault) {
    const IterationTimePredictor predictor;
    EXPECT_FALSE(predictor.milliseconds_per_iteration());
    EXPECT_EQ(predictor.iterations_for(FrameBudget::iterations(37)), 37);
    EXPECT_EQ(predictor.iterations_for(FrameBudget::milliseconds(10, 25)), 25);
    EXPECT_EQ(predictor.iterations_for(FrameBudget::milliseconds(10)),
              IterationTimePredictor::kDefaultFirstFrameIterations);
    EXPECT_EQ(predictor.iterations_for(FrameBudget::milliseconds(10, 3)), 3);
    EXPECT_THROW(predictor.iterations_for(FrameBudget{0, 0}), InvalidArgumentError);
    EXPECT_THROW(IterationTimePredictor(0), InvalidArgumentError);
    EXPECT_THROW(IterationTimePredictor(1.5), InvalidArgumentError);
    EXPECT_THROW(IterationTimePredictor(std::nan("")), InvalidArgumentError);
}

TEST(IterationTimePredictor, FollowsTheMeasuredCostPerIteration) {
    const double smoothing = 0.5;
    IterationTimePredictor predictor(smoothing);
    predictor.record(10, 20.0);  // 2 ms per iteration
    ASSERT_TRUE(predictor.milliseconds_per_iteration());
    EXPECT_DOUBLE_EQ(*predictor.milliseconds_per_iteration(), 2.0);
    EXPECT_EQ(predictor.iterations_for(FrameBudget::milliseconds(9)), 4);  // floor(9 / 2)
    EXPECT_EQ(predictor.iterations_for(FrameBudget::milliseconds(9, 3)), 3);  // capped by the limit
    EXPECT_EQ(predictor.iterations_for(FrameBudget::milliseconds(0.5)), 1);   // at least one
    EXPECT_EQ(predictor.iterations_for(FrameBudget::iterations(50)), 50);     // no time limit: ignored

    // The machine slows down to 4 ms per iteration: the average moves towards it frame by frame and the
    // predicted count falls monotonically to 10 ms / 4 ms.
    int previous = predictor.iterations_for(FrameBudget::milliseconds(10));
    double expected = 2.0;
    for (int frame = 0; frame < 30; ++frame) {
        predictor.record(5, 20.0);
        expected = (1 - smoothing) * expected + smoothing * 4.0;
        EXPECT_NEAR(*predictor.milliseconds_per_iteration(), expected, 1e-12);
        const int now = predictor.iterations_for(FrameBudget::milliseconds(10));
        EXPECT_LE(now, previous);
        previous = now;
    }
    EXPECT_EQ(previous, static_cast<int>(std::floor(10 / 4.0 + 1e-9)));

    // Frames without iterations or with a broken time say nothing.
    const double before = *predictor.milliseconds_per_iteration();
    predictor.record(0, 50.0);
    predictor.record(3, std::nan(""));
    predictor.record(3, -1.0);
    EXPECT_EQ(*predictor.milliseconds_per_iteration(), before);

    // A clock too coarse to see the frame (0 ms): as many as the cap allows, never a division by zero.
    IterationTimePredictor instant;
    instant.record(4, 0.0);
    EXPECT_EQ(instant.iterations_for(FrameBudget::milliseconds(5, 40)), 40);
    EXPECT_EQ(instant.iterations_for(FrameBudget::milliseconds(5)), IterationTimePredictor::kMaxPredictedIterations);
    instant.reset();
    EXPECT_FALSE(instant.milliseconds_per_iteration());
}

}  // namespace
}  // namespace waxwork
