#include "solver/conjugate_gradient.h"

#include "base/error.h"
#include "base/parallel_rows.h"
#include "solver/cg_channel_state.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace waxwork {
namespace {

// Rows per parallel chunk; the chunks are fixed, so the sums and iterates do not depend on the
// thread count (base/parallel_rows.h).
constexpr size_t kGrain = 4096;

template <typename Scalar>
double row_product(const CsrMatrixView<Scalar>& m, const Scalar* x, size_t i) {
    double sum = 0;
    for (int32_t k = m.offsets[i]; k < m.offsets[i + 1]; ++k)
        sum += static_cast<double>(m.values[k]) * static_cast<double>(x[m.columns[k]]);
    return sum;
}

// r = b - M x (accumulated in double); returns r . D^-1 r and fills z = D^-1 r.
template <typename Scalar>
double true_residual(const CsrMatrixView<Scalar>& m, const Scalar* b, const Scalar* x, const Scalar* inv_diag,
                     Scalar* r, Scalar* z) {
    return sum_rows(m.rows, kGrain, [&](size_t i) {
        const double ri = static_cast<double>(b[i]) - row_product(m, x, i);
        r[i] = static_cast<Scalar>(ri);
        z[i] = static_cast<Scalar>(ri * static_cast<double>(inv_diag[i]));
        return static_cast<double>(r[i]) * static_cast<double>(z[i]);
    });
}

[[noreturn]] void breakdown(int iteration, const std::string& what) {
    throw AlgorithmError("conjugate gradient: " + what + " at iteration " + std::to_string(iteration) +
                         " (matrix not positive definite, or values lost to rounding: degenerate tets?)");
}

}  // namespace

double smallest_tridiagonal_eigenvalue(std::span<const double> diag, std::span<const double> off, double upper_bound) {
    const size_t k = diag.size();
    if (k == 0) return 0;
    // Number of eigenvalues below x: the negative pivots of the LDL^T factorisation of T - x I.
    auto count_below = [&](double x) {
        int count = 0;
        double d = diag[0] - x;
        for (size_t i = 0;; ++i) {
            if (d < 0) ++count;
            if (i + 1 == k) break;
            if (d == 0) d = std::numeric_limits<double>::min();
            d = diag[i + 1] - x - off[i] * off[i] / d;
        }
        return count;
    };
    double hi = upper_bound > 0 ? upper_bound : std::numeric_limits<double>::infinity();
    if (!std::isfinite(hi)) {
        hi = 0;  // Gershgorin upper bound
        for (size_t i = 0; i < k; ++i)
            hi = std::max(hi, diag[i] + (i > 0 ? std::abs(off[i - 1]) : 0.0) + (i + 1 < k ? std::abs(off[i]) : 0.0));
    }
    if (count_below(hi) == 0) return hi;
    // T is positive definite when M is, so lambda_min > 0: find a lower bracket by decades, then bisect
    // geometrically (lambda_min may lie many orders of magnitude below hi).
    double lo = hi;
    while (count_below(lo) > 0) {
        hi = lo;
        lo *= 1e-2;
        if (lo < 1e-300) {
            lo = 0;
            break;
        }
    }
    for (int it = 0; it < 200 && hi - lo > 1e-6 * hi; ++it) {
        const double mid = lo > 0 ? std::sqrt(lo * hi) : 0.5 * hi;
        (count_below(mid) > 0 ? hi : lo) = mid;
    }
    return hi;
}

template <typename Scalar>
void multiply(const CsrMatrixView<Scalar>& m, std::span<const Scalar> x, std::span<Scalar> y) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, m.rows, kGrain), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) y[i] = static_cast<Scalar>(row_product(m, x.data(), i));
    });
}

