#include "bench/studies/repeated_timing.h"

#include <algorithm>

namespace waxwork {

RunTimes median_min_max(std::vector<double> samples) {
    if (samples.empty()) return {};
    std::sort(samples.begin(), samples.end());
    const size_t half = samples.size() / 2;
    const double median = samples.size() % 2 ? samples[half] : 0.5 * (samples[half - 1] + samples[half]);
    return {median, samples.front(), samples.back()};
}

RunTimes repeated_run_ms(int runs, const std::function<double()>& run) {
    std::vector<double> ms(static_cast<size_t>(std::max(runs, 1)));
    for (double& m : ms) m = run();
    return median_min_max(std::move(ms));
}

double median_run_ms(int runs, const std::function<double()>& run) { return repeated_run_ms(runs, run).ms; }

}  // namespace waxwork
