#include "multires/multigrid_frame_solver.h"

#include "multires/parallel_rows.h"

#include "solver/conjugate_gradient.h"
#include "tetops/error.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace waxwork {
namespace {

constexpr size_t kGrain = 2048;

template <size_t N>
using Sums = std::array<double, N>;

// Fixed chunks and a fixed combination order: bit-identical sums on any thread count.
template <size_t N, typename Body>
Sums<N> reduce_rows(size_t n, const Body& body) {
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<size_t>(0, n, kGrain), Sums<N>{},
        [&](const tbb::blocked_range<size_t>& r, Sums<N> acc) {
            for (size_t i = r.begin(); i != r.end(); ++i) body(i, acc);
            return acc;
        },
        [](Sums<N> a, const Sums<N>& b) {
            for (size_t k = 0; k < N; ++k) a[k] += b[k];
            return a;
        },
        tbb::simple_partitioner());
}

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
    : options_(options), n_(matrix.size()) {
    if (!(options.relative_tolerance > 0) || options.residual_refresh_interval < 1)
        throw InvalidArgumentError("frame solver: tolerance must be positive and the refresh interval >= 1");
    hierarchy_ = std::make_unique<MultiresHierarchy>(build_multires_hierarchy(matrix, positions, options.hierarchy));
    preconditioner_ = std::make_unique<MultigridPreconditioner>(*hierarchy_, options.multigrid);
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

void MultigridFrameSolver::set_relative_tolerance(double tolerance) {
    if (!(tolerance > 0) || !std::isfinite(tolerance))
        throw InvalidArgumentError("frame solver: tolerance " + std::to_string(tolerance) + " must be positive");
    options_.relative_tolerance = tolerance;
}

void MultigridFrameSolver::reset() {
    for (auto& v : phi_) std::fill(v.begin(), v.end(), 0.0);
    refresh_ = phi_zero_ = true;
    cg_.restart();
    cg_.forget_eigenvalues(true);
}

void MultigridFrameSolver::set_phi(const std::array<std::span<const double>, 3>& phi) {
    check_frame_channels(phi, n_, "phi");
    for (size_t c = 0; c < 3; ++c) std::copy(phi[c].begin(), phi[c].end(), phi_[c].begin());
    refresh_ = true;
    cg_.restart();
    phi_zero_ = false;
    if (has_b_) refresh_residual();
}

void MultigridFrameSolver::set_right_hand_side(const std::array<std::span<const double>, 3>& b) {
    check_frame_channels(b, n_, "right-hand side");
    // r = b - M phi changes by exactly the change of b.
    const bool follow = has_b_ && !refresh_;
    for_rows(n_, kGrain, [&](size_t i) {
        for (size_t c = 0; c < 3; ++c) {
            const double value = b[c][i];
            if (follow) r_[3 * i + c] += value - b_[3 * i + c];
            b_[3 * i + c] = value;
        }
    });
    has_b_ = true;
    cg_.restart();
}

void MultigridFrameSolver::refresh_residual() {
    if (phi_zero_) {
        r_ = b_;
        refresh_ = false;
        updates_since_refresh_ = 0;
        return;
    }
    const int32_t* offsets = hierarchy_->levels[0].offsets.data();
    const int32_t* columns = hierarchy_->levels[0].columns.data();
    for_rows(n_, kGrain, [&](size_t i) {
        double s[3] = {0, 0, 0};
        for (int32_t k = offsets[i]; k < offsets[i + 1]; ++k) {
            const double* v = &values_[3 * static_cast<size_t>(k)];
            const auto j = static_cast<size_t>(columns[k]);
            for (size_t c = 0; c < 3; ++c) s[c] += v[c] * phi_[c][j];
        }
        for (size_t c = 0; c < 3; ++c) r_[3 * i + c] = b_[3 * i + c] - s[c];
    });
    refresh_ = false;
    updates_since_refresh_ = 0;
}

FrameStep MultigridFrameSolver::step(int budget) {
    if (!has_b_) throw InvalidArgumentError("frame solver: step() before set_right_hand_side()");
    if (budget < 1) throw InvalidArgumentError("frame solver: budget " + std::to_string(budget) + " < 1");
    return step_within(budget, FrameDeadline{});
}

FrameStep MultigridFrameSolver::step(const FrameBudget& budget, const MillisecondClock& clock) {
    validate(budget);
    const FrameDeadline deadline = FrameDeadline::of(budget, clock);
    return step_within(budget.limits_iterations() ? budget.max_iterations : std::numeric_limits<int>::max(), deadline);
}

FrameStep MultigridFrameSolver::step_within(int budget, const FrameDeadline& deadline) {
    if (!has_b_) throw InvalidArgumentError("frame solver: step() before set_right_hand_side()");
    FrameStep result;
    if (refresh_) {
        refresh_residual();
        cg_.restart();
    }
    if (cg_.restarting()) cg_.begin_restart();
    const int32_t* offsets = hierarchy_->levels[0].offsets.data();
    const int32_t* columns = hierarchy_->levels[0].columns.data();
    // The deadline is read between V-cycles only (one clock read each): the first always runs.
    for (int cycle = 0; cycle < budget && !(cycle > 0 && deadline.expired()); ++cycle) {
        preconditioner_->apply_rgb(r_, z_);
        ++result.vcycles;
        // r . z and phi . M phi = phi . (b - r) per channel.
        const Sums<6> sums = reduce_rows<6>(n_, [&](size_t i, Sums<6>& acc) {
            for (size_t c = 0; c < 3; ++c) {
                const size_t e = 3 * i + c;
                acc[c] += r_[e] * z_[e];
                acc[3 + c] += phi_[c][i] * (b_[e] - r_[e]);
            }
        });
        if (cg_.estimate(sums, options_.relative_tolerance, result.estimated_relative_error, "frame solver")) {
            result.converged = true;
            break;
        }
        // p = z on a restart, else z + beta p (beta = new r.z / old r.z).
        const std::array<double, 3> beta = cg_.beta(sums);
        if (cg_.restarting()) {
            std::swap(p_, z_);  // z is recomputed before it is read again
        } else {
            for_rows(n_, kGrain, [&](size_t i) {
                for (size_t c = 0; c < 3; ++c) p_[3 * i + c] = z_[3 * i + c] + beta[c] * p_[3 * i + c];
            });
        }
        // q = M p and p . q.
        const Sums<3> pq = reduce_rows<3>(n_, [&](size_t i, Sums<3>& acc) {
            double* q = &q_[3 * i];
            product_row(i, offsets, columns, values_.data(), p_.data(), q);
            for (size_t c = 0; c < 3; ++c) acc[c] += p_[3 * i + c] * q[c];
        });
        const std::array<double, 3> alpha = cg_.alpha(sums, pq, beta, "frame solver");
        phi_zero_ = false;
        for_rows(n_, kGrain, [&](size_t i) {
            for (size_t c = 0; c < 3; ++c) {
                const size_t e = 3 * i + c;
                phi_[c][i] += alpha[c] * p_[e];
                r_[e] -= alpha[c] * q_[e];
            }
        });
        if (++updates_since_refresh_ >= options_.residual_refresh_interval) {
            // The recursive residual drifts from b - M phi by rounding: recompute it and restart.
            refresh_residual();
            cg_.restart_after_refresh();
        }
    }
    return result;
}

void MultigridFrameSolver::update_values(const DiffusionMatrix& matrix, std::span<const int32_t> changed_rows) {
    HierarchyLevel& level0 = hierarchy_->levels[0];
    if (matrix.size() != n_ || matrix.columns != level0.columns)
        throw InvalidArgumentError("frame solver update_values: the matrix pattern changed (rebuild the solver)");
    for (int32_t row : changed_rows) {
        if (row < 0 || static_cast<size_t>(row) >= n_)
            throw InvalidArgumentError("frame solver update_values: row " + std::to_string(row) + " out of range");
        for (int32_t k = matrix.offsets[static_cast<size_t>(row)]; k < matrix.offsets[static_cast<size_t>(row) + 1]; ++k)
            for (size_t c = 0; c < 3; ++c) {
                level0.values[c][static_cast<size_t>(k)] = matrix.values[c][static_cast<size_t>(k)];
                values_[3 * static_cast<size_t>(k) + c] = matrix.values[c][static_cast<size_t>(k)];
            }
    }
    preconditioner_->update_values(changed_rows);
    refresh_ = true;
    cg_.restart();
    cg_.forget_eigenvalues(false);  // another operator: earlier estimates do not hold
}

}  // namespace waxwork
