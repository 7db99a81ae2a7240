// median_run_ms (bench/studies/repeated_timing.h): the median of the times the runs report, every run made.
#include "bench/studies/repeated_timing.h"

#include <gtest/gtest.h>

#include <functional>
#include <vector>

namespace waxwork {
namespace {

// A run that reports the next of `times` and counts its calls.
struct ScriptedRuns {
    std::vector<double> times;
    size_t calls = 0;
    double operator()() { return times.at(calls++); }
};

TEST(RepeatedTiming, MedianOfTheReportedTimesAfterEveryRun) {
    ScriptedRuns odd{{30, 10, 400}};
    EXPECT_EQ(median_run_ms(3, std::ref(odd)), 30);  // the outlier (a first touch, say) is left out
    EXPECT_EQ(odd.calls, 3u);
    ScriptedRuns even{{8, 2, 4, 100}};
    EXPECT_EQ(median_run_ms(4, std::ref(even)), 6);
    EXPECT_EQ(even.calls, 4u);
    ScriptedRuns once{{7, 1}};
    EXPECT_EQ(median_run_ms(0, std::ref(once)), 7);  // at least one run
    EXPECT_EQ(once.calls, 1u);
}

}  // namespace
}  // namespace waxwork
