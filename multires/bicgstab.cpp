#include "multires/bicgstab.h"

#include "base/parallel_rows.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace waxwork {

const char* to_string(BicgstabStatus status) {
    switch (status) {
        case BicgstabStatus::Converged: return "converged";
        case BicgstabStatus::IterationLimit: return "iteration limit";
        case BicgstabStatus::RhoBreakdown: return "rho breakdown";
        case BicgstabStatus::OmegaBreakdown: return "omega breakdown";
        case BicgstabStatus::Stagnation: return "stagnation";
        case BicgstabStatus::Divergence: return "divergence";
        case BicgstabStatus::NonFinite: return "non-finite value";
    }
    return "unknown";
}

namespace {

constexpr size_t kGrain = 4096;

// Deterministic (base/parallel_rows.h): the sum's rounding does not depend on scheduling.
double dot(std::span<const double> a, std::span<const double> b) {
    return sum_rows(a.size(), kGrain, [&](size_t i) { return a[i] * b[i]; });
}

double true_residual(const CsrMatrixView<double>& a, std::span<const double> b, std::span<const double> x,
                     std::vector<double>& r) {
    multiply<double>(a, x, r);
    for_rows(r.size(), kGrain, [&](size_t i) { r[i] = b[i] - r[i]; });
    return std::sqrt(dot(r, r));
}

bool tiny(double inner, double norm_product, double tolerance) {
    return !(std::abs(inner) > tolerance * norm_product);  // also true for NaN
}

}  // namespace

BicgstabResult solve_jacobi_bicgstab(const CsrMatrixView<double>& a, std::span<const int32_t> diagonal,
                                     std::span<const double> b, std::span<double> x, const BicgstabOptions& options) {
    const size_t n = a.rows;
    BicgstabResult result;
    std::vector<double> x0(x.begin(), x.end());
    std::vector<double> r(n), r0(n), p(n, 0.0), v(n, 0.0), y(n), s(n), z(n), t(n), inv_d(n);
    for (size_t i = 0; i < n; ++i) {
        const double d = a.values[diagonal[i]];
        inv_d[i] = (std::isfinite(d) && d != 0) ? 1.0 / d : 1.0;
    }
    const double b_norm = std::sqrt(dot(b, b));
    if (!std::isfinite(b_norm)) {
        std::fill(x.begin(), x.end(), 0.0);
        result.status = BicgstabStatus::NonFinite;
        return result;
    }
    if (b_norm == 0) {  // the solution is zero
        std::fill(x.begin(), x.end(), 0.0);
        return result;
    }
    bool start_finite = true;
    for (double xi : x) start_finite = start_finite && std::isfinite(xi);
    if (!start_finite) {
        std::fill(x.begin(), x.end(), 0.0);
        std::fill(x0.begin(), x0.end(), 0.0);
    }
    double r_norm = true_residual(a, b, x, r);
    const double initial = r_norm;
    result.initial_relative_residual = initial / b_norm;
    if (!std::isfinite(r_norm)) {  // the matrix itself holds non-finite values
        std::copy(x0.begin(), x0.end(), x.begin());
        result.status = BicgstabStatus::NonFinite;
        result.relative_residual = result.initial_relative_residual;
        result.reverted = true;
        return result;
    }
    const double target = options.relative_tolerance * b_norm;
    std::copy(r.begin(), r.end(), r0.begin());
    const double r0_norm = r_norm;
    double rho = 1, alpha = 1, omega = 1;
    double best = r_norm;
    int best_iteration = 0;
    result.status = BicgstabStatus::IterationLimit;
    if (r_norm <= target) result.status = BicgstabStatus::Converged;
    for (int k = 0; k < options.max_iterations && r_norm > target; ++k) {
        const double rho_new = dot(r0, r);
        if (tiny(rho_new, r0_norm * r_norm, options.breakdown_tolerance)) {
            result.status = std::isfinite(rho_new) ? BicgstabStatus::RhoBreakdown : BicgstabStatus::NonFinite;
            break;
        }
        const double beta = (rho_new / rho) * (alpha / omega);
        rho = rho_new;
        for_rows(n, kGrain, [&](size_t i) {
            p[i] = r[i] + beta * (p[i] - omega * v[i]);
            y[i] = inv_d[i] * p[i];
        });
        multiply<double>(a, y, v);
        const double r0v = dot(r0, v);
        if (tiny(r0v, r0_norm * std::sqrt(dot(v, v)), options.breakdown_tolerance)) {
            result.status = std::isfinite(r0v) ? BicgstabStatus::RhoBreakdown : BicgstabStatus::NonFinite;
            break;
        }
        alpha = rho / r0v;
        for_rows(n, kGrain, [&](size_t i) {
            s[i] = r[i] - alpha * v[i];
            z[i] = inv_d[i] * s[i];
        });
        result.iterations = k + 1;
        const double s_norm = std::sqrt(dot(s, s));
        if (s_norm <= target) {  // the half step already converged
            for_rows(n, kGrain, [&](size_t i) { x[i] += alpha * y[i]; });
            r.swap(s);
            r_norm = s_norm;
            break;
        }
        multiply<double>(a, z, t);
        const double tt = dot(t, t);
        const double ts = dot(t, s);
        if (!(tt > 0) || tiny(ts, std::sqrt(tt) * s_norm, options.breakdown_tolerance)) {
            // omega would be ~0: BiCGSTAB cannot continue; keep the half step, which is still valid.
            for_rows(n, kGrain, [&](size_t i) { x[i] += alpha * y[i]; });
            r.swap(s);
            r_norm = s_norm;
            result.status = std::isfinite(ts) && std::isfinite(tt) ? BicgstabStatus::OmegaBreakdown
                                                                   : BicgstabStatus::NonFinite;
            break;
        }
        omega = ts / tt;
        for_rows(n, kGrain, [&](size_t i) {
            x[i] += alpha * y[i] + omega * z[i];
            r[i] = s[i] - omega * t[i];
        });
        r_norm = std::sqrt(dot(r, r));
        if (!std::isfinite(r_norm)) {
            result.status = BicgstabStatus::NonFinite;
            break;
        }
        if (r_norm > options.divergence_factor * initial) {
            result.status = BicgstabStatus::Divergence;
            break;
        }
        if (r_norm < 0.99 * best) {
            best = r_norm;
            best_iteration = k;
        } else if (k - best_iteration >= options.stagnation_window) {
            result.status = BicgstabStatus::Stagnation;
            break;
        }
    }
    // Judge the returned point by its true residual (the recursive one drifts, and breakdowns leave
    // it meaningless); hand back the start vector when the iterate is not an improvement.
    double final_norm = true_residual(a, b, x, r);
    // A failed solve that made no progress is also reverted, so that callers see it as skipped.
    if (!std::isfinite(final_norm) || final_norm > initial || (result.failed() && final_norm >= initial)) {
        if (!result.failed())
            result.status = std::isfinite(final_norm) ? BicgstabStatus::Divergence : BicgstabStatus::NonFinite;
        std::copy(x0.begin(), x0.end(), x.begin());
        final_norm = initial;
        result.reverted = true;
    } else if (result.status == BicgstabStatus::IterationLimit && final_norm <= target) {
        result.status = BicgstabStatus::Converged;
    } else if (result.status == BicgstabStatus::Converged && final_norm > 10 * target) {
        // The recursive residual converged but the true one did not (rounding drift).
        result.status = BicgstabStatus::IterationLimit;
    }
    result.relative_residual = final_norm / b_norm;
    return result;
}

}  // namespace waxwork
