#include "multires/multigrid_frame_solver.h"

#include "base/error.h"
#include "base/parallel_rows.h"
#include "solver/conjugate_gradient.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace waxwork {
namespace {

constexpr size_t kGrain = 2048;

template <size_t N>
using Sums = std::array<double, N>;


// out[c] = (M_c x)_i for the three channels of row i; x interleaved.
inline void product_row(size_t i, const int32_t* offsets, const int32_t* columns, const double* values,
                        const double* x, double out[3]) {
    double s0 = 0, s1 = 0, s2 = 0;
    for (int32_t k = offsets[i]; k < offsets[i + 1]; ++k) {
        const double* v = values + 3 * static_cast<size_t>(k);
        const double* xc = x + 3 * static_cast<size_t>(columns[k]);
        s0 += v[0] * xc[0];
        s1 += v[1] * xc[1];
        s2 += v[2] * xc[2];
    }
    out[0] = s0;
    out[1] = s1;
    out[2] = s2;
}

}  // namespace

MultigridFrameSolver::MultigridFrameSolver(const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                                           const FrameSolverOptions& options)
    : MultigridFrameSolver(matrix, build_multires_hierarchy(matrix, positions, options.hierarchy), options) {}

MultigridFrameSolver::MultigridFrameSolver(const DiffusionMatrix& matrix, MultiresHierarchy hierarchy,
                                           const FrameSolverOptions& options, const MultigridFrameSolver* previous,
                                           std::span<const int32_t> new_of_old_vertex)
    : MultigridFrameCg(matrix.size(), options, "frame solver") {
    check_hierarchy(hierarchy);
    hierarchy_ = std::make_unique<MultiresHierarchy>(std::move(hierarchy));
    preconditioner_ = previous ? std::make_unique<MultigridPreconditioner>(*hierarchy_, previous->preconditioner(),
                                                                           new_of_old_vertex, options.multigrid)
                               : std::make_unique<MultigridPreconditioner>(*hierarchy_, options.multigrid);
    values_.resize(3 * matrix.nonzeros());
    for_rows(matrix.nonzeros(), kGrain, [&](size_t k) {
        for (size_t c = 0; c < 3; ++c) values_[3 * k + c] = matrix.values[c][k];
    });
    for (auto& v : phi_) v.assign(n_, 0.0);
    for (auto* v : {&b_, &r_, &z_, &p_, &q_}) v->assign(3 * n_, 0.0);
}

MultigridFrameSolver::~MultigridFrameSolver() = default;

std::span<const double> MultigridFrameSolver::phi(int channel) const {
    if (channel < 0 || channel > 2)
        throw InvalidArgumentError("frame solver: channel " + std::to_string(channel) + " is not 0, 1 or 2");
    return phi_[static_cast<size_t>(channel)];
}

void MultigridFrameSolver::reset() {
    for (auto& v : phi_) std::fill(v.begin(), v.end(), 0.0);
    phi_reset();
}

void MultigridFrameSolver::set_phi(const std::array<std::span<const double>, 3>& phi) {
    check_frame_channels(phi, n_, "phi");
    for (size_t c = 0; c < 3; ++c) std::copy(phi[c].begin(), phi[c].end(), phi_[c].begin());
    phi_set();
}

void MultigridFrameSolver::set_right_hand_side(const std::array<std::span<const double>, 3>& b) {
    check_frame_channels(b, n_, "right-hand side");
    // r = b - M phi changes by exactly the change of b.
    const bool follow = residual_follows_b();
    for_rows(n_, kGrain, [&](size_t i) {
        for (size_t c = 0; c < 3; ++c) {
            const double value = b[c][i];
            if (follow) r_[3 * i + c] += value - b_[3 * i + c];
            b_[3 * i + c] = value;
        }
    });
    right_hand_side_set();
}

std::array<double, 6> MultigridFrameSolver::compute_residual(bool phi_is_zero) {
    if (phi_is_zero) {
        r_ = b_;
        return {};
    }
    const HierarchyLevel& level0 = hierarchy_->levels[0];
    const int32_t* offsets = level0.offsets.data();
    const int32_t* columns = level0.columns.data();
    return reduce_rows<6>(n_, kGrain, [&](size_t i, Sums<6>& acc) {
        double s[3] = {0, 0, 0};
        for (int32_t k = offsets[i]; k < offsets[i + 1]; ++k) {
            const double* v = &values_[3 * static_cast<size_t>(k)];
            const auto j = static_cast<size_t>(columns[k]);
            for (size_t c = 0; c < 3; ++c) s[c] += v[c] * phi_[c][j];
        }
        const double* diagonal = &values_[3 * static_cast<size_t>(level0.diagonal[i])];
        for (size_t c = 0; c < 3; ++c) {
            const double r = b_[3 * i + c] - s[c], moved = r - r_[3 * i + c];
            acc[c] += moved * moved / diagonal[c];  // residual_drift's sums, in the D^-1 norm
            acc[3 + c] += r * r / diagonal[c];
            r_[3 * i + c] = r;
        }
    });
}

void MultigridFrameSolver::precondition() { preconditioner_->apply_rgb(r_, z_); }

MultigridCgState::StepSums MultigridFrameSolver::step_sums() {
    // r . z and phi . M phi = phi . (b - r) per channel.
    return reduce_rows<6>(n_, kGrain, [&](size_t i, Sums<6>& acc) {
        for (size_t c = 0; c < 3; ++c) {
            const size_t e = 3 * i + c;
            acc[c] += r_[e] * z_[e];
            acc[3 + c] += phi_[c][i] * (b_[e] - r_[e]);
        }
    });
}

void MultigridFrameSolver::set_direction(const Rgb& beta, bool restart) {
    if (restart) {
        std::swap(p_, z_);  // z is recomputed before it is read again
        return;
    }
    for_rows(n_, kGrain, [&](size_t i) {
        for (size_t c = 0; c < 3; ++c) p_[3 * i + c] = z_[3 * i + c] + beta[c] * p_[3 * i + c];
    });
}

MultigridFrameSolver::Rgb MultigridFrameSolver::multiply_direction() {
    // q = M p and p . q.
    const int32_t* offsets = hierarchy_->levels[0].offsets.data();
    const int32_t* columns = hierarchy_->levels[0].columns.data();
    return reduce_rows<3>(n_, kGrain, [&](size_t i, Sums<3>& acc) {
        double* q = &q_[3 * i];
        product_row(i, offsets, columns, values_.data(), p_.data(), q);
        for (size_t c = 0; c < 3; ++c) acc[c] += p_[3 * i + c] * q[c];
    });
}

void MultigridFrameSolver::update_solution(const Rgb& alpha) {
    for_rows(n_, kGrain, [&](size_t i) {
        for (size_t c = 0; c < 3; ++c) {
            const size_t e = 3 * i + c;
            phi_[c][i] += alpha[c] * p_[e];
            r_[e] -= alpha[c] * q_[e];
        }
    });
}

void MultigridFrameSolver::update_values(const DiffusionMatrix& matrix, std::span<const int32_t> changed_rows) {
    copy_changed_rows(matrix, changed_rows, hierarchy_->levels[0], &values_);
    preconditioner_->update_values(changed_rows);
    operator_changed();
}

}  // namespace waxwork
