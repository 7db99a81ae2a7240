#include "solver/iteration_time_predictor.h"

#include "base/error.h"

#include <algorithm>
#include <cmath>

namespace waxwork {

IterationTimePredictor::IterationTimePredictor(double smoothing) : smoothing_(smoothing) {
    if (!(smoothing > 0 && smoothing <= 1))
        throw InvalidArgumentError("iteration time predictor: smoothing " + std::to_string(smoothing) +
                                   " is not in (0, 1]");
}

int IterationTimePredictor::iterations_for(const FrameBudget& budget) const {
    validate(budget);
    const int cap = budget.limits_iterations() ? budget.max_iterations : kMaxPredictedIterations;
    if (!budget.limits_time()) return budget.max_iterations;
    if (!ms_per_iteration_) return budget.limits_iterations() ? cap : std::min(cap, kDefaultFirstFrameIterations);
    // A measured cost of 0 (a clock too coarse for a tiny frame) allows as many as the cap.
    if (*ms_per_iteration_ <= 0) return cap;
    const double fit = std::floor(budget.max_milliseconds / *ms_per_iteration_);
    return static_cast<int>(std::clamp(fit, 1.0, static_cast<double>(cap)));
}

void IterationTimePredictor::record(int iterations, double milliseconds) {
    if (iterations <= 0 || !std::isfinite(milliseconds) || milliseconds < 0) return;
    const double sample = milliseconds / iterations;
    ms_per_iteration_ = ms_per_iteration_ ? (1 - smoothing_) * *ms_per_iteration_ + smoothing_ * sample : sample;
}

}  // namespace waxwork
