// The benchmarks' main(): Google Benchmark's, after the allocator policy of the waxwork process
// (base/memory_reuse.h), so that a benchmark measures what the application does. With
// WAXWORK_BENCH_DEFAULT_MALLOC=1 in the environment the policy is left out, to measure what it changes.
#pragma once

#include "base/memory_reuse.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string_view>

#define WAXWORK_BENCHMARK_MAIN()                                             \
    int main(int argc, char** argv) {                                        \
        const char* keep_defaults = std::getenv("WAXWORK_BENCH_DEFAULT_MALLOC"); \
        if (!keep_defaults || std::string_view(keep_defaults) != "1")        \
            waxwork::keep_freed_memory_for_reuse();                          \
        ::benchmark::Initialize(&argc, argv);                                \
        if (::benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;  \
        ::benchmark::RunSpecifiedBenchmarks();                               \
        ::benchmark::Shutdown();                                             \
        return 0;                                                            \
    }
