// Jacobi-preconditioned conjugate gradients on the GPU (OpenGL 4.3 compute shaders), float, for the
// three rgb diffusion systems at once, with the matrix and vectors resident on the device between
// frames. Same algorithm and stopping rule as the CPU float path (conjugate_gradient.h,
// diffusion_solve.cpp; the rule is shared through cg_channel_state.h): the estimated relative error
// ||phi - x||_D / ||x||_D from r . D^-1 r and the smallest Ritz value, confirmed with the true residual
// (row sums in double on the device) before a channel stops.
//
// Per iteration: 3 dispatches (q = M p with p . q; the fused x/r/z update with r . z and x . D x;
// p = z + beta p) and 2 small read-backs of reduction partials (the scalars alpha and beta, and the
// Lanczos bookkeeping, stay on the host, as on the CPU).
#pragma once

#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "solver/gpu/gpu_kernels.h"
#include "solver/gpu/gpu_matrix.h"

#include <array>
#include <functional>
#include <optional>
#include <span>
#include <vector>

namespace waxwork {

struct GpuCgOptions {
    double relative_tolerance = 1e-3;  // on the estimated relative error, per channel
    int max_iterations = 10000;
    // Start from the previous solve's lambda_min estimates (per channel): a warm-started frame can then
    // stop at once when its start is already good enough (conjugate_gradient.h, smallest_eigenvalue_hint).
    bool use_eigenvalue_hints = false;
    // Called after every iteration with the estimated error per channel (0 for stopped channels); the
    // estimate is then refreshed every iteration. For convergence curves (e.g. `waxwork bench solvers`).
    std::function<void(int iteration, const Rgbd& estimated_relative_error)> on_iteration;
};

// The persistent GPU state of one volume's diffusion system. SELL-C-sigma by default: the fastest
// product on llvmpipe (bench/gpu_solver_bench.cpp) and the coalesced layout GPUs want; CSR is kept for
// comparison, ELL pads spot's matrix 2.6-3x.
class GpuDiffusionSolver {
public:
    // Uploads the pattern and values of `matrix` and compiles the kernels. The OpenGL context of `gl`
    // (>= 4.3) must stay current while the solver lives. Throws GpuError when the driver cannot run it.
    GpuDiffusionSolver(const GlApi& gl, const DiffusionMatrix& matrix,
                       GpuMatrixFormat format = GpuMatrixFormat::SellCSigma);

    size_t size() const { return matrix_.layout.rows; }

    // After assemble_diffusion_values (same pattern): re-uploads all values.
    void update_values(const DiffusionMatrix& matrix);
    // After update_diffusion_matrix: uploads only `rows` (its return value), O(their entries).
    void update_rows(const DiffusionMatrix& matrix, std::span<const int32_t> rows);
    // After the values were rewritten on the device (gpu_assembly.h writes into matrix()): refreshes
    // the Jacobi preconditioner from the new diagonal.
    void values_changed_on_device() { kernels_.extract_diagonal(matrix_, diag_, inv_diag_); }
    // b = source q (Eq. 12) for the three channels, uploaded.
    void set_light(const DiffusionMatrix& matrix, const std::vector<std::array<double, 3>>& q);
    // b per channel, directly.
    void set_right_hand_side(const std::array<std::vector<double>, 3>& b);
    // The warm start (any finite values); the solver otherwise keeps the previous solution.
    void set_solution(const std::vector<std::array<double, 3>>& phi);

    // Runs CG from the resident solution. Throws AlgorithmError on breakdown (as the CPU solver) and
    // GpuError on an OpenGL error; non-convergence is reported in the results, not thrown.
    std::array<ConjugateGradientResult, 3> solve(const GpuCgOptions& options);
    // The per-frame mode: at most `iteration_budget` iterations from the previous frame's solution,
    // with its eigenvalue estimates. Returns whether every channel reached the tolerance.
    bool solve_frame(int iteration_budget, double relative_tolerance);

    std::vector<std::array<double, 3>> solution() const;
    // phi on the device, 3 floats per vertex (rgb): what a renderer on the same context reads.
    const GpuBuffer& solution_buffer() const { return x_; }
    // Writable, for a start vector computed on the device (multires interpolation).
    GpuBuffer& solution_buffer() { return x_; }
    const GpuBuffer& right_hand_side_buffer() const { return b_; }
    const GpuMatrix& matrix() const { return matrix_; }
    // Writable values for a device assembly; call values_changed_on_device() afterwards.
    GpuMatrix& matrix() { return matrix_; }
    GpuKernels& kernels() { return kernels_; }

private:
    GpuKernels kernels_;
    GpuMatrix matrix_;
    GpuBuffer b_, x_, r_, z_, p_, q_, diag_, inv_diag_;
    Rgbd eigenvalue_hints_{};
};

// The GPU solve as one call, for benchmarks and `waxwork bench solvers` curves: uploads `matrix`,
// b = source q, and runs CG (options.on_iteration sees every iteration). phi: the warm start when it
// has the matrix size (else zeros), and the solution on return.
std::array<ConjugateGradientResult, 3> solve_diffusion_gpu(const GlApi& gl, const DiffusionMatrix& matrix,
                                                           const std::vector<std::array<double, 3>>& q,
                                                           const GpuCgOptions& options,
                                                           std::vector<std::array<double, 3>>& phi,
                                                           GpuMatrixFormat format = GpuMatrixFormat::SellCSigma);

}  // namespace waxwork
