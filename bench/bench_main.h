// The benchmarks' main(): Google Benchmark's, after the allocator policy of the waxwork process
// (base/memory_reuse.h), so that a benchmark measures what the application does. With
// WAXWORK_BENCH_DEFAULT_MALLOC=1 in the environment the policy is left out, to measure what it changes.
// `--threads N` (0, the default: every hardware thread) limits every library alike, as `waxwork bench
// --threads` does (bench/studies/thread_limit.h); the JSON of --benchmark_out then records the threads,
// the build (commit, compiler, flags, libraries) and the command line in its "context".
#pragma once

#include "base/memory_reuse.h"
#include "bench/studies/provenance.h"
#include "bench/studies/thread_limit.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <iostream>
#include <string>
#include <string_view>

namespace waxwork {

// Removes "--threads N" or "--threads=N" from argv and returns N (0 when absent); -1 on a bad value.
inline int take_threads_argument(int& argc, char** argv) {
    int threads = 0;
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg(argv[i]);
        std::string value;
        int consumed = 0;
        if (arg == "--threads" && i + 1 < argc) {
            value = argv[i + 1];
            consumed = 2;
        } else if (arg.rfind("--threads=", 0) == 0) {
            value = std::string(arg.substr(10));
            consumed = 1;
        } else {
            continue;
        }
        char* end = nullptr;
        const long n = std::strtol(value.c_str(), &end, 10);
        if (value.empty() || *end != '\0' || n < 0 || n > kMaxBenchThreads) return -1;
        threads = static_cast<int>(n);
        for (int j = i; j + consumed < argc; ++j) argv[j] = argv[j + consumed];
        argc -= consumed;
        --i;
    }
    return threads;
}

inline int run_benchmarks(int argc, char** argv) {
    const char* keep_defaults = std::getenv("WAXWORK_BENCH_DEFAULT_MALLOC");
    if (!keep_defaults || std::string_view(keep_defaults) != "1") keep_freed_memory_for_reuse();
    const std::string command = command_line();
    const int threads = take_threads_argument(argc, argv);
    if (threads < 0) {
        std::cerr << argv[0] << ": --threads expects 0 (every hardware thread) to " << kMaxBenchThreads << "\n";
        return 1;
    }
    const ThreadLimit limit(threads);
    const nlohmann::ordered_json build = build_provenance();
    ::benchmark::AddCustomContext("waxwork_command", command);
    ::benchmark::AddCustomContext("waxwork_threads", std::to_string(limit.threads()));
    ::benchmark::AddCustomContext("waxwork_threads_by_library", limit.libraries().dump());
    ::benchmark::AddCustomContext("waxwork_commit", build.at("commit").get<std::string>());
    ::benchmark::AddCustomContext("waxwork_dirty", build.at("dirty").get<bool>() ? "true" : "false");
    ::benchmark::AddCustomContext("waxwork_compiler", build.at("compiler").get<std::string>());
    ::benchmark::AddCustomContext("waxwork_flags", build.at("flags").get<std::string>());
    ::benchmark::AddCustomContext("waxwork_libraries", build.at("libraries").dump());
    ::benchmark::Initialize(&argc, argv);
    if (::benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    ::benchmark::RunSpecifiedBenchmarks();
    ::benchmark::Shutdown();
    return 0;
}

}  // namespace waxwork

#define WAXWORK_BENCHMARK_MAIN() \
    int main(int argc, char** argv) { return ::waxwork::run_benchmarks(argc, argv); }
