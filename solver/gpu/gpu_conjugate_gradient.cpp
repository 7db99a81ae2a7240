#include "solver/gpu/gpu_conjugate_gradient.h"

#include "base/error.h"
#include "solver/cg_channel_state.h"

#include <cmath>
#include <limits>
#include <string>

namespace waxwork {
namespace {

[[noreturn]] void breakdown(int iteration, const std::string& what) {
    throw AlgorithmError("GPU conjugate gradient: " + what + " at iteration " + std::to_string(iteration) +
                         " (matrix not positive definite, or values lost to rounding: degenerate tets?)");
}

std::vector<float> interleave(const std::vector<std::array<double, 3>>& v) {
    std::vector<float> out(3 * v.size());
    for (size_t i = 0; i < v.size(); ++i)
        for (int c = 0; c < 3; ++c) out[3 * i + c] = static_cast<float>(v[i][c]);
    return out;
}

}  // namespace

GpuDiffusionSolver::GpuDiffusionSolver(const GlApi& gl, const DiffusionMatrix& matrix, GpuMatrixFormat format)
    : kernels_(gl, {format}), matrix_(gl, rgb_csr_view(matrix), format) {
    const size_t n = matrix.size();
    for (GpuBuffer* v : {&b_, &x_, &r_, &z_, &p_, &q_, &diag_, &inv_diag_}) *v = kernels_.vector(n);
    kernels_.extract_diagonal(matrix_, diag_, inv_diag_);
    check_gpu_error(gl, "uploading the diffusion matrix");
}

void GpuDiffusionSolver::update_values(const DiffusionMatrix& matrix) {
    if (matrix.size() != size() || matrix.nonzeros() != matrix_.layout.stored_index.size())
        throw InvalidArgumentError("GPU solver: update_values needs the matrix of the same pattern");
    const std::vector<float> values = gpu_matrix_values(matrix_.layout, rgb_csr_view(matrix));
    matrix_.values.write(0, values.size() * sizeof(float), values.data());
    kernels_.extract_diagonal(matrix_, diag_, inv_diag_);
}

void GpuDiffusionSolver::update_rows(const DiffusionMatrix& matrix, std::span<const int32_t> rows) {
    if (matrix.size() != size() || matrix.nonzeros() != matrix_.layout.stored_index.size())
        throw InvalidArgumentError("GPU solver: update_rows needs the matrix of the same pattern");
    // Stored positions and new values of the rows' entries, scattered by one dispatch: works for every
    // format (ELL/SELL scatter a row's entries across the buffer).
    std::vector<int32_t> slots;
    std::vector<float> values;
    for (int32_t row : rows) {
        if (row < 0 || static_cast<size_t>(row) >= size())
            throw InvalidArgumentError("GPU solver: update_rows: row " + std::to_string(row) + " out of range");
        for (int32_t k = matrix.offsets[row]; k < matrix.offsets[row + 1]; ++k) {
            slots.push_back(matrix_.layout.stored_index[k]);
            for (int c = 0; c < 3; ++c) values.push_back(static_cast<float>(matrix.values[c][k]));
        }
    }
    if (slots.empty()) return;
    const GlApi& gl = kernels_.gl();
    const GpuBuffer slot_buffer = GpuBuffer::from<int32_t>(gl, slots);
    const GpuBuffer value_buffer = GpuBuffer::from<float>(gl, values);
    kernels_.scatter(slots.size(), slot_buffer, value_buffer, matrix_.values);
    // The Jacobi preconditioner of every row (a cheap O(n) pass) rather than a second scatter.
    kernels_.extract_diagonal(matrix_, diag_, inv_diag_);
}

void GpuDiffusionSolver::set_light(const DiffusionMatrix& matrix, const std::vector<std::array<double, 3>>& q) {
    if (matrix.size() != size() || q.size() != size())
        throw InvalidArgumentError("GPU solver: set_light: " + std::to_string(q.size()) + " light values for " +
                                   std::to_string(size()) + " vertices");
    std::array<std::vector<double>, 3> b;
    for (int c = 0; c < 3; ++c) {
        b[c].resize(size());
        diffusion_right_hand_side(matrix, q, c, b[c]);
    }
    set_right_hand_side(b);
}

void GpuDiffusionSolver::set_right_hand_side(const std::array<std::vector<double>, 3>& b) {
    for (const auto& channel : b)
        if (channel.size() != size())
            throw InvalidArgumentError("GPU solver: right-hand side of size " + std::to_string(channel.size()) +
                                       " for " + std::to_string(size()) + " vertices");
    std::vector<float> data(3 * size());
    for (size_t i = 0; i < size(); ++i)
        for (int c = 0; c < 3; ++c) data[3 * i + c] = static_cast<float>(b[c][i]);
    b_.write(0, data.size() * sizeof(float), data.data());
}

void GpuDiffusionSolver::set_solution(const std::vector<std::array<double, 3>>& phi) {
    if (phi.size() != size())
        throw InvalidArgumentError("GPU solver: set_solution: " + std::to_string(phi.size()) + " values for " +
                                   std::to_string(size()) + " vertices");
    const std::vector<float> data = interleave(phi);
    x_.write(0, data.size() * sizeof(float), data.data());
}

std::vector<std::array<double, 3>> GpuDiffusionSolver::solution() const {
    const std::vector<float> data = x_.download<float>();
    std::vector<std::array<double, 3>> phi(size());
    for (size_t i = 0; i < size(); ++i)
        for (int c = 0; c < 3; ++c) phi[i][c] = data[3 * i + c];
    return phi;
}

std::array<ConjugateGradientResult, 3> GpuDiffusionSolver::solve(const GpuCgOptions& options) {
    if (!(options.relative_tolerance > 0) || options.max_iterations < 0)
        throw InvalidArgumentError("GPU conjugate gradient: tolerance must be positive and max_iterations non-negative");
    const size_t n = size();
    const double tol = options.relative_tolerance;
    std::array<CgChannelState, 3> ch;
    std::array<ConjugateGradientResult, 3> results;
    if (n == 0) {
        for (auto& r : results) r.converged = true;
        return results;
    }
    GpuKernels& K = kernels_;
    const Rgbd rz0 = K.residual(matrix_, b_, x_, inv_diag_, r_, z_);
    const Rgbd bnorm2 = K.dot(n, b_, b_, inv_diag_);
    const Rgbd xnorm2 = K.dot(n, x_, x_, diag_);
    Rgbd keep{1, 1, 1};
    for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(rz0[c]) || !std::isfinite(bnorm2[c]) || !std::isfinite(xnorm2[c]))
            throw AlgorithmError("GPU conjugate gradient: right-hand side or start vector is not finite");
        ch[c].rz = rz0[c];
        ch[c].xnorm2 = xnorm2[c];
        if (bnorm2[c] == 0) {  // the solution is exactly zero
            keep[c] = 0;
            ch[c].active = false;
            ch[c].result.converged = true;
            continue;
        }
        const double hint = options.use_eigenvalue_hints ? eigenvalue_hints_[c] : 0;
        if (hint > 0 && std::isfinite(hint)) {
            ch[c].ritz_floor = hint;
            const double est = ch[c].estimate(ch[c].rz, hint);
            if (est <= tol) {  // the warm start is already good enough
                ch[c].active = false;
                ch[c].result.converged = true;
                ch[c].result.estimated_relative_error = est;
            }
        }
    }
    if (keep != Rgbd{1, 1, 1}) K.axpby(n, {0, 0, 0}, x_, keep, x_);
    p_.copy_from(z_);

    int k = 0;
    for (; k < options.max_iterations && (ch[0].active || ch[1].active || ch[2].active); ++k) {
        const std::array<bool, 3> act = {ch[0].active, ch[1].active, ch[2].active};
        const Rgbd pq = K.multiply_dot(matrix_, p_, q_);
        Rgbd alpha{};
        for (int c = 0; c < 3; ++c) {
            if (!act[c]) continue;
            if (!std::isfinite(pq[c])) breakdown(k, "p.Mp is not finite");
            if (!(pq[c] > 0)) breakdown(k, "p.Mp = " + std::to_string(pq[c]) + " is not positive");
            alpha[c] = ch[c].rz / pq[c];
        }
        const std::array<double, 6> upd = K.cg_update(n, alpha, p_, q_, diag_, inv_diag_, x_, r_, z_);
        // p = z + beta p per channel: (a, b) = (1, beta) to continue, (1, 0) to restart, (0, 1) frozen.
        Rgbd pa{0, 0, 0}, pb{1, 1, 1};
        Rgbd errors{};
        std::array<bool, 3> confirm{};
        std::array<double, 3> lams{};
        for (int c = 0; c < 3; ++c) {
            if (!act[c]) continue;
            CgChannelState& st = ch[c];
            if (!std::isfinite(upd[2 * c]) || !std::isfinite(upd[2 * c + 1])) breakdown(k, "the iterate became non-finite");
            const double beta = st.record_step(alpha[c], upd[2 * c], upd[2 * c + 1]);
            const double est = st.current_estimate(k, tol, static_cast<bool>(options.on_iteration), lams[c]);
            errors[c] = est;
            if (est <= tol && st.may_stop(k, n)) {
                confirm[c] = true;
            } else {
                st.result.estimated_relative_error = est;
                pa[c] = 1;
                pb[c] = beta;
            }
        }
        if (confirm[0] || confirm[1] || confirm[2]) {
            // Confirm with the true residual (r and z replaced for the confirming channels only).
            const Rgbd rz_true = K.residual(matrix_, b_, x_, inv_diag_, r_, z_, confirm);
            for (int c = 0; c < 3; ++c) {
                if (!confirm[c]) continue;
                if (!std::isfinite(rz_true[c])) breakdown(k, "the true residual is not finite");
                const double est_true = ch[c].estimate(rz_true[c], lams[c]);
                errors[c] = est_true;
                if (!ch[c].confirm(k, rz_true[c], est_true, lams[c], tol)) {
                    pa[c] = 1;  // restart from the true residual: p = z
                    pb[c] = 0;
                }
            }
        }
        if (pa != Rgbd{0, 0, 0}) K.axpby(n, pa, z_, pb, p_);
        if (options.on_iteration) options.on_iteration(k + 1, errors);
    }
    for (int c = 0; c < 3; ++c) {
        results[c] = ch[c].finish(k);
        if (results[c].smallest_eigenvalue_estimate > 0) eigenvalue_hints_[c] = results[c].smallest_eigenvalue_estimate;
    }
    check_gpu_error(kernels_.gl(), "conjugate gradient");
    return results;
}

bool GpuDiffusionSolver::solve_frame(int iteration_budget, double relative_tolerance) {
    GpuCgOptions options;
    options.relative_tolerance = relative_tolerance;
    options.max_iterations = iteration_budget;
    options.use_eigenvalue_hints = true;
    const auto results = solve(options);
    return results[0].converged && results[1].converged && results[2].converged;
}

std::array<ConjugateGradientResult, 3> solve_diffusion_gpu(const GlApi& gl, const DiffusionMatrix& matrix,
                                                           const std::vector<std::array<double, 3>>& q,
                                                           const GpuCgOptions& options,
                                                           std::vector<std::array<double, 3>>& phi,
                                                           GpuMatrixFormat format) {
    GpuDiffusionSolver solver(gl, matrix, format);
    solver.set_light(matrix, q);
    if (phi.size() == matrix.size()) solver.set_solution(phi);
    const auto results = solver.solve(options);
    phi = solver.solution();
    return results;
}

}  // namespace waxwork
