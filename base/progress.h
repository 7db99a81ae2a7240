// Progress of long work (reading and repairing a surface, meshing it, a solve): the code doing the work
// names the stage it is in and may give a fraction done; whoever started it shows that (the command
// line on stderr, the editor in its status bar) and may ask it to stop. No I/O here: the front ends
// decide what is printed or drawn.
#pragma once

#include "base/error.h"

#include <atomic>
#include <mutex>
#include <string>

namespace waxwork {

// Work stopped because whoever started it asked it to (Progress::request_cancel).
class CancelledError : public Error {
public:
    using Error::Error;
};

class Progress {
public:
    Progress() = default;
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;
    virtual ~Progress() = default;

    // Names the stage now running ("repairing (filling holes)", "meshing (TetGen)"); may be called
    // from any thread. The fraction goes back to unknown.
    void set_stage(std::string stage);
    std::string stage() const;
    // Fraction of the current stage in [0, 1]; negative: unknown.
    void set_fraction(float fraction) { fraction_.store(fraction); }
    float fraction() const { return fraction_.load(); }

    // Cooperative cancellation: the work checks it between steps (throw_if_cancelled) and libraries
    // that poll a flag get it directly (cancel_flag: CGAL Mesh_3's stop flag).
    bool cancel_requested() const { return cancel_.load(); }
    void request_cancel() { cancel_.store(true); }
    std::atomic<bool>* cancel_flag() { return &cancel_; }
    // Throws CancelledError naming the stage when cancellation was requested.
    void throw_if_cancelled() const;

protected:
    // Called by set_stage after the stage is stored (a printer starts its clock here).
    virtual void on_stage(const std::string& /*stage*/) {}

private:
    std::atomic<float> fraction_{-1.0f};
    std::atomic<bool> cancel_{false};
    mutable std::mutex mutex_;
    std::string stage_;
};

// set_stage on `progress` when there is one: the library calls take an optional Progress*.
inline void report_stage(Progress* progress, std::string stage) {
    if (progress) progress->set_stage(std::move(stage));
}

// throw_if_cancelled on `progress` when there is one.
inline void check_cancelled(const Progress* progress) {
    if (progress) progress->throw_if_cancelled();
}

}  // namespace waxwork
