#include "editor/background_task.h"

#include <stdexcept>

namespace waxwork {

BackgroundTask::~BackgroundTask() {
    cancel();
    if (thread_.joinable()) thread_.join();
}

void BackgroundTask::start(std::string label, Work work) {
    if (busy()) throw std::logic_error("BackgroundTask::start: '" + label_ + "' is still running");
    label_ = std::move(label);
    progress_ = std::make_shared<TaskProgress>();
    done_ = std::make_shared<std::atomic<bool>>(false);
    result_ = std::make_shared<Apply>();
    error_ = std::make_shared<std::exception_ptr>();
    started_ = std::chrono::steady_clock::now();
    // The thread owns shared copies, so nothing it touches can dangle whatever the UI does meanwhile.
    thread_ = std::thread([work = std::move(work), progress = progress_, done = done_, result = result_,
                           error = error_] {
        try {
            *result = work(*progress);
        } catch (...) {
            *error = std::current_exception();
        }
        done->store(true, std::memory_order_release);
    });
}

bool BackgroundTask::poll() {
    if (!thread_.joinable() || !done_->load(std::memory_order_acquire)) return false;
    thread_.join();
    if (*error_) std::rethrow_exception(*error_);
    if (*result_) (*result_)();
    return true;
}

void BackgroundTask::wait() {
    if (thread_.joinable()) {
        while (!done_->load(std::memory_order_acquire)) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
}

void BackgroundTask::cancel() {
    if (progress_) progress_->request_cancel();
}

double BackgroundTask::elapsed_seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
}

}  // namespace waxwork
