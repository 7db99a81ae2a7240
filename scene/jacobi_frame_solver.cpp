#include "scene/jacobi_frame_solver.h"

#include "solver/conjugate_gradient.h"

#include <algorithm>

namespace waxwork {

void JacobiFrameSolver::matrix_rebuilt(const TetMesh&, const DiffusionMatrix&, std::span<const int32_t>) {
    eigenvalue_hint_ = {0, 0, 0};
}

FrameResult JacobiFrameSolver::iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                                       std::array<std::vector<double>, 3>& phi, const FrameLimits& limits,
                                       double relative_tolerance, const std::array<bool, 3>& skip) {
    const size_t n = matrix.size();
    FrameResult result;
    auto& out = result.channels;
    int channels_left = static_cast<int>(std::count(skip.begin(), skip.end(), false));
    for (int c = 0; c < 3; ++c) {
        if (skip[c] || n == 0) {
            out[c].converged = true;
            out[c].estimated_relative_error = 0;
            continue;
        }
        ConjugateGradientOptions cg;
        cg.relative_tolerance = relative_tolerance;
        cg.max_iterations = limits.iterations;
        cg.smallest_eigenvalue_hint = eigenvalue_hint_[c];
        // The channels run one after the other: each gets its share of the frame's time left.
        cg.deadline = limits.deadline.share(channels_left--);
        const CsrMatrixView<double> view{n, matrix.offsets.data(), matrix.columns.data(), matrix.values[c].data()};
        const ConjugateGradientResult r = solve_jacobi_cg<double>(view, b[c], phi[c], cg);
        if (r.smallest_eigenvalue_estimate > 0) eigenvalue_hint_[c] = r.smallest_eigenvalue_estimate;
        out[c] = {r.iterations, r.estimated_relative_error, r.converged};
    }
    return result;
}

}  // namespace waxwork
