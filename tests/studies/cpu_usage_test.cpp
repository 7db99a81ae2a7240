// cpu_usage: a busy thread counts as one core, a sleeping one as none.
#include "bench/studies/cpu_usage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <thread>

namespace waxwork {
namespace {

TEST(CpuUsage, ABusyThreadIsOneCoreAndASleepingOneNone) {
    CpuSample start = sample_cpu_usage();
    volatile double x = 0;
    while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start.wall).count() < 0.3)
        x = x + std::sqrt(static_cast<double>(x) + 1.0);
    CpuUsage busy = cpu_usage_between(start, sample_cpu_usage());
    EXPECT_GE(busy.wall_s, 0.3);
    EXPECT_GT(busy.parallelism, 0.5);  // a loaded machine can take some of the core
    EXPECT_LT(busy.parallelism, 1.1);

    start = sample_cpu_usage();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    const CpuUsage idle = cpu_usage_between(start, sample_cpu_usage());
    EXPECT_LT(idle.parallelism, 0.2);
    EXPECT_GE(idle.other_load_cores, 0.0);  // /proc/stat is readable here
}

}  // namespace
}  // namespace waxwork
