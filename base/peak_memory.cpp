#include "base/peak_memory.h"

#include <sys/resource.h>

namespace waxwork {

double peak_resident_mib() {
    rusage usage{};
    if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux reports KiB
}

}  // namespace waxwork
