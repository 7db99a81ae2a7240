#include "multires/gpu_multigrid_frame_solver.h"

#include "tetops/error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace waxwork {

GpuMultigridFrameSolver::GpuMultigridFrameSolver(const GlApi& gl, const DiffusionMatrix& matrix,
                                                 std::span<const Eigen::Vector3d> positions,
                                                 const FrameSolverOptions& options)
    : options_(options), n_(matrix.size()) {
    if (!(options.relative_tolerance > 0) || options.residual_refresh_interval < 1)
        throw InvalidArgumentError("frame solver: tolerance must be positive and the refresh interval >= 1");
    require_compute_support(gl);  // before the host setup: a context that cannot run it fails at once
    hierarchy_ = std::make_unique<MultiresHierarchy>(build_multires_hierarchy(matrix, positions, options.hierarchy));
    preconditioner_ = std::make_unique<MultigridPreconditioner>(*hierarchy_, options.multigrid);
    kernels_ = std::make_unique<GpuKernels>(gl, std::initializer_list<GpuMatrixFormat>{GpuMatrixFormat::SellCSigma});
    device_ = std::make_unique<GpuMultigridPreconditioner>(*kernels_, *preconditioner_);
    for (GpuBuffer* v : {&b_, &r_, &z_, &p_, &q_, &phi_, &scratch_}) *v = kernels_->vector(n_);
    staging_.resize(3 * n_);
    check_gpu_error(gl, "setting up the multigrid frame solver");
}

GpuMultigridFrameSolver::~GpuMultigridFrameSolver() = default;

void GpuMultigridFrameSolver::upload(const std::array<std::span<const double>, 3>& v, GpuBuffer& target) {
    for (size_t i = 0; i < n_; ++i)
        for (size_t c = 0; c < 3; ++c) staging_[3 * i + c] = static_cast<float>(v[c][i]);
    target.write(0, staging_.size() * sizeof(float), staging_.data());
}

std::array<std::vector<double>, 3> GpuMultigridFrameSolver::phi() const {
    const std::vector<float> data = phi_.download<float>();
    std::array<std::vector<double>, 3> out;
    for (size_t c = 0; c < 3; ++c) {
        out[c].resize(n_);
        for (size_t i = 0; i < n_; ++i) out[c][i] = data[3 * i + c];
    }
    return out;
}

void GpuMultigridFrameSolver::set_relative_tolerance(double tolerance) {
    if (!(tolerance > 0) || !std::isfinite(tolerance))
        throw InvalidArgumentError("frame solver: tolerance " + std::to_string(tolerance) + " must be positive");
    options_.relative_tolerance = tolerance;
}

void GpuMultigridFrameSolver::reset() {
    // Written, not scaled by 0: a phi left non-finite by a breakdown must become 0 as well.
    std::fill(staging_.begin(), staging_.end(), 0.0f);
    phi_.write(0, staging_.size() * sizeof(float), staging_.data());
    refresh_ = phi_zero_ = true;
    cg_.restart();
    cg_.forget_eigenvalues(true);
}

void GpuMultigridFrameSolver::set_phi(const std::array<std::span<const double>, 3>& phi) {
    check_frame_channels(phi, n_, "phi");
    upload(phi, phi_);
    refresh_ = true;
    cg_.restart();
    phi_zero_ = false;
    if (has_b_) refresh_residual();
}

void GpuMultigridFrameSolver::set_right_hand_side(const std::array<std::span<const double>, 3>& b) {
    check_frame_channels(b, n_, "right-hand side");
    if (has_b_ && !refresh_) {
        // r = b - M phi changes by exactly the change of b: r += (b_new - b_old), the difference formed
        // first (scratch = b_new - b_old) so r keeps its own precision.
        upload(b, scratch_);
        kernels_->axpby(n_, {-1, -1, -1}, b_, {1, 1, 1}, scratch_);
        kernels_->axpby(n_, {1, 1, 1}, scratch_, {1, 1, 1}, r_);
    }
    upload(b, b_);
    has_b_ = true;
    cg_.restart();
}

