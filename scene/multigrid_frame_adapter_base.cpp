#include "scene/multigrid_frame_adapter_base.h"

#include <utility>

namespace waxwork {

MultigridFrameAdapterBase::MultigridFrameAdapterBase(const MultigridOptions& options,
                                                     std::vector<Eigen::Vector3d> positions,
                                                     MultigridOperators waiting, const std::array<double, 3>& error)
    : options_(options), positions_(std::move(positions)), waiting_(std::move(waiting)), error_(error) {}

void MultigridFrameAdapterBase::values_changed() {
    forget_estimates();
    pending_.values_changed();
    waiting_ = MultigridOperators{};  // old values at level 0: the solver is built afresh
}

void MultigridFrameAdapterBase::rows_changed(std::span<const int32_t> rows) {
    forget_estimates();
    waiting_ = MultigridOperators{};  // old values at level 0: the solver is built afresh
    if (has_solver()) pending_.rows_changed(rows);
}

void MultigridFrameAdapterBase::right_hand_sides_changed() {
    pending_.right_hand_sides = true;
    forget_estimates();
}

void MultigridFrameAdapterBase::solution_changed() {
    pending_.solution = true;
    forget_estimates();
}

}  // namespace waxwork
