// The host-side scalar bookkeeping of the three-channel multigrid-preconditioned CG of the live frame
// solvers (multigrid_frame_solver.h on the CPU, gpu_multigrid_frame_solver.h on the device): the
// error estimate and stopping rule, alpha and beta, and the Lanczos matrix whose smallest Ritz value
// estimates lambda_min(B M). Both backends reduce their vectors to the same per-channel sums (r . z,
// phi . M phi, p . M p) and hand them here, so they stop by exactly the same rule (as
// solver/cg_channel_state.h does for the Jacobi CG loops).
#pragma once

#include "base/error.h"
#include "solver/conjugate_gradient.h"

#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace waxwork {

// The frame solvers' check of three channels given by the caller ("right-hand side", "phi"): throws
// InvalidArgumentError when a channel does not have n entries, AlgorithmError when one is not finite.
inline void check_frame_channels(const std::array<std::span<const double>, 3>& v, size_t n, const std::string& what) {
    for (size_t c = 0; c < 3; ++c) {
        if (v[c].size() != n)
            throw InvalidArgumentError("frame solver: " + what + " of channel " + std::to_string(c) + " has " +
                                       std::to_string(v[c].size()) + " entries for " + std::to_string(n) + " vertices");
        for (double x : v[c])
            if (!std::isfinite(x))
                throw AlgorithmError("frame solver: " + what + " of channel " + std::to_string(c) + " is not finite");
    }
}

class MultigridCgState {
public:
    using Rgb = std::array<double, 3>;
    // The sums after a V-cycle z = B r: r . z per channel, then phi . M phi per channel.
    using StepSums = std::array<double, 6>;

    // The next step starts a new Krylov space (p = z): after a new b, phi or operator, or a refreshed
    // residual.
    void restart() { restart_ = true; }
    bool restarting() const { return restart_; }

    // At the start of a frame that restarts: the Lanczos matrix belongs to the old Krylov space; keep
    // what it said about lambda_min (the smallest seen) and clear it.
    void begin_restart() {
        for (size_t c = 0; c < 3; ++c) {
            if (!t_diag_[c].empty()) fold(c);
            t_diag_[c].clear();
            t_off_[c].clear();
        }
    }
    // After the periodic residual refresh: the same, and the next step restarts.
    void restart_after_refresh() {
        restart_ = true;
        for (size_t c = 0; c < 3; ++c) {
            fold(c);
            t_diag_[c].clear();
            t_off_[c].clear();
        }
    }
    // Forgets the eigenvalue estimates of earlier restarts (another operator), and with `clear_lanczos`
    // the current Lanczos matrix too (phi = 0: a new solve).
    void forget_eigenvalues(bool clear_lanczos) {
        for (size_t c = 0; c < 3; ++c) {
            if (clear_lanczos) {
                t_diag_[c].clear();
                t_off_[c].clear();
            }
            lambda_floor_[c] = 0;
        }
    }

    // The energy-norm estimate ||phi* - phi||_M / ||phi||_M <= sqrt((r . z) / lambda_min(B M) /
    // (phi . M phi)) per channel into `estimates`; true when every channel is within `tolerance`.
    // Throws AlgorithmError (prefixed by `who`) on non-finite sums or r . z < 0 (B not positive).
    bool estimate(const StepSums& sums, double tolerance, Rgb& estimates, const std::string& who) const {
        bool all_converged = true;
        for (size_t c = 0; c < 3; ++c) {
            const double rz = sums[c], xmx = sums[3 + c];
            if (!std::isfinite(rz) || !std::isfinite(xmx)) throw AlgorithmError(who + ": the iterate became non-finite");
            if (rz < 0)
                throw AlgorithmError(who + ": r.Br = " + std::to_string(rz) + " (preconditioner not positive definite)");
            const double lambda = smallest_eigenvalue(c);
            double value = std::numeric_limits<double>::infinity();
            if (rz == 0)
                value = 0;
            else if (xmx > 0 && std::isfinite(lambda))
                value = std::sqrt(rz / lambda / xmx);
            estimates[c] = value;
            all_converged = all_converged && value <= tolerance;
        }
        return all_converged;
    }

    // beta per channel for p = z + beta p (0 on a restart or a channel solved exactly).
    Rgb beta(const StepSums& sums) const {
        Rgb out{};
        for (size_t c = 0; c < 3; ++c) out[c] = restart_ || rz_[c] == 0 ? 0.0 : sums[c] / rz_[c];
        return out;
    }

    // alpha per channel from r . z and p . M p (0 for a channel with r . z = 0: it is solved exactly and
    // left alone), recording the Lanczos coefficients of B M (Saad, Iterative Methods, Sec. 6.7.3).
    // Ends the restart. Throws AlgorithmError when p . M p is not positive (M not positive definite).
    Rgb alpha(const StepSums& sums, const Rgb& pq, const Rgb& beta, const std::string& who) {
        Rgb out{};
        for (size_t c = 0; c < 3; ++c) {
            const double rz = sums[c];
            if (rz == 0) continue;
            if (!(pq[c] > 0) || !std::isfinite(pq[c]))
                throw AlgorithmError(who + ": p.Mp = " + std::to_string(pq[c]) + " (matrix not positive definite)");
            out[c] = rz / pq[c];
            const bool first = restart_ || t_diag_[c].empty();
            t_diag_[c].push_back(1.0 / out[c] + (first ? 0.0 : beta_prev_[c] / alpha_prev_[c]));
            if (!first) t_off_[c].push_back(std::sqrt(beta_prev_[c]) / alpha_prev_[c]);
            alpha_prev_[c] = out[c];
            rz_[c] = rz;
        }
        beta_prev_ = beta;
        restart_ = false;
        return out;
    }

    double smallest_eigenvalue(size_t c) const {
        double lambda = lambda_floor_[c] > 0 ? lambda_floor_[c] : std::numeric_limits<double>::infinity();
        if (!t_diag_[c].empty()) lambda = std::min(lambda, smallest_tridiagonal_eigenvalue(t_diag_[c], t_off_[c]));
        return lambda;
    }

private:
    void fold(size_t c) {
        const double ritz = smallest_tridiagonal_eigenvalue(t_diag_[c], t_off_[c]);
        lambda_floor_[c] = lambda_floor_[c] > 0 ? std::min(lambda_floor_[c], ritz) : ritz;
    }

    bool restart_ = true;
    Rgb rz_{}, alpha_prev_{}, beta_prev_{};
    std::array<std::vector<double>, 3> t_diag_, t_off_;  // Lanczos matrix since the last restart
    Rgb lambda_floor_{};                                  // smallest Ritz value of earlier restarts
};

}  // namespace waxwork
