// The number of threads every library in a measurement may use, so that a comparison runs each
// solver on the same count. Waxwork's solvers run on oneTBB; CHOLMOD's supernodal factorisation on
// OpenMP (libgomp) and on the BLAS it calls; llvmpipe's rasteriser and compute shaders on a thread pool
// of its own sized by LP_NUM_THREADS, which it reads when the first OpenGL context is made; Eigen's
// sparse solvers are sequential (Waxwork is compiled without -fopenmp, so Eigen has no threads).
#pragma once

#include <tbb/global_control.h>

#include <nlohmann/json.hpp>

#include <memory>

namespace waxwork {

// The largest --threads value accepted.
inline constexpr int kMaxBenchThreads = 1024;

class ThreadLimit {
public:
    // threads >= 1, or 0 for every hardware thread; throws InvalidArgumentError otherwise. Make it
    // before the OpenGL context (llvmpipe sizes its pool once). The TBB and OpenMP limits last as long
    // as the object; LP_NUM_THREADS stays set in the process environment.
    explicit ThreadLimit(int threads);
    ~ThreadLimit();
    ThreadLimit(const ThreadLimit&) = delete;
    ThreadLimit& operator=(const ThreadLimit&) = delete;

    // The count in force (the hardware's for 0).
    int threads() const { return threads_; }

    // What each library was allowed: {"tbb", "openmp", "cholmod_openmp_loops", "blas", "blas_library",
    // "eigen", "llvmpipe"}. CHOLMOD's OpenMP loops ask for a thread count fixed when SuiteSparse was
    // built (num_threads clauses), which only a limit of one (no parallel regions) overrides; the BLAS
    // is reported by the library the process loaded.
    nlohmann::ordered_json libraries() const;

private:
    int threads_ = 1;
    std::unique_ptr<tbb::global_control> tbb_limit_;
    int previous_omp_threads_ = 1;
    int previous_omp_levels_ = 1;
};

// The BLAS library this process loaded (its path from /proc/self/maps), or "" when none is loaded.
std::string loaded_blas_library();

}  // namespace waxwork
