// ThreadLimit: one thread really runs one thread (CPU time against wall time), more threads run more
// when the machine has them free, the limits end with the object, and bad counts are refused.
#include "bench/studies/thread_limit.h"

#include "base/error.h"
#include "bench/studies/cpu_usage.h"

#include <gtest/gtest.h>
#include <omp.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <thread>

namespace waxwork {
namespace {

// About `seconds` of arithmetic per available thread, spread by TBB over as many threads as it may use.
void busy_parallel_work(double seconds) {
    const auto start = std::chrono::steady_clock::now();
    std::atomic<double> sink{0};
    while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < seconds)
        tbb::parallel_for(0, 64, [&](int i) {
            double x = i;
            for (int k = 0; k < 200000; ++k) x = std::sqrt(x + k);
            sink = sink + x;
        });
}

// The same through OpenMP, as CHOLMOD's loops run (num_threads asks for four).
double omp_parallelism() {
    const CpuSample start = sample_cpu_usage();
    double total = 0;
    for (int repeat = 0; repeat < 5; ++repeat) {
#pragma omp parallel for num_threads(4) reduction(+ : total)
        for (int i = 0; i < 64; ++i) {
            double x = i;
            for (int k = 0; k < 200000; ++k) x = std::sqrt(x + k);
            total += x;
        }
    }
    EXPECT_GT(total, 0);
    return cpu_usage_between(start, sample_cpu_usage()).parallelism;
}

TEST(ThreadLimit, OneThreadRunsOnOneCore) {
    const ThreadLimit limit(1);
    EXPECT_EQ(limit.threads(), 1);
    const CpuSample start = sample_cpu_usage();
    busy_parallel_work(0.4);
    const CpuUsage usage = cpu_usage_between(start, sample_cpu_usage());
    EXPECT_GT(usage.parallelism, 0.5);  // it ran (a busy machine can take some of the core)
    EXPECT_LT(usage.parallelism, 1.1);  // and never on two cores
    EXPECT_LT(omp_parallelism(), 1.1);  // not even where a num_threads clause asks for four
    const auto libraries = limit.libraries();
    for (const char* library : {"tbb", "openmp", "eigen", "llvmpipe"}) EXPECT_EQ(libraries[library], 1) << library;
    EXPECT_STREQ(std::getenv("LP_NUM_THREADS"), "1");
}

TEST(ThreadLimit, TwoThreadsUseTwoCoresWhenTheMachineHasThem) {
    if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one hardware thread";
    const ThreadLimit limit(2);
    const CpuSample start = sample_cpu_usage();
    busy_parallel_work(0.4);
    const CpuUsage usage = cpu_usage_between(start, sample_cpu_usage());
    // Only meaningful on a machine with a core to spare: other tests may be running beside this one.
    if (usage.other_load_cores < 0 || usage.other_load_cores > 0.3)
        GTEST_SKIP() << "the machine was busy (" << usage.other_load_cores << " cores used by others)";
    EXPECT_GT(usage.parallelism, 1.3);
}

TEST(ThreadLimit, LimitsEndWithTheObjectAndBadCountsAreRefused) {
    const size_t before = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    const int omp_levels = omp_get_max_active_levels();
    {
        const ThreadLimit limit(1);
        EXPECT_EQ(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism), 1u);
        EXPECT_EQ(omp_get_max_active_levels(), 0);
    }
    EXPECT_EQ(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism), before);
    EXPECT_EQ(omp_get_max_active_levels(), omp_levels);
    const ThreadLimit all(0);
    EXPECT_EQ(all.threads(), static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
    EXPECT_THROW(ThreadLimit(-1), InvalidArgumentError);
    EXPECT_THROW(ThreadLimit(kMaxBenchThreads + 1), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