template <typename Scalar>
ConjugateGradientResult solve_jacobi_cg(const CsrMatrixView<Scalar>& m, std::span<const Scalar> b, std::span<Scalar> x,
                                        const ConjugateGradientOptions& options) {
    const size_t n = m.rows;
    if (b.size() != n || x.size() != n)
        throw InvalidArgumentError("conjugate gradient: vector sizes (" + std::to_string(b.size()) + ", " +
                                   std::to_string(x.size()) + ") differ from the matrix size " + std::to_string(n));
    if (!(options.relative_tolerance > 0) || options.max_iterations < 0)
        throw InvalidArgumentError("conjugate gradient: tolerance must be positive and max_iterations non-negative");
    ConjugateGradientResult result;
    if (n == 0) {
        result.converged = true;
        return result;
    }

    std::vector<Scalar> inv_diag(n), r(n), z(n), p(n), q(n);
    std::vector<double> diag(n);
    bool bad_input = false;
    for (size_t i = 0; i < n; ++i) {
        double d = 0;
        for (int32_t k = m.offsets[i]; k < m.offsets[i + 1]; ++k)
            if (static_cast<size_t>(m.columns[k]) == i) d = m.values[k];
        if (!(d > 0) || !std::isfinite(d)) {
            throw AlgorithmError("conjugate gradient: diagonal entry " + std::to_string(i) + " is " +
                                 std::to_string(d) + " (must be positive and finite)");
        }
        diag[i] = d;
        inv_diag[i] = static_cast<Scalar>(1.0 / d);
        if (!std::isfinite(static_cast<double>(b[i])) || !std::isfinite(static_cast<double>(x[i]))) bad_input = true;
    }
    if (bad_input) throw AlgorithmError("conjugate gradient: right-hand side or start vector is not finite");

    const double tol = options.relative_tolerance;
    const double rz = true_residual(m, b.data(), x.data(), inv_diag.data(), r.data(), z.data());
    const double bnorm2 = sum_rows(n, kGrain, [&](size_t i) { return static_cast<double>(b[i]) * b[i] / diag[i]; });
    if (bnorm2 == 0) {  // the solution is exactly zero
        std::fill(x.begin(), x.end(), Scalar(0));
        result.converged = true;
        return result;
    }
    CgChannelState st;
    st.rz = rz;
    st.xnorm2 = sum_rows(n, kGrain, [&](size_t i) { return diag[i] * static_cast<double>(x[i]) * x[i]; });
    std::copy(z.begin(), z.end(), p.begin());

    // A known lower bound of lambda_min acts as the Ritz floor from the start (an infinite "hint", e.g.
    // the estimate of a run without iterations, says nothing).
    if (options.smallest_eigenvalue_hint > 0 && std::isfinite(options.smallest_eigenvalue_hint)) {
        st.ritz_floor = options.smallest_eigenvalue_hint;
        // A warm start can already be good enough (only checkable with a known eigenvalue bound).
        const double est = st.estimate(st.rz, st.ritz_floor);
        if (est <= tol) {
            result.converged = true;
            result.estimated_relative_error = est;
            result.smallest_eigenvalue_estimate = st.ritz_floor;
            return result;
        }
    }

    int k = 0;
    // The deadline is read last (short-circuit): only when another iteration would otherwise run.
    for (; k < options.max_iterations && st.active && !(k > 0 && options.deadline.expired()); ++k) {
        // q = M p and p . q in one pass.
        const double pq = sum_rows(n, kGrain, [&](size_t i) {
            const double qi = row_product(m, p.data(), i);
            q[i] = static_cast<Scalar>(qi);
            return static_cast<double>(p[i]) * qi;
        });
        if (!std::isfinite(pq)) breakdown(k, "p.Mp is not finite");
        if (!(pq > 0)) breakdown(k, "p.Mp = " + std::to_string(pq) + " is not positive");
        const double alpha = st.rz / pq;
        const Scalar a = static_cast<Scalar>(alpha);
        // x += alpha p, r -= alpha q, z = D^-1 r, and the two norms, in one pass.
        // rz and the x norm (the stopping rule's), for the new iterate.
        const auto [rz_new, xnorm2] = reduce_rows<2>(n, kGrain, [&](size_t i, std::array<double, 2>& sums) {
            x[i] += a * p[i];
            r[i] -= a * q[i];
            z[i] = inv_diag[i] * r[i];
            sums[0] += static_cast<double>(r[i]) * static_cast<double>(z[i]);
            sums[1] += diag[i] * static_cast<double>(x[i]) * static_cast<double>(x[i]);
        });
        if (!std::isfinite(rz_new) || !std::isfinite(xnorm2)) breakdown(k, "the iterate became non-finite");
        const double beta = st.record_step(alpha, rz_new, xnorm2);
        double lam = 0;
        const double est = st.current_estimate(k, tol, static_cast<bool>(options.on_iteration), lam);
        if (options.on_iteration) options.on_iteration(k + 1, est);
        if (est <= tol && st.may_stop(k, n)) {
            // Confirm with the true residual: the recursive one drifts (far, in float).
            const double rz_true = true_residual(m, b.data(), x.data(), inv_diag.data(), r.data(), z.data());
            if (!std::isfinite(rz_true)) breakdown(k, "the true residual is not finite");
            if (!st.confirm(k, rz_true, st.estimate(rz_true, lam), lam, tol))
                std::copy(z.begin(), z.end(), p.begin());  // restart from the true residual
            continue;
        }
        st.result.estimated_relative_error = est;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& range) {
            const Scalar bt = static_cast<Scalar>(beta);
            for (size_t i = range.begin(); i != range.end(); ++i) p[i] = z[i] + bt * p[i];
        });
    }
    result = st.finish(k);
    result.smallest_eigenvalue_estimate = st.lambda();
    return result;
}

template ConjugateGradientResult solve_jacobi_cg<float>(const CsrMatrixView<float>&, std::span<const float>,
                                                        std::span<float>, const ConjugateGradientOptions&);
template ConjugateGradientResult solve_jacobi_cg<double>(const CsrMatrixView<double>&, std::span<const double>,
                                                         std::span<double>, const ConjugateGradientOptions&);
template void multiply<float>(const CsrMatrixView<float>&, std::span<const float>, std::span<float>);
template void multiply<double>(const CsrMatrixView<double>&, std::span<const double>, std::span<double>);

}  // namespace waxwork
