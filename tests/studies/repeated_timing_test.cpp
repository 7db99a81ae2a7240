// median_run_ms and median_min_max (bench/studies/repeated_timing.h): the median of the times the runs
// report, every run made, and the spread.
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

TEST(RepeatedTiming, MedianMinAndMaxOfSamples) {
    const RunTimes odd = median_min_max({30, 10, 400});
    EXPECT_EQ(odd.ms, 30);
    EXPECT_EQ(odd.min_ms, 10);
    EXPECT_EQ(odd.max_ms, 400);
    const RunTimes even = median_min_max({8, 2, 4, 100});
    EXPECT_EQ(even.ms, 6);
    EXPECT_EQ(even.min_ms, 2);
    EXPECT_EQ(even.max_ms, 100);
    const RunTimes none = median_min_max({});
    EXPECT_EQ(none.ms, 0);
    EXPECT_EQ(none.max_ms, 0);
}

}  // namespace
}  // namespace waxwork
