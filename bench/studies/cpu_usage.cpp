#include "bench/studies/cpu_usage.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

namespace waxwork {
namespace {

double seconds(const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); }

// The first line of /proc/stat: "cpu user nice system idle iowait irq softirq steal ..." in clock ticks.
double machine_busy_seconds() {
    std::ifstream stat("/proc/stat");
    std::string line;
    if (!std::getline(stat, line) || line.rfind("cpu ", 0) != 0) return -1;
    std::istringstream fields(line.substr(4));
    double user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0, softirq = 0, steal = 0;
    if (!(fields >> user >> nice >> system >> idle >> iowait >> irq >> softirq)) return -1;
    fields >> steal;  // absent on old kernels
    const long ticks = sysconf(_SC_CLK_TCK);
    if (ticks <= 0) return -1;
    return (user + nice + system + irq + softirq + steal) / static_cast<double>(ticks);
}

}  // namespace

CpuSample sample_cpu_usage() {
    CpuSample sample;
    sample.wall = std::chrono::steady_clock::now();
    rusage usage{};
    if (getrusage(RUSAGE_SELF, &usage) == 0) sample.process_cpu_s = seconds(usage.ru_utime) + seconds(usage.ru_stime);
    sample.machine_busy_s = machine_busy_seconds();
    return sample;
}

CpuUsage cpu_usage_between(const CpuSample& start, const CpuSample& end) {
    CpuUsage usage;
    usage.wall_s = std::chrono::duration<double>(end.wall - start.wall).count();
    usage.process_cpu_s = end.process_cpu_s - start.process_cpu_s;
    if (usage.wall_s <= 0) return usage;
    usage.parallelism = usage.process_cpu_s / usage.wall_s;
    if (start.machine_busy_s >= 0 && end.machine_busy_s >= 0)
        usage.other_load_cores =
            std::max(0.0, (end.machine_busy_s - start.machine_busy_s - usage.process_cpu_s) / usage.wall_s);
    return usage;
}

}  // namespace waxwork
