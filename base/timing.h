// Wall-clock time for reports and frame budgets.
#pragma once

#include <chrono>

namespace waxwork {

// Milliseconds of steady (monotonic) clock since `start`.
inline double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace waxwork
