// One piece of long work (loading and meshing, a cut, a solve) run off the UI thread so the window
// keeps drawing and answering input. The UI thread starts it, polls it once per frame and never
// waits: the work runs on its own std::thread and hands back a function that the UI thread then runs
// to install the result (the only moment shared editor state changes), or the error it threw.
#pragma once

#include "base/progress.h"

#include <atomic>
#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace waxwork {

// What the work may report while it runs (read by the UI thread): the shared progress type, so that
// the library calls the work makes (meshing, repairs) report their own stages into it.
class TaskProgress : public Progress {};

class BackgroundTask {
public:
    // What the work returns: run on the UI thread by poll() to install the result.
    using Apply = std::function<void()>;
    using Work = std::function<Apply(TaskProgress&)>;

    BackgroundTask() = default;
    ~BackgroundTask();  // requests cancellation and joins: never leaves a thread behind
    BackgroundTask(const BackgroundTask&) = delete;
    BackgroundTask& operator=(const BackgroundTask&) = delete;

    // Starts `work` on a new thread. Throws std::logic_error if a task is still running.
    void start(std::string label, Work work);
    bool busy() const { return thread_.joinable(); }
    // UI thread, once per frame: when the work has finished, joins it and runs its Apply (returns
    // true), or rethrows what the work threw. Returns false while running or when idle.
    bool poll();
    // Blocks until the running work finishes (screenshot mode and shutdown only, never per frame).
    void wait();
    // Asks the work to stop (its TaskProgress's cancel flag); it ends when the work next checks.
    void cancel();
    // cancel() was called for the task started last: an Apply that would install a result the user
    // no longer wants checks this.
    bool cancel_requested() const { return progress_ && progress_->cancel_requested(); }

    const std::string& label() const { return label_; }
    double elapsed_seconds() const;
    const TaskProgress* progress() const { return progress_.get(); }

private:
    std::string label_;
    std::thread thread_;
    std::shared_ptr<TaskProgress> progress_;
    std::shared_ptr<std::atomic<bool>> done_;
    std::shared_ptr<Apply> result_;
    std::shared_ptr<std::exception_ptr> error_;
    std::chrono::steady_clock::time_point started_;
};

}  // namespace waxwork
