#include "bench/studies/repeated_timing.h"

#include <algorithm>
#include <vector>

namespace waxwork {

double median_run_ms(int runs, const std::function<double()>& run) {
    std::vector<double> ms(static_cast<size_t>(std::max(runs, 1)));
    for (double& m : ms) m = run();
    std::sort(ms.begin(), ms.end());
    const size_t half = ms.size() / 2;
    return ms.size() % 2 ? ms[half] : 0.5 * (ms[half - 1] + ms[half]);
}

}  // namespace waxwork
