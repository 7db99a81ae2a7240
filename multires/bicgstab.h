// Jacobi-preconditioned BiCGSTAB (van der Vorst 1992) for the non-symmetric coarse systems of the
// multi-resolution solver (Li et al. 2013, Sec. 4.2: "biconjugate gradient methods ... at all levels
// except at level 0"). solver/ has only CG (symmetric positive definite), hence this file.
//
// Coarse matrices are not guaranteed invertible (Sec. 4.2), so the solver watches for every way
// BiCGSTAB fails: rho = r0.r or r0.v near zero relative to the norms involved (Lanczos breakdown),
// omega near zero (the stabilising step stalls), no progress over a window of iterations
// (stagnation), residual growth beyond a factor (divergence) and non-finite values. It then stops and
// reports why. Whatever happens, x on return is finite and its true residual is no larger than that
// of the start vector: a failed solve hands back the start vector (or the best point reached).
#pragma once

#include "solver/conjugate_gradient.h"

#include <span>

namespace waxwork {

enum class BicgstabStatus {
    Converged,
    IterationLimit,  // budget used up; x is the last (finite, improved) iterate
    RhoBreakdown,
    OmegaBreakdown,
    Stagnation,
    Divergence,
    NonFinite,
};

const char* to_string(BicgstabStatus status);

struct BicgstabOptions {
    double relative_tolerance = 1e-6;  // on ||b - A x|| / ||b||
    int max_iterations = 1000;
    double breakdown_tolerance = 1e-12;  // |inner product| / (product of norms) below this is breakdown
    int stagnation_window = 50;          // iterations without a 1% improvement of the best residual
    double divergence_factor = 1e6;      // residual growth over the initial residual
};

struct BicgstabResult {
    BicgstabStatus status = BicgstabStatus::Converged;
    int iterations = 0;
    double initial_relative_residual = 0;
    double relative_residual = 0;  // true residual of the returned x
    bool reverted = false;         // x was reset to the start vector (the iterate was worse or broken)

    bool failed() const { return status != BicgstabStatus::Converged && status != BicgstabStatus::IterationLimit; }
};

// Solves A x = b with x the start vector on entry. diagonal[i]: the position of (i, i) in the matrix's
// columns (for the Jacobi preconditioner; a zero or non-finite diagonal entry is treated as 1).
// Reductions are deterministic (fixed partition), so results do not depend on the thread count.
BicgstabResult solve_jacobi_bicgstab(const CsrMatrixView<double>& matrix, std::span<const int32_t> diagonal,
                                     std::span<const double> b, std::span<double> x, const BicgstabOptions& options = {});

}  // namespace waxwork
