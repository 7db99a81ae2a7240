#include "scene/gpu_jacobi_frame_solver.h"

#include "scene/jacobi_frame_solver.h"

#include <string>

namespace waxwork {

void GpuJacobiFrameSolver::matrix_rebuilt(const TetMesh&, const DiffusionMatrix&, std::span<const int32_t>) {
    pending_ = PendingChanges{};  // the next device copy takes this matrix; b and phi to send
    context_.free_device_for_new_matrix(device_);
}

FrameResult GpuJacobiFrameSolver::iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                                          std::array<std::vector<double>, 3>& phi, const FrameLimits& limits,
                                          double relative_tolerance, const std::array<bool, 3>& skip) {
    const size_t n = matrix.size();
    FrameResult result;
    if (n == 0 || (skip[0] && skip[1] && skip[2])) {
        result.channels = idle_gpu_frame(n, skip);
        return result;
    }
    SolverGlContext& context = context_.open();
    const CurrentContext current(context);
    const GlApi& gl = context.gl();
    if (context_.make_device(device_, gl, [&] { return std::make_unique<GpuDiffusionSolver>(gl, matrix); })) {
        pending_ = PendingChanges{};  // a new device copy: the current values; b and phi to send
    } else if (pending_.all_values) {
        device_->solver->update_values(matrix);
    } else if (!pending_.rows.empty()) {
        device_->solver->update_rows(matrix, pending_.rows);  // paint: O(changed entries) upload
    }
    pending_.values_applied();
    GpuDiffusionSolver& solver = *device_->solver;
    if (pending_.right_hand_sides) solver.set_right_hand_side(b);
    pending_.right_hand_sides = false;
    auto& staging = device_->staging;
    if (pending_.solution) {
        staging.resize(n);
        for (size_t v = 0; v < n; ++v)
            for (int c = 0; c < 3; ++c) staging[v][c] = phi[c][v];
        solver.set_solution(staging);
    }
    pending_.solution = false;

    GpuCgOptions options;
    options.relative_tolerance = relative_tolerance;
    options.max_iterations = limits.iterations;
    options.use_eigenvalue_hints = true;
    const std::array<ConjugateGradientResult, 3> results = solver.solve(options);
    staging = solver.solution();
    for (size_t v = 0; v < n; ++v)
        for (int c = 0; c < 3; ++c) phi[c][v] = staging[v][c];
    for (int c = 0; c < 3; ++c)
        result.channels[c] = {results[c].iterations, results[c].estimated_relative_error, results[c].converged};
    return result;
}

std::unique_ptr<FrameSolver> GpuJacobiFrameSolver::cpu_successor() { return std::make_unique<JacobiFrameSolver>(); }

}  // namespace waxwork
