#include "base/progress.h"


namespace waxwork {

void Progress::set_stage(std::string stage) {
    {
        std::lock_guard lock(mutex_);
        stage_ = std::move(stage);
    }
    fraction_.store(-1.0f);
    on_stage(this->stage());
}

std::string Progress::stage() const {
    std::lock_guard lock(mutex_);
    return stage_;
}

void Progress::throw_if_cancelled() const {
    if (cancel_requested()) throw CancelledError("cancelled while " + stage());
}

}  // namespace waxwork
