// What the CPU and the GPU multigrid frame adapters (multigrid_frame_adapter.h,
// gpu_multigrid_frame_adapter.h) keep between frames, and how a change of the live system reaches it:
// both run multigrid_frame.h on operators built for the current matrix, so a change invalidates the
// same things in both (the last estimates, operators built for old values, the solver's pending
// record). After a GPU fallback the CPU adapter takes over this state as it stood (cpu_successor).
#pragma once

#include "multires/multigrid_preconditioner.h"
#include "scene/frame_solver.h"
#include "scene/pending_changes.h"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace waxwork {

class MultigridFrameAdapterBase : public FrameSolver {
public:
    void values_changed() override;
    void rows_changed(std::span<const int32_t> rows) override;
    void right_hand_sides_changed() override;
    void solution_changed() override;

protected:
    explicit MultigridFrameAdapterBase(const MultigridOptions& options) : options_(options) {}
    MultigridFrameAdapterBase(const MultigridOptions& options, std::vector<Eigen::Vector3d> positions,
                              MultigridOperators waiting, const std::array<double, 3>& error);

    // Whether a solver exists for pending_ to reach (one built later takes the current values).
    virtual bool has_solver() const = 0;
    void forget_estimates() { error_ = {1, 1, 1}; }

    MultigridOptions options_;
    // The mesh's rest positions (the hierarchy's Eq. 16 weights), kept for a solver built at a later
    // frame; empty otherwise.
    std::vector<Eigen::Vector3d> positions_;
    // After an edit with a vertex map: the hierarchy and preconditioner rebuilt around the edit, for a
    // solver built at a later frame. Empty otherwise, and after painting (stale values).
    MultigridOperators waiting_;
    PendingChanges pending_;                // the solver's: values, b, and phi as a warm start
    std::array<double, 3> error_{1, 1, 1};  // the last frame's estimates (1 after a change)
};

}  // namespace waxwork
