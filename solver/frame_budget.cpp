#include "solver/frame_budget.h"

#include "base/error.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

namespace waxwork {

double steady_clock_milliseconds() {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool FrameBudget::limits_time() const { return max_milliseconds > 0 && std::isfinite(max_milliseconds); }

void validate(const FrameBudget& budget) {
    if (budget.max_iterations < 0)
        throw InvalidArgumentError("frame budget: max_iterations is " + std::to_string(budget.max_iterations) +
                                   " (must be >= 0; 0 = no iteration limit)");
    if (std::isnan(budget.max_milliseconds) || budget.max_milliseconds < 0) {
        std::ostringstream msg;
        msg << "frame budget: max_milliseconds is " << budget.max_milliseconds
            << " (must be >= 0; 0 or infinity = no time limit)";
        throw InvalidArgumentError(msg.str());
    }
    if (!budget.limits_iterations() && !budget.limits_time())
        throw InvalidArgumentError(
            "frame budget: neither max_iterations nor max_milliseconds is set (a frame needs at least one limit)");
}

FrameDeadline FrameDeadline::after(double milliseconds, MillisecondClock clock) {
    FrameDeadline deadline;
    if (!(milliseconds > 0) || !std::isfinite(milliseconds)) return deadline;
    deadline.clock_ = clock ? std::move(clock) : MillisecondClock(steady_clock_milliseconds);
    deadline.end_ = deadline.clock_() + milliseconds;
    deadline.bounded_ = true;
    return deadline;
}

FrameDeadline FrameDeadline::of(const FrameBudget& budget, MillisecondClock clock) {
    return budget.limits_time() ? after(budget.max_milliseconds, std::move(clock)) : FrameDeadline{};
}

bool FrameDeadline::expired() const { return bounded_ && clock_() >= end_; }

double FrameDeadline::remaining() const {
    return bounded_ ? end_ - clock_() : std::numeric_limits<double>::infinity();
}

FrameDeadline FrameDeadline::share(int parts) const {
    if (!bounded_) return *this;
    FrameDeadline part = *this;
    const double now = clock_();
    const double left = end_ - now;
    // One part, or no time left (an expired deadline stays expired): the share is the whole deadline.
    if (left > 0 && parts > 1) part.end_ = now + left / parts;
    return part;
}

std::string frame_ms_problem(double milliseconds) {
    if (!std::isfinite(milliseconds) || milliseconds <= 0 || milliseconds > kMaxFrameMilliseconds) {
        std::ostringstream msg;
        msg << "must be a time in milliseconds in (0, " << kMaxFrameMilliseconds << "]";
        return msg.str();
    }
    return "";
}

}  // namespace waxwork
