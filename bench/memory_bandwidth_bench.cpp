// STREAM-like memory bandwidth (McCalpin's copy and triad kernels) on one and two threads: the
// machine's ceiling for the rebuild phases, whose roofline docs/performance.md derives from it.
//
// Arrays of 2^23 doubles (64 MiB each, far beyond any cache) are split into one contiguous block per
// thread, so every thread streams its own pages. Bytes are counted as STREAM counts them: copy reads
// one array and writes one (16 bytes per element), triad reads two and writes one (24 bytes); the
// write-allocate read of the destination is not counted, as in STREAM.
#include "bench_main.h"

#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <benchmark/benchmark.h>

#include <cstddef>
#include <vector>

namespace waxwork {
namespace {

constexpr size_t kElements = size_t{1} << 23;

struct StreamArrays {
    std::vector<double> a, b, c;
    StreamArrays() : a(kElements, 1.0), b(kElements, 2.0), c(kElements, 0.5) {}
};

StreamArrays& arrays() {
    static StreamArrays s;
    return s;
}

// Runs body(begin, end) over [0, kElements) in `threads` equal contiguous blocks, one per thread.
template <typename Body>
void run_blocks(tbb::task_arena& arena, int threads, const Body& body) {
    arena.execute([&] {
        tbb::parallel_for(0, threads, 1, [&](int k) {
            const size_t begin = kElements * static_cast<size_t>(k) / static_cast<size_t>(threads);
            const size_t end = kElements * static_cast<size_t>(k + 1) / static_cast<size_t>(threads);
            body(begin, end);
        }, tbb::static_partitioner());
    });
}

void report(benchmark::State& state, double bytes_per_iteration) {
    state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * bytes_per_iteration));
    state.counters["threads"] = static_cast<double>(state.range(0));
    state.counters["MB"] = bytes_per_iteration / 1e6;
}

void BM_StreamCopy(benchmark::State& state) {
    const int threads = static_cast<int>(state.range(0));
    tbb::task_arena arena(threads);
    StreamArrays& s = arrays();
    for (auto _ : state) {
        run_blocks(arena, threads, [&](size_t begin, size_t end) {
            for (size_t i = begin; i < end; ++i) s.b[i] = s.a[i];
        });
        benchmark::DoNotOptimize(s.b.data());
        benchmark::ClobberMemory();
    }
    report(state, 2.0 * sizeof(double) * kElements);
}
BENCHMARK(BM_StreamCopy)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_StreamTriad(benchmark::State& state) {
    const int threads = static_cast<int>(state.range(0));
    tbb::task_arena arena(threads);
    StreamArrays& s = arrays();
    const double scalar = 3.0;
    for (auto _ : state) {
        run_blocks(arena, threads, [&](size_t begin, size_t end) {
            for (size_t i = begin; i < end; ++i) s.a[i] = s.b[i] + scalar * s.c[i];
        });
        benchmark::DoNotOptimize(s.a.data());
        benchmark::ClobberMemory();
    }
    report(state, 3.0 * sizeof(double) * kElements);
}
BENCHMARK(BM_StreamTriad)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace waxwork

WAXWORK_BENCHMARK_MAIN()
