#include "multires/multigrid_frame_cg.h"

#include "base/error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace waxwork {
namespace {

// Refuted claims of convergence after which a solve stops at its precision floor even while each
// refutation still halves the error (the Jacobi CG's limit on residual replacements).
constexpr int kMaxRefutedClaims = 8;
// CG updates between two estimates from recomputed residuals (periodic refreshes) over which a
// healthy solve at least halves the error: fewer say nothing about a floor.
constexpr int kMinUpdatesToHalve = 10;
// A recomputed residual within this of the recursive one (residual_drift) confirms a claim of
// convergence without another V-cycle. The drift is measured in the D^-1 norm, which weighs the
// rounding noise of a float residual more than the estimate's B norm does, so it is no bound, only a
// filter, set from measurements on the GPU: a frame's 1e-2 claim on a well-shaped cube moved r by
// about 6e-4 (and the claim held), a 1e-4 claim on 1e-5 slivers that was 2x off by 1.6e-2.
constexpr double kTrustedResidualDrift = 1e-3;

}  // namespace

MultigridFrameCg::MultigridFrameCg(size_t n, const FrameSolverOptions& options, std::string who)
    : options_(options), n_(n), who_(std::move(who)) {
    if (!(options.relative_tolerance > 0) || options.residual_refresh_interval < 1)
        throw InvalidArgumentError(who_ + ": tolerance must be positive and the refresh interval >= 1");
}

void MultigridFrameCg::check_hierarchy(const MultiresHierarchy& hierarchy) const {
    if (hierarchy.levels.empty() || hierarchy.levels[0].size() != n_)
        throw InvalidArgumentError(who_ + ": the hierarchy was not built for this " + std::to_string(n_) + "-vertex matrix");
    if (!(hierarchy.options == options_.hierarchy))
        throw InvalidArgumentError(who_ + ": the hierarchy was built with other options");
}

void MultigridFrameCg::set_relative_tolerance(double tolerance) {
    if (!(tolerance > 0) || !std::isfinite(tolerance))
        throw InvalidArgumentError(who_ + ": tolerance " + std::to_string(tolerance) + " must be positive");
    options_.relative_tolerance = tolerance;
}

void MultigridFrameCg::forget_refuted_claims() {
    confirming_ = false;
    last_true_estimate_ = std::numeric_limits<double>::infinity();
    updates_since_true_estimate_ = 0;
    refuted_claims_ = 0;
}

bool MultigridFrameCg::stopped_at_floor(const Rgb& estimates) {
    // As the Jacobi CG's confirmation (solver/cg_channel_state.h): an estimate from a recomputed
    // residual that no longer halves the previous one says the updates' precision is spent. After a
    // refuted claim of convergence that holds at once (the Jacobi rule); after a periodic refresh only
    // across enough updates for CG to have halved a healthy error, and then it catches a floor that
    // the channels never all get under together, so no claim is ever made.
    const bool refuted_claim = std::exchange(confirming_, false);
    if (!refuted_claim && updates_since_true_estimate_ < kMinUpdatesToHalve) return false;
    const double error = std::max({estimates[0], estimates[1], estimates[2]});
    const bool stagnating = error > 0.5 * last_true_estimate_;
    last_true_estimate_ = error;
    updates_since_true_estimate_ = 0;
    return stagnating || (refuted_claim && ++refuted_claims_ > kMaxRefutedClaims);
}

void MultigridFrameCg::phi_reset() {
    forget_refuted_claims();
    refresh_ = phi_zero_ = true;
    cg_.restart();
    cg_.forget_eigenvalues(true);
}

void MultigridFrameCg::phi_set() {
    forget_refuted_claims();
    refresh_ = true;
    cg_.restart();
    phi_zero_ = false;
    if (has_b_) refresh_residual();
}

void MultigridFrameCg::right_hand_side_set() {
    forget_refuted_claims();
    has_b_ = true;
    cg_.restart();
}

void MultigridFrameCg::operator_changed() {
    forget_refuted_claims();
    refresh_ = true;
    cg_.restart();
    cg_.forget_eigenvalues(false);  // another operator: earlier estimates do not hold
}

