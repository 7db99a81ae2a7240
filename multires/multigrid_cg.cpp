#include "multires/multigrid_cg.h"

#include "base/error.h"
#include "base/parallel_rows.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace waxwork {
namespace {

constexpr size_t kGrain = 4096;

double row_product(const CsrMatrixView<double>& m, const double* x, size_t i) {
    double sum = 0;
    for (int32_t k = m.offsets[i]; k < m.offsets[i + 1]; ++k) sum += m.values[k] * x[m.columns[k]];
    return sum;
}

[[noreturn]] void breakdown(int iteration, const std::string& what) {
    throw AlgorithmError("multigrid CG: " + what + " at iteration " + std::to_string(iteration) +
                         " (matrix or preconditioner not positive definite)");
}

}  // namespace

ConjugateGradientResult solve_multigrid_cg(MultigridPreconditioner& preconditioner, int channel,
                                           std::span<const double> b, std::span<double> x,
                                           const ConjugateGradientOptions& options) {
    if (channel < 0 || channel > 2)
        throw InvalidArgumentError("multigrid CG: channel " + std::to_string(channel) + " is not 0, 1 or 2");
    const CsrMatrixView<double> m = preconditioner.view(0, channel);
    const size_t n = m.rows;
    if (b.size() != n || x.size() != n)
        throw InvalidArgumentError("multigrid CG: vector sizes (" + std::to_string(b.size()) + ", " +
                                   std::to_string(x.size()) + ") differ from the matrix size " + std::to_string(n));
    if (!(options.relative_tolerance > 0) || options.max_iterations < 0)
        throw InvalidArgumentError("multigrid CG: tolerance must be positive and max_iterations non-negative");
    for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(b[i]) || !std::isfinite(x[i]))
            throw AlgorithmError("multigrid CG: right-hand side or start vector is not finite");
    ConjugateGradientResult result;
    if (std::all_of(b.begin(), b.end(), [](double v) { return v == 0; })) {
        std::fill(x.begin(), x.end(), 0.0);
        result.converged = true;
        return result;
    }
    std::vector<double> r(n), z(n), p(n), q(n);

    // (r . z, x . M x), with M x = b - r.
    auto rz_and_xmx = [&] {
        return reduce_rows<2>(n, kGrain, [&](size_t i, std::array<double, 2>& sums) {
            sums[0] += r[i] * z[i];
            sums[1] += x[i] * (b[i] - r[i]);
        });
    };
    // r = b - M x, z = B r; returns (r . z, x . M x).
    auto refresh = [&]() {
        for_rows(n, kGrain, [&](size_t i) { r[i] = b[i] - row_product(m, x.data(), i); });
        preconditioner.apply(channel, r, z);
        return rz_and_xmx();
    };
    std::array<double, 2> sums = refresh();
    double rz = sums[0], xmx = sums[1];
    if (!(rz >= 0) || !std::isfinite(rz)) breakdown(0, "r.Br = " + std::to_string(rz));

    const double hint = options.smallest_eigenvalue_hint > 0 ? options.smallest_eigenvalue_hint
                                                             : std::numeric_limits<double>::infinity();
    std::vector<double> t_diag, t_off;
    double ritz = std::numeric_limits<double>::infinity(), ritz_floor = ritz;
    auto lambda = [&] {
        if (!t_diag.empty()) ritz = smallest_tridiagonal_eigenvalue(t_diag, t_off, std::isfinite(ritz) ? ritz : 0);
        return std::min({hint, ritz, ritz_floor});
    };
    auto estimate = [&](double rz_value, double xmx_value, double lam) {
        if (!(xmx_value > 0) || !std::isfinite(lam)) return std::numeric_limits<double>::infinity();
        return std::sqrt(std::max(rz_value, 0.0) / lam / xmx_value);
    };
    if (std::isfinite(hint) && estimate(rz, xmx, hint) <= options.relative_tolerance) {
        result.converged = true;
        result.estimated_relative_error = estimate(rz, xmx, hint);
        result.smallest_eigenvalue_estimate = hint;
        return result;
    }
    std::copy(z.begin(), z.end(), p.begin());
    double alpha_prev = 0, beta_prev = 0;
    int k = 0;
    for (; k < options.max_iterations; ++k) {
        const double pq = sum_rows(n, kGrain, [&](size_t i) {
            q[i] = row_product(m, p.data(), i);
            return p[i] * q[i];
        });
        if (!(pq > 0) || !std::isfinite(pq)) breakdown(k, "p.Mp = " + std::to_string(pq));
        const double alpha = rz / pq;
        for_rows(n, kGrain, [&](size_t i) {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
        });
        preconditioner.apply(channel, r, z);
        sums = rz_and_xmx();
        if (!std::isfinite(sums[0]) || !std::isfinite(sums[1])) breakdown(k, "the iterate became non-finite");
        if (sums[0] < 0) breakdown(k, "r.Br = " + std::to_string(sums[0]));
        const double beta = sums[0] / rz;
        // Lanczos coefficients of B M (Saad, Iterative Methods, Sec. 6.7.3).
        t_diag.push_back(1.0 / alpha + (t_diag.empty() ? 0.0 : beta_prev / alpha_prev));
        if (t_diag.size() > 1) t_off.push_back(std::sqrt(beta_prev) / alpha_prev);
        alpha_prev = alpha;
        beta_prev = beta;
        rz = sums[0];
        xmx = sums[1];
        const double lam = lambda();
        double est = estimate(rz, xmx, lam);
        if (options.on_iteration) options.on_iteration(k + 1, est);
        result.estimated_relative_error = est;
        if (est <= options.relative_tolerance) {
            // Confirm with the true residual; restart from it if the recursive one drifted.
            sums = refresh();
            rz = sums[0];
            xmx = sums[1];
            est = estimate(rz, xmx, lam);
            result.estimated_relative_error = est;
            if (est <= options.relative_tolerance) {
                result.converged = true;
                ++k;
                break;
            }
            ++result.residual_replacements;
            if (result.residual_replacements > 4) {
                ++k;
                break;
            }
            ritz_floor = lam;
            t_diag.clear();
            t_off.clear();
            ritz = std::numeric_limits<double>::infinity();
            std::copy(z.begin(), z.end(), p.begin());
            continue;
        }
        for_rows(n, kGrain, [&](size_t i) { p[i] = z[i] + beta * p[i]; });
    }
    result.iterations = k;
    result.smallest_eigenvalue_estimate = lambda();
    return result;
}

}  // namespace waxwork
