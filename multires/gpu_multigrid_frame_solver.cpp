#include "multires/gpu_multigrid_frame_solver.h"

#include "base/error.h"
#include "base/parallel_rows.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace waxwork {
namespace {

constexpr size_t kResidualGrain = 2048;  // rows per TBB task of the host residual

// The hierarchy, built once the context is known to run compute shaders: a context that cannot fails at
// once instead of after the host setup.
MultiresHierarchy checked_context_hierarchy(const GlApi& gl, const DiffusionMatrix& matrix,
                                            std::span<const Eigen::Vector3d> positions, const HierarchyOptions& options) {
    require_compute_support(gl);
    return build_multires_hierarchy(matrix, positions, options);
}

}  // namespace

GpuMultigridFrameSolver::GpuMultigridFrameSolver(const GlApi& gl, const DiffusionMatrix& matrix,
                                                 std::span<const Eigen::Vector3d> positions,
                                                 const FrameSolverOptions& options)
    : GpuMultigridFrameSolver(gl, matrix, checked_context_hierarchy(gl, matrix, positions, options.hierarchy), options) {}

GpuMultigridFrameSolver::GpuMultigridFrameSolver(const GlApi& gl, const DiffusionMatrix& matrix,
                                                 MultiresHierarchy hierarchy, const FrameSolverOptions& options)
    : GpuMultigridFrameSolver(gl, matrix, MultigridOperators{std::make_unique<MultiresHierarchy>(std::move(hierarchy)), nullptr},
                              options) {}

GpuMultigridFrameSolver::GpuMultigridFrameSolver(const GlApi& gl, const DiffusionMatrix& matrix, MultigridOperators operators,
                                                 const FrameSolverOptions& options)
    : MultigridFrameCg(matrix.size(), options, "GPU frame solver") {
    require_compute_support(gl);
    if (!operators.hierarchy) throw InvalidArgumentError("GPU frame solver: no hierarchy");
    check_hierarchy(*operators.hierarchy);
    if (operators.preconditioner && &operators.preconditioner->hierarchy() != operators.hierarchy.get())
        throw InvalidArgumentError("GPU frame solver: the preconditioner was built on another hierarchy");
    hierarchy_ = std::move(operators.hierarchy);
    preconditioner_ = operators.preconditioner ? std::move(operators.preconditioner)
                                               : std::make_unique<MultigridPreconditioner>(*hierarchy_, options.multigrid);
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

void GpuMultigridFrameSolver::reset() {
    // Written, not scaled by 0: a phi left non-finite by a breakdown must become 0 as well.
    std::fill(staging_.begin(), staging_.end(), 0.0f);
    phi_.write(0, staging_.size() * sizeof(float), staging_.data());
    phi_reset();
}

void GpuMultigridFrameSolver::set_phi(const std::array<std::span<const double>, 3>& phi) {
    check_frame_channels(phi, n_, "phi");
    upload(phi, phi_);
    phi_set();
}

void GpuMultigridFrameSolver::set_right_hand_side(const std::array<std::span<const double>, 3>& b) {
    check_frame_channels(b, n_, "right-hand side");
    if (residual_follows_b()) {
        // r = b - M phi changes by exactly the change of b: r += (b_new - b_old), the difference formed
        // first (scratch = b_new - b_old) so r keeps its own precision.
        upload(b, scratch_);
        kernels_->axpby(n_, {-1, -1, -1}, b_, {1, 1, 1}, scratch_);
        kernels_->axpby(n_, {1, 1, 1}, scratch_, {1, 1, 1}, r_);
    }
    upload(b, b_);
    for (size_t c = 0; c < 3; ++c) host_b_[c].assign(b[c].begin(), b[c].end());
    right_hand_side_set();
}

std::array<double, 6> GpuMultigridFrameSolver::compute_residual(bool phi_is_zero) {
    if (phi_is_zero) {
        r_.copy_from(b_);
        return {};
    }
    // On the host in double from the double level-0 matrix (the header's "Precision"): the device's
    // float copy of M would measure the float system. Read-backs of phi and of the r it replaces (for
    // residual_drift), one upload of r.
    const std::vector<float> phi = phi_.download<float>();
    const std::vector<float> old_r = r_.download<float>();
    const HierarchyLevel& level0 = hierarchy_->levels[0];
    const int32_t* offsets = level0.offsets.data();
    const int32_t* columns = level0.columns.data();
    const std::array<double, 6> sums = reduce_rows<6>(n_, kResidualGrain, [&](size_t i, std::array<double, 6>& acc) {
        const auto diagonal = static_cast<size_t>(level0.diagonal[i]);
        for (size_t c = 0; c < 3; ++c) {
            const double* values = level0.values[c].data();
            double product = 0;
            for (int32_t k = offsets[i]; k < offsets[i + 1]; ++k)
                product += values[k] * static_cast<double>(phi[3 * static_cast<size_t>(columns[k]) + c]);
            const double r = host_b_[c][i] - product, moved = r - static_cast<double>(old_r[3 * i + c]);
            acc[c] += moved * moved / values[diagonal];  // residual_drift's sums, in the D^-1 norm
            acc[3 + c] += r * r / values[diagonal];
            staging_[3 * i + c] = static_cast<float>(r);
        }
    });
    r_.write(0, staging_.size() * sizeof(float), staging_.data());
    return sums;
}

void GpuMultigridFrameSolver::precondition() { device_->apply(r_, z_); }

MultigridCgState::StepSums GpuMultigridFrameSolver::step_sums() {
    return kernels_->rz_and_energy(n_, r_, z_, phi_, b_);  // r . z, phi . (b - r) = phi . M phi
}

void GpuMultigridFrameSolver::set_direction(const Rgb& beta, bool restart) {
    if (restart)
        p_.copy_from(z_);
    else
        kernels_->axpby(n_, {1, 1, 1}, z_, beta, p_);  // p = z + beta p
}

GpuMultigridFrameSolver::Rgb GpuMultigridFrameSolver::multiply_direction() {
    return kernels_->multiply_dot(device_->matrix(0), p_, q_);
}

void GpuMultigridFrameSolver::update_solution(const Rgb& alpha) {
    kernels_->axpby(n_, alpha, p_, {1, 1, 1}, phi_);                        // phi += alpha p
    kernels_->axpby(n_, {-alpha[0], -alpha[1], -alpha[2]}, q_, {1, 1, 1}, r_);  // r -= alpha q
}

void GpuMultigridFrameSolver::steps_done() { check_gpu_error(kernels_->gl(), "multigrid conjugate gradient"); }

void GpuMultigridFrameSolver::update_values(const DiffusionMatrix& matrix, std::span<const int32_t> changed_rows) {
    copy_changed_rows(matrix, changed_rows, hierarchy_->levels[0], nullptr);
    // The CPU preconditioner's update, then the recomputed rows of every level to the device (level 0:
    // the rows of the matrix the CG multiplies with as well).
    device_->update_values(changed_rows);
    operator_changed();
}

}  // namespace waxwork