void MultigridFrameCg::copy_changed_rows(const DiffusionMatrix& matrix, std::span<const int32_t> changed_rows,
                                         HierarchyLevel& level0, std::vector<double>* interleaved) const {
    if (matrix.size() != n_ || matrix.columns != level0.columns)
        throw InvalidArgumentError(who_ + " update_values: the matrix pattern changed (rebuild the solver)");
    for (int32_t row : changed_rows) {
        if (row < 0 || static_cast<size_t>(row) >= n_)
            throw InvalidArgumentError(who_ + " update_values: row " + std::to_string(row) + " out of range");
        for (auto k = static_cast<size_t>(matrix.offsets[static_cast<size_t>(row)]);
             k < static_cast<size_t>(matrix.offsets[static_cast<size_t>(row) + 1]); ++k)
            for (size_t c = 0; c < 3; ++c) {
                level0.values[c][k] = matrix.values[c][k];
                if (interleaved) (*interleaved)[3 * k + c] = matrix.values[c][k];
            }
    }
}

double residual_drift(const std::array<double, 6>& sums) {
    double drift = 0;
    for (size_t c = 0; c < 3; ++c) {
        const double moved = sums[c], norm = sums[3 + c];
        if (moved > 0) drift = std::max(drift, norm > 0 ? std::sqrt(moved / norm) : std::numeric_limits<double>::infinity());
    }
    return drift;
}

double MultigridFrameCg::refresh_residual() {
    const double drift = residual_drift(compute_residual(phi_zero_));
    refresh_ = false;
    updates_since_refresh_ = 0;
    return drift;
}

FrameStep MultigridFrameCg::step(int budget) {
    if (!has_b_) throw InvalidArgumentError(who_ + ": step() before set_right_hand_side()");
    if (budget < 1) throw InvalidArgumentError(who_ + ": budget " + std::to_string(budget) + " < 1");
    return step_within(budget, FrameDeadline{});
}

FrameStep MultigridFrameCg::step(const FrameBudget& budget, const MillisecondClock& clock) {
    validate(budget);
    const FrameDeadline deadline = FrameDeadline::of(budget, clock);
    return step_within(budget.limits_iterations() ? budget.max_iterations : std::numeric_limits<int>::max(), deadline);
}

FrameStep MultigridFrameCg::step_within(int budget, const FrameDeadline& deadline) {
    if (!has_b_) throw InvalidArgumentError(who_ + ": step() before set_right_hand_side()");
    FrameStep result;
    if (refresh_) {
        refresh_residual();
        cg_.restart();
    }
    if (cg_.restarting()) cg_.begin_restart();
    // The deadline is read between V-cycles only (one clock read each): the first always runs.
    for (int cycle = 0; cycle < budget && !(cycle > 0 && deadline.expired()); ++cycle) {
        precondition();
        ++result.vcycles;
        const MultigridCgState::StepSums sums = step_sums();
        // The estimate is the true residual's when r was recomputed since the last update.
        const bool from_true_residual = updates_since_refresh_ == 0;
        if (cg_.estimate(sums, options_.relative_tolerance, result.estimated_relative_error, who_)) {
            bool confirmed = from_true_residual || !confirms_convergence();
            if (!confirmed) {
                // Confirm: recompute r = b - M phi. Where it barely moved (kTrustedResidualDrift) the
                // estimate stands; otherwise the next V-cycle's estimate from r decides (and CG goes
                // on from it).
                confirmed = refresh_residual() <= kTrustedResidualDrift;
                cg_.restart_after_refresh();
            }
            confirming_ = !confirmed;
            if (confirmed) {
                result.converged = true;
                break;
            }
            continue;
        }
        if (from_true_residual && stopped_at_floor(result.estimated_relative_error)) {
            result.at_precision_floor = true;
            break;
        }
        ++updates_since_true_estimate_;
        const Rgb beta = cg_.beta(sums);
        set_direction(beta, cg_.restarting());
        const Rgb pq = multiply_direction();
        const Rgb alpha = cg_.alpha(sums, pq, beta, who_);
        phi_zero_ = false;
        update_solution(alpha);
        if (++updates_since_refresh_ >= options_.residual_refresh_interval) {
            // The recursive residual drifts from b - M phi by rounding: recompute it and restart.
            refresh_residual();
            cg_.restart_after_refresh();
        }
    }
    steps_done();
    return result;
}

}  // namespace waxwork
