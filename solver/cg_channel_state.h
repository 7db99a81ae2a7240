// The per-channel bookkeeping of the rgb Jacobi CG loops (the CPU float path in diffusion_solve.cpp
// and the GPU path in gpu_conjugate_gradient.cpp): the stopping rule of conjugate_gradient.h on the
// estimated relative error, with the Lanczos tridiagonal matrix whose smallest Ritz value estimates
// lambda_min. Shared so both backends stop by exactly the same rule.
#pragma once

#include "solver/conjugate_gradient.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace waxwork {

struct CgChannelState {
    bool active = true;
    double rz = 0, xnorm2 = 0;
    std::vector<double> t_diag, t_off;
    double ritz = std::numeric_limits<double>::infinity();
    bool ritz_stale = true;
    double ritz_floor = std::numeric_limits<double>::infinity();
    double alpha_prev = 0, beta_prev = 0;
    double last_restart_estimate = std::numeric_limits<double>::infinity();
    ConjugateGradientResult result;

    double lambda() {
        if (ritz_stale && !t_diag.empty()) {
            ritz = smallest_tridiagonal_eigenvalue(t_diag, t_off, std::isfinite(ritz) ? ritz : 0);
            ritz_stale = false;
        }
        return std::min(ritz, ritz_floor);
    }
    double estimate(double rz_value, double lam) const {
        if (xnorm2 <= 0) return std::numeric_limits<double>::infinity();
        return std::sqrt(std::max(rz_value, 0.0)) / lam / std::sqrt(xnorm2);
    }
    // After an iteration with step alpha: records the Lanczos coefficients (Saad, Iterative Methods,
    // Sec. 6.7.3), takes the new r . z and x . D x, and returns beta.
    double record_step(double alpha, double rz_new, double xnorm2_new) {
        xnorm2 = xnorm2_new;
        const double beta = rz_new / rz;
        t_diag.push_back(1.0 / alpha + (t_diag.empty() ? 0.0 : beta_prev / alpha_prev));
        if (t_diag.size() > 1) t_off.push_back(std::sqrt(beta_prev) / alpha_prev);
        ritz_stale = true;
        alpha_prev = alpha;
        beta_prev = beta;
        rz = rz_new;
        return beta;
    }
    // The error estimate after iteration k: cheap with the last Ritz value (an over-estimate of
    // lambda_min, so an under-estimate of the error), refreshed only when the cheap test passes, at the
    // first iteration, or when `refresh` asks. Sets `lam` to the eigenvalue used.
    double current_estimate(int k, double tolerance, bool refresh, double& lam) {
        lam = std::min(ritz, ritz_floor);
        double est = estimate(rz, std::isfinite(lam) ? lam : t_diag.front());
        if (est <= tolerance || k == 0 || refresh) {
            lam = lambda();
            est = estimate(rz, lam);
        }
        return est;
    }
    // Whether an estimate at or under the tolerance after iteration k may stop a system of `unknowns`.
    // A Ritz value from one or two Lanczos steps can lie arbitrarily far above lambda_min (one step gives
    // the Rayleigh quotient of the first search direction), so without a floor from the caller or an
    // earlier restart the estimate stops nothing before kTrustedLanczosSteps, or before the Krylov space
    // is the whole space. A single tet 1e-3 degrees flat stopped after one iteration with three of its
    // four vertices at 3e-5 of their value (ConjugateGradient.FewLanczosStepsDoNotStopAColdSolve); cold solves
    // of real meshes take tens of iterations, so this costs them nothing.
    static constexpr int kTrustedLanczosSteps = 3;
    bool may_stop(int k, size_t unknowns) const {
        return std::isfinite(ritz_floor) || k + 1 >= kTrustedLanczosSteps || static_cast<size_t>(k + 1) >= unknowns;
    }
    // The true residual confirmed or refuted convergence (est_true with the same lam). Returns true
    // when the channel stops (converged, or restarts stopped halving the error: the precision floor);
    // otherwise prepares a restart from the true residual (the caller sets p = z).
    bool confirm(int k, double rz_true, double est_true, double lam, double tolerance) {
        if (est_true <= tolerance) {
            result.converged = true;
            result.estimated_relative_error = est_true;
            result.iterations = k + 1;
            active = false;
            return true;
        }
        ++result.residual_replacements;
        const bool stagnating = est_true > 0.5 * last_restart_estimate;
        last_restart_estimate = est_true;
        result.estimated_relative_error = est_true;
        if (stagnating || result.residual_replacements > 8) {
            result.iterations = k + 1;
            active = false;
            return true;
        }
        rz = rz_true;
        ritz_floor = lam;
        t_diag.clear();
        t_off.clear();
        ritz = std::numeric_limits<double>::infinity();
        return false;
    }
    // At the end of a solve: fills iterations/error for a channel that ran out of iterations, and the
    // eigenvalue estimate.
    ConjugateGradientResult finish(int k) {
        if (active) {
            result.iterations = k;
            result.estimated_relative_error = estimate(rz, lambda());
        }
        if (!t_diag.empty() || std::isfinite(ritz_floor)) result.smallest_eigenvalue_estimate = lambda();
        return result;
    }
};

}  // namespace waxwork
