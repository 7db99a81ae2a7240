// Jacobi-preconditioned conjugate gradients on a compressed-row matrix, in float or double, with a
// stopping rule on the estimated relative error of the solution rather than on the residual.
//
// Error estimate. With D = diag(M), ~M = D^-1/2 M D^-1/2 and e = phi - x, the preconditioned
// residual satisfies D^1/2 e = ~M^-1 D^-1/2 r, hence
//     ||e||_D <= sqrt(r . D^-1 r) / lambda_min(~M)       (r . D^-1 r = r . z, which CG computes anyway),
// and the relative error is estimated as that bound divided by ||x||_D. lambda_min is estimated by
// the smallest Ritz value of the Lanczos tridiagonal matrix that CG builds implicitly from its
// coefficients (diagonal 1/alpha_k + beta_{k-1}/alpha_{k-1}, off-diagonal sqrt(beta_k)/alpha_k),
// found by Sturm-sequence bisection. Ritz values approach lambda_min from above, so early in a solve
// the estimate can be low; the caller may pass a known lower bound or an earlier run's estimate
// (smallest_eigenvalue_hint), and the solver takes the smaller of the two. Late in a solve, when the
// error is dominated by the lowest modes, the bound is tight (within a small factor of the true error;
// tests/solver/conjugate_gradient_test.cpp measures it).
//
// Attainable accuracy. The recursively updated residual drifts away from b - M x in float. Before
// declaring convergence the solver recomputes the true residual (accumulated in double) and re-checks;
// if the true estimate is above the tolerance it restarts from the true residual, and gives up with
// converged = false after a few restarts that fail to halve the estimate (the precision's floor).
//
// Robustness. Non-finite input, a non-positive diagonal, p.Mp <= 0 (not positive definite) or a
// non-finite iterate throw AlgorithmError: the solver never returns NaN.
#pragma once

#include "solver/frame_budget.h"

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace waxwork {

// A borrowed compressed-row matrix: row i's entries are columns/values[offsets[i] .. offsets[i+1]).
template <typename Scalar>
struct CsrMatrixView {
    size_t rows = 0;
    const int32_t* offsets = nullptr;
    const int32_t* columns = nullptr;
    const Scalar* values = nullptr;
};

// The smallest relative tolerance a user may ask a solve for: below about 1e-15 a relative error is
// under double's rounding, and no solver can report it reached (the render command and sessions
// refuse less; benchmarks that run a fixed iteration count pass it to never stop early; the live scene
// takes any tolerance in (0, 1) and says so when a solve stops at its precision floor).
inline constexpr double kMinRelativeTolerance = 1e-15;

struct ConjugateGradientOptions {
    double relative_tolerance = 1e-3;  // on the estimated ||phi - x||_D / ||x||_D
    int max_iterations = 10000;
    // A lower bound (or a previous estimate) of lambda_min(D^-1/2 M D^-1/2); 0 = none.
    double smallest_eigenvalue_hint = 0;
    // Called after every iteration with the iterate and its error estimate (slower: the estimate is
    // then refreshed every iteration). For tests and convergence plots.
    std::function<void(int iteration, double estimated_relative_error)> on_iteration;
    // A frame's time limit (frame_budget.h): checked before each iteration after the first (one clock
    // read), so an iteration that started finishes and at least one runs. The stop is just an earlier
    // max_iterations: a run the deadline stopped after k iterations equals the run with
    // max_iterations = k bit for bit. Default: none.
    FrameDeadline deadline;
};

// Options that run exactly `iterations` iterations (the error estimate never stops them first), for
// measuring the error reached against the work spent.
inline ConjugateGradientOptions exact_iteration_count(int iterations) {
    ConjugateGradientOptions options;
    options.relative_tolerance = kMinRelativeTolerance;
    options.max_iterations = iterations;
    return options;
}

struct ConjugateGradientResult {
    int iterations = 0;
    bool converged = false;
    double estimated_relative_error = 0;
    double smallest_eigenvalue_estimate = 0;  // feed back as smallest_eigenvalue_hint next frame
    int residual_replacements = 0;            // true-residual restarts (precision floor checks)
};

// Solves M x = b. x is the warm start on entry (any finite vector; zeros for a cold start) and the
// solution on exit. M must be symmetric positive definite. Values and vectors in Scalar (float or
// double); reductions are accumulated in double in a fixed order (deterministic results).
template <typename Scalar>
ConjugateGradientResult solve_jacobi_cg(const CsrMatrixView<Scalar>& matrix, std::span<const Scalar> b,
                                        std::span<Scalar> x, const ConjugateGradientOptions& options = {});

// y = M x (parallel).
template <typename Scalar>
void multiply(const CsrMatrixView<Scalar>& matrix, std::span<const Scalar> x, std::span<Scalar> y);

// Smallest eigenvalue of the symmetric tridiagonal matrix (diagonal, off_diagonal), off_diagonal one
// shorter, by Sturm-sequence bisection to a relative accuracy of about 1e-6. upper_bound (optional, >
// 0) is a known upper bound that narrows the search.
double smallest_tridiagonal_eigenvalue(std::span<const double> diagonal, std::span<const double> off_diagonal,
                                       double upper_bound = 0);

}  // namespace waxwork
