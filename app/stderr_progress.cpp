#include "app/stderr_progress.h"

#include <algorithm>
#include <cmath>
#include <iostream>

namespace waxwork {

namespace {

std::chrono::steady_clock::duration seconds(double s) {
    return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

StderrProgress::StderrProgress(std::string prefix, double first_seconds, double repeat_seconds)
    : prefix_(std::move(prefix)), first_seconds_(first_seconds), repeat_seconds_(repeat_seconds) {
    watcher_ = std::thread([this] { watch(); });
}

StderrProgress::~StderrProgress() {
    {
        std::lock_guard lock(mutex_);
        end_stage_locked();
        stopping_ = true;
    }
    wake_.notify_all();
    watcher_.join();
}

void StderrProgress::finish() {
    std::lock_guard lock(mutex_);
    end_stage_locked();
}

void StderrProgress::on_stage(const std::string& stage) {
    {
        std::lock_guard lock(mutex_);
        stage_ = stage;
        running_ = true;
        stage_start_ = Clock::now();
        // A line already shown is rewritten at once with the new stage; otherwise after a second.
        next_print_ = shown_length_ > 0 ? stage_start_ : stage_start_ + seconds(first_seconds_);
    }
    wake_.notify_all();
}

void StderrProgress::end_stage_locked() {
    // Blank the status line so that whatever is printed next starts on a clean line.
    if (shown_length_ > 0) std::cerr << '\r' << std::string(shown_length_, ' ') << '\r' << std::flush;
    shown_length_ = 0;
    running_ = false;
}

void StderrProgress::watch() {
    std::unique_lock lock(mutex_);
    while (!stopping_) {
        if (!running_) {
            wake_.wait(lock);
            continue;
        }
        if (Clock::now() < next_print_) {
            wake_.wait_until(lock, next_print_);
            continue;
        }
        const double elapsed = std::chrono::duration<double>(Clock::now() - stage_start_).count();
        std::string line = prefix_ + stage_ + "... " + std::to_string(static_cast<long>(std::floor(elapsed))) + " s";
        const size_t length = line.size();
        if (length < shown_length_) line += std::string(shown_length_ - length, ' ');
        std::cerr << '\r' << line << std::flush;
        shown_length_ = std::max(length, shown_length_);
        next_print_ = Clock::now() + seconds(repeat_seconds_);
    }
}

}  // namespace waxwork