void GpuMultigridFrameSolver::refresh_residual() {
    if (phi_zero_) {
        r_.copy_from(b_);
    } else {
        // Row sums in double on the device (the z it also writes, D^-1 r, is not used).
        kernels_->residual(device_->matrix(0), b_, phi_, device_->inverse_diagonal(0), r_, scratch_);
    }
    refresh_ = false;
    updates_since_refresh_ = 0;
}

FrameStep GpuMultigridFrameSolver::step(int budget) {
    if (!has_b_) throw InvalidArgumentError("frame solver: step() before set_right_hand_side()");
    if (budget < 1) throw InvalidArgumentError("frame solver: budget " + std::to_string(budget) + " < 1");
    return step_within(budget, FrameDeadline{});
}

FrameStep GpuMultigridFrameSolver::step(const FrameBudget& budget, const MillisecondClock& clock) {
    validate(budget);
    const FrameDeadline deadline = FrameDeadline::of(budget, clock);
    return step_within(budget.limits_iterations() ? budget.max_iterations : std::numeric_limits<int>::max(), deadline);
}

FrameStep GpuMultigridFrameSolver::step_within(int budget, const FrameDeadline& deadline) {
    if (!has_b_) throw InvalidArgumentError("frame solver: step() before set_right_hand_side()");
    FrameStep result;
    if (refresh_) {
        refresh_residual();
        cg_.restart();
    }
    if (cg_.restarting()) cg_.begin_restart();
    GpuKernels& K = *kernels_;
    const GpuMatrix& m = device_->matrix(0);
    // The deadline is read between V-cycles only (one clock read each): the first always runs.
    for (int cycle = 0; cycle < budget && !(cycle > 0 && deadline.expired()); ++cycle) {
        device_->apply(r_, z_);
        ++result.vcycles;
        const MultigridCgState::StepSums sums = K.rz_and_energy(n_, r_, z_, phi_, b_);
        if (cg_.estimate(sums, options_.relative_tolerance, result.estimated_relative_error, "GPU frame solver")) {
            result.converged = true;
            break;
        }
        const std::array<double, 3> beta = cg_.beta(sums);
        if (cg_.restarting())
            p_.copy_from(z_);
        else
            K.axpby(n_, {1, 1, 1}, z_, beta, p_);  // p = z + beta p
        const Rgbd pq = K.multiply_dot(m, p_, q_);
        const std::array<double, 3> alpha = cg_.alpha(sums, pq, beta, "GPU frame solver");
        phi_zero_ = false;
        K.axpby(n_, alpha, p_, {1, 1, 1}, phi_);                        // phi += alpha p
        K.axpby(n_, {-alpha[0], -alpha[1], -alpha[2]}, q_, {1, 1, 1}, r_);  // r -= alpha q
        if (++updates_since_refresh_ >= options_.residual_refresh_interval) {
            // The recursive residual drifts from b - M phi by rounding: recompute it and restart.
            refresh_residual();
            cg_.restart_after_refresh();
        }
    }
    check_gpu_error(K.gl(), "multigrid conjugate gradient");
    return result;
}

void GpuMultigridFrameSolver::update_values(const DiffusionMatrix& matrix, std::span<const int32_t> changed_rows) {
    HierarchyLevel& level0 = hierarchy_->levels[0];
    if (matrix.size() != n_ || matrix.columns != level0.columns)
        throw InvalidArgumentError("frame solver update_values: the matrix pattern changed (rebuild the solver)");
    for (int32_t row : changed_rows) {
        if (row < 0 || static_cast<size_t>(row) >= n_)
            throw InvalidArgumentError("frame solver update_values: row " + std::to_string(row) + " out of range");
        for (int32_t k = matrix.offsets[static_cast<size_t>(row)]; k < matrix.offsets[static_cast<size_t>(row) + 1]; ++k)
            for (size_t c = 0; c < 3; ++c) level0.values[c][static_cast<size_t>(k)] = matrix.values[c][static_cast<size_t>(k)];
    }
    // The CPU preconditioner's update, then the recomputed rows of every level to the device (level 0:
    // the rows of the matrix the CG multiplies with as well).
    device_->update_values(changed_rows);
    refresh_ = true;
    cg_.restart();
    cg_.forget_eigenvalues(false);  // another operator: earlier estimates do not hold
}

}  // namespace waxwork
