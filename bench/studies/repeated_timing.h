// Timing a step that varies from run to run on a shared machine (this one's timings move by 10-30%
// between runs, and the first run of a large step in a process also maps every fresh page it touches):
// the median of several runs, with the spread kept for error bands.
#pragma once

#include <functional>
#include <vector>

namespace waxwork {

// Several runs of one step: the statistic reported (`ms`: the median, or the fastest where a caller's
// policy says so) and the fastest and slowest run.
struct RunTimes {
    double ms = 0, min_ms = 0, max_ms = 0;
};

// Runs `run` `runs` times (at least once) and returns the median, fastest and slowest of the times it
// reports, in ms. `run` times itself, so that preparing its input (a fresh copy of a mesh to cut) stays
// outside the measure.
RunTimes repeated_run_ms(int runs, const std::function<double()>& run);

// repeated_run_ms(runs, run).ms.
double median_run_ms(int runs, const std::function<double()>& run);

// The median, min and max of `samples` (in ms; empty gives zeros).
RunTimes median_min_max(std::vector<double> samples);

}  // namespace waxwork
