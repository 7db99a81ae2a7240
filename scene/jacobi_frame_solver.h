// CPU Jacobi CG (solver/conjugate_gradient.h) in double, one channel after the other: the live
// editor's default method (on spot it is as fast to 1% as the multires solver, live_scene.h), and what
// runs when the multigrid V-cycle cannot be built (live_solver.h).
#pragma once

#include "scene/frame_solver.h"

#include <array>

namespace waxwork {

class JacobiFrameSolver : public FrameSolver {
public:
    // Drops the smallest-eigenvalue hints: they belong to the old matrix (a stale hint can be too
    // optimistic).
    void matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                        std::span<const int32_t> new_of_old_vertex) override;
    // Material changes keep the hints: the stopping rule confirms convergence with the true residual
    // anyway (conjugate_gradient.h).
    void values_changed() override {}
    void rows_changed(std::span<const int32_t>) override {}
    void right_hand_sides_changed() override {}
    void solution_changed() override {}

    // Each channel stops at its share of the frame's time left (remaining / channels left, so a
    // channel that finishes early leaves its time to the next); at least one iteration per channel.
    FrameResult iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                        std::array<std::vector<double>, 3>& phi, const FrameLimits& limits, double relative_tolerance,
                        const std::array<bool, 3>& skip) override;
    std::string description() const override { return "CPU Jacobi CG (double)"; }

private:
    std::array<double, 3> eigenvalue_hint_{};
};

}  // namespace waxwork
