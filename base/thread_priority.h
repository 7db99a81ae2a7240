// Background work that must not slow down the work someone is watching: the calling thread gives way
// to the process's other threads (the window, the live solve, the software renderer) on a loaded
// machine, and still runs at full speed on an idle one.
#pragma once

namespace waxwork {

// Lowers the scheduling priority of the calling thread only (Linux: its nice value to kBackgroundNice
// unless it is that low already; a no-op elsewhere). Irreversible for an unprivileged process, so call it only on
// a thread that does nothing else afterwards (a BackgroundTask's own thread). Returns whether it took
// effect.
bool lower_this_thread_priority();

inline constexpr int kBackgroundNice = 10;

}  // namespace waxwork
