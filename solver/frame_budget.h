// How much work one live frame may do: at most so many iterations, at most so many milliseconds, or
// both (whichever runs out first).
//
// Why milliseconds as well as iterations. An iteration budget costs a different time on every mesh
// size, method and machine; what the user wants to fix is the frame rate. The CPU solvers check a
// FrameDeadline once per iteration (solve_jacobi_cg), per V-cycle (MultigridFrameSolver::step) or per
// level-0 CG iteration (MultiresSolver::solve_frame): a check is one clock read, negligible next to an
// iteration over the matrix. An iteration that has started always finishes (the deadline is not a
// preemption), so a frame goes over its budget by up to one iteration; and at least one iteration
// always runs, so successive frames keep making progress however small the budget. The GPU queue
// cannot be interrupted cheaply: there the budget is turned into an iteration count beforehand
// (iteration_time_predictor.h).
//
// The clock is injectable (a function returning milliseconds) so tests can drive deadlines with a
// fake clock instead of timing real work.
#pragma once

#include <functional>
#include <string>

namespace waxwork {

// Milliseconds since an arbitrary, fixed origin; must not decrease.
using MillisecondClock = std::function<double()>;

// std::chrono::steady_clock in milliseconds: the default clock.
double steady_clock_milliseconds();

struct FrameBudget {
    int max_iterations = 0;       // 0: no iteration limit
    double max_milliseconds = 0;  // 0 or +infinity: no time limit

    // Only an iteration limit (what the int overloads of the per-frame solvers mean).
    static FrameBudget iterations(int count) { return {count, 0}; }
    // A time limit, optionally also capped in iterations.
    static FrameBudget milliseconds(double ms, int max_iterations = 0) { return {max_iterations, ms}; }

    bool limits_iterations() const { return max_iterations > 0; }
    bool limits_time() const;
};

// Throws InvalidArgumentError naming the field: a negative or NaN limit, or neither limit set
// ("frame budget: max_milliseconds is nan (...)").
void validate(const FrameBudget& budget);

// An absolute point in time on a clock, after which a frame should stop starting iterations. Default:
// never expires (and never reads a clock). Cheap to copy.
class FrameDeadline {
public:
    FrameDeadline() = default;
    // `milliseconds` from now on `clock` (empty: steady_clock_milliseconds); 0 or +infinity: never.
    static FrameDeadline after(double milliseconds, MillisecondClock clock = {});
    // The deadline of `budget`'s time limit, started now (never, without one).
    static FrameDeadline of(const FrameBudget& budget, MillisecondClock clock = {});

    bool bounded() const { return bounded_; }
    // Reads the clock (once) unless unbounded.
    bool expired() const;
    // Milliseconds left (<= 0 once expired; +infinity when unbounded). Reads the clock once.
    double remaining() const;
    // A deadline for one of `parts` equal shares of the time left (the first share starts now), e.g.
    // the rgb channels solved one after the other: each channel gets remaining() / parts, and what an
    // early channel leaves over goes to the later ones. Unbounded stays unbounded.
    FrameDeadline share(int parts) const;

private:
    MillisecondClock clock_;
    double end_ = 0;
    bool bounded_ = false;
};

// The largest frame time accepted (a frame of 10 s is no longer live; a larger value is more likely a typo).
constexpr double kMaxFrameMilliseconds = 10000;
// Checks a frame time in ms: finite and in (0, kMaxFrameMilliseconds]. Returns "" when valid, else
// what is wrong (for the option's and the session file's one-line errors).
std::string frame_ms_problem(double milliseconds);

}  // namespace waxwork
