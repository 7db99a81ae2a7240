// How many cores a piece of work kept busy, and how busy the rest of the machine was meanwhile: the
// process's CPU time (every thread's, from getrusage) and the machine's busy time (/proc/stat)
// against the wall clock. A benchmark records both, so a reader can see that "1 thread" used one core
// and that no other program competed for the machine.
#pragma once

#include <chrono>

namespace waxwork {

struct CpuSample {
    std::chrono::steady_clock::time_point wall;
    double process_cpu_s = 0;  // user + system time of every thread of this process so far
    double machine_busy_s = -1;  // all cores' non-idle time since boot (/proc/stat); -1 when unreadable
};

CpuSample sample_cpu_usage();

// Between two samples: the process's CPU seconds per wall second (about 1 for one busy thread), and
// the cores other processes kept busy on average (machine busy time less ours, per wall second; -1
// when /proc/stat is unreadable).
struct CpuUsage {
    double wall_s = 0;
    double process_cpu_s = 0;
    double parallelism = 0;
    double other_load_cores = -1;
};

CpuUsage cpu_usage_between(const CpuSample& start, const CpuSample& end);

}  // namespace waxwork
