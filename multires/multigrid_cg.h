// Conjugate gradients on level 0 preconditioned by the multigrid V-cycle on the independent-set
// hierarchy (multires/multigrid_preconditioner.h). Beyond the paper (Li et al. 2013 solve their levels
// once, coarse to fine, multires_solver.h); here every CG iteration applies one V-cycle.
//
// Stopping rule: the estimated relative error, as in solver/conjugate_gradient.h, but in the energy
// norm, which is the natural norm of preconditioned CG. With B the preconditioner, z = B r and
// e = phi - x = M^-1 r,
//     ||e||_M^2 = r . M^-1 r <= (r . B r) / lambda_min(B M) = (r . z) / lambda_min(B M),
// and ||x||_M^2 = x . M x = x . (b - r), computed from vectors CG has anyway. lambda_min(B M) is the
// smallest Ritz value of CG's Lanczos matrix (the same construction and Sturm bisection as the Jacobi
// CG; with a good V-cycle it is of order one, so the bound is nearly the residual's B-norm).
// Before declaring convergence the true residual b - M x is recomputed and the test repeated.
//
// Robustness: non-finite input, p.Mp <= 0 or r.z < 0 (a preconditioner that is not positive
// definite) throw AlgorithmError; no NaN is returned.
#pragma once

#include "multires/multigrid_preconditioner.h"
#include "solver/conjugate_gradient.h"

#include <span>

namespace waxwork {

// Solves M x = b for one channel (M: level 0 of the preconditioner's hierarchy, in double). x is the
// warm start on entry and the solution on exit. options: relative_tolerance (energy norm, above),
// max_iterations, smallest_eigenvalue_hint (of B M; feed back a previous solve's estimate) and
// on_iteration.
ConjugateGradientResult solve_multigrid_cg(MultigridPreconditioner& preconditioner, int channel,
                                           std::span<const double> b, std::span<double> x,
                                           const ConjugateGradientOptions& options = {});

}  // namespace waxwork
