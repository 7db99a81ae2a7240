#include "bench/studies/thread_limit.h"

#include "base/error.h"

#include <dlfcn.h>
#include <omp.h>

#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

namespace waxwork {
namespace {

int hardware_threads() { return std::max(1, static_cast<int>(std::thread::hardware_concurrency())); }

// OpenBLAS and BLIS size their own pools; the reference BLAS has none. Reached through dlsym because
// which BLAS the process loads is the system's choice (Debian's alternatives), not the build's.
void limit_blas_threads(int threads) {
    using SetThreads = void (*)(int);
    for (const char* name : {"openblas_set_num_threads", "bli_thread_set_num_threads"})
        if (auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, name))) set(threads);
}

}  // namespace

std::string loaded_blas_library() {
    std::ifstream maps("/proc/self/maps");
    std::string line;
    while (std::getline(maps, line)) {
        const size_t slash = line.find('/');
        if (slash == std::string::npos) continue;
        const std::string path = line.substr(slash);
        const std::string file = path.substr(path.rfind('/') + 1);
        if (file.find("blas") != std::string::npos || file.find("blis") != std::string::npos ||
            file.find("libmkl") != std::string::npos)
            return path;
    }
    return "";
}

ThreadLimit::ThreadLimit(int threads) {
    if (threads < 0 || threads > kMaxBenchThreads)
        throw InvalidArgumentError("--threads " + std::to_string(threads) + ": expected 1.." +
                                   std::to_string(kMaxBenchThreads) + ", or 0 for every hardware thread");
    threads_ = threads == 0 ? hardware_threads() : threads;
    tbb_limit_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                       static_cast<size_t>(threads_));
    previous_omp_threads_ = omp_get_max_threads();
    previous_omp_levels_ = omp_get_max_active_levels();
    omp_set_num_threads(threads_);
    // A num_threads clause overrides omp_set_num_threads; no active level at all does not.
    omp_set_max_active_levels(threads_ == 1 ? 0 : previous_omp_levels_);
    limit_blas_threads(threads_);
    setenv("LP_NUM_THREADS", std::to_string(threads_).c_str(), 1);
}

ThreadLimit::~ThreadLimit() {
    omp_set_num_threads(previous_omp_threads_);
    omp_set_max_active_levels(previous_omp_levels_);
    limit_blas_threads(hardware_threads());
}

nlohmann::ordered_json ThreadLimit::libraries() const {
    const std::string blas = loaded_blas_library();
    const bool reference_blas = blas.find("openblas") == std::string::npos && blas.find("blis") == std::string::npos &&
                                blas.find("mkl") == std::string::npos;
    return {{"tbb", threads_},
            {"openmp", threads_},
            {"cholmod_openmp_loops", threads_ == 1 ? "1" : "fixed by the SuiteSparse build (num_threads clauses)"},
            {"blas", reference_blas ? 1 : threads_},
            {"blas_library", blas.empty() ? "not loaded" : blas},
            {"eigen", 1},
            {"llvmpipe", threads_}};
}

}  // namespace waxwork
