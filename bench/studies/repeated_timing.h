// Timing a step that varies from run to run on a shared machine (this one's timings move by 10-30%
// between runs, and the first run of a large step in a process also maps every fresh page it touches):
// the median of several runs.
#pragma once

#include <functional>

namespace waxwork {

// Runs `run` `runs` times (at least once) and returns the median of the times it reports, in ms. `run`
// times itself, so that preparing its input (a fresh copy of a mesh to cut) stays outside the measure.
double median_run_ms(int runs, const std::function<double()>& run);

}  // namespace waxwork
