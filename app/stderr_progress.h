// The command line's view of long work: a Progress that shows the running stage on stderr as one
// status line, rewritten in place ("\r") once the stage has run for a second and then every second:
//   waxwork: horse.ply: meshing (TetGen, graded)... 12 s
// and blanked again when the stage ends, so stderr keeps its one-line error on failure and quick runs
// print nothing. A watcher thread does the printing (TetGen and CGAL run for minutes without calling
// back); it never touches signals, so Ctrl-C stops the process as before.
#pragma once

#include "base/progress.h"

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

namespace waxwork {

class StderrProgress : public Progress {
public:
    // `prefix` starts the status line ("waxwork: FILE: ").
    explicit StderrProgress(std::string prefix, double first_seconds = 1.0, double repeat_seconds = 1.0);
    ~StderrProgress() override;  // blanks the status line

    // Ends the current stage without starting another (blanks the status line).
    void finish();

private:
    void on_stage(const std::string& stage) override;
    void end_stage_locked();
    void watch();

    using Clock = std::chrono::steady_clock;
    const std::string prefix_;
    const double first_seconds_;
    const double repeat_seconds_;
    std::mutex mutex_;
    std::condition_variable wake_;
    bool stopping_ = false;
    std::string stage_;
    bool running_ = false;     // a stage is running
    size_t shown_length_ = 0;  // characters of the status line on screen (0: none)
    Clock::time_point stage_start_;
    Clock::time_point next_print_;
    std::thread watcher_;
};

}  // namespace waxwork
