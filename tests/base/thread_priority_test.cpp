// lower_this_thread_priority lowers the calling thread's priority and no other thread's.
#include "base/thread_priority.h"

#include <gtest/gtest.h>

#include <thread>

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace waxwork {
namespace {

#if defined(__linux__)
int this_thread_nice() { return getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid))); }

TEST(ThreadPriority, LowersTheCallingThreadAlone) {
    const int before = this_thread_nice();
    if (before >= kBackgroundNice) GTEST_SKIP() << "the test runs at nice " << before << " already";
    int in_thread = before;
    bool lowered = false;
    std::thread worker([&] {
        lowered = lower_this_thread_priority();
        in_thread = this_thread_nice();
    });
    worker.join();
    EXPECT_TRUE(lowered);
    EXPECT_EQ(in_thread, kBackgroundNice);
    EXPECT_EQ(this_thread_nice(), before);  // the caller of the thread keeps its priority
}
#endif

}  // namespace
}  // namespace waxwork
