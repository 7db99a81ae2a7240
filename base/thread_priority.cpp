#include "base/thread_priority.h"

#if defined(__linux__)
#include <cerrno>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace waxwork {

bool lower_this_thread_priority() {
#if defined(__linux__)
    // On Linux the nice value belongs to the thread (the kernel's task), so PRIO_PROCESS with the
    // thread's id changes this thread alone (setpriority(2), NOTES).
    const auto thread_id = static_cast<id_t>(syscall(SYS_gettid));
    errno = 0;
    const int current = getpriority(PRIO_PROCESS, thread_id);  // -1 is a valid nice value: errno tells
    if (errno != 0) return false;
    if (current >= kBackgroundNice) return true;  // already as low: raising it back is not ours to do
    return setpriority(PRIO_PROCESS, thread_id, kBackgroundNice) == 0;
#else
    return false;
#endif
}

}  // namespace waxwork
