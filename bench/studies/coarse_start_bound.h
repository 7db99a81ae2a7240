// The best start the paper's coarse-to-fine scheme (multires_solver.h, Li et al. 2013 Sec. 4.2) can hand
// to level 0, measured: level 1 solved exactly (a direct factorisation, not timed), interpolated by
// Eq. 16, and the level-0 Jacobi CG iterations still needed from there to a target error, next to the
// iterations from a zero start.
//
// Why a bound. The scheme gains the level-0 iterations its start saves, minus what the coarse pass
// costs. Its coarse pass approximates the exact solution of level 1's Eq. 17 system, and comes closer
// to it the more work it spends on the coarse levels; the iterations left after that exact solution
// are what the scheme needs in the limit of exact coarse solves that cost nothing. If even that start
// saves less than half the iterations, tuning the coarse levels (iterations per level, tolerances,
// another Krylov method) cannot make the scheme twice as fast as Jacobi CG on that system (a cheap,
// inexact coarse pass could land closer by chance, but the measured one does not: its level-0 start
// is further off than the exact one). The same bound for the Galerkin system P^T M P y = P^T b (whose
// P y is the element of range(P) closest to the solution in the M-norm) separates what Eq. 17's
// collocation loses from what Eq. 16's interpolation itself loses: the interpolation error of the
// exact solution's own coarse values is reported too. Both depend on Eq. 16's weights
// (HierarchyOptions::weights): the bench part coarse_start measures the paper's and linear-exact ones.
//
// Errors are relative L2 over the three channels together, as in the solver comparison
// (bench/studies/solver_comparison.h): sqrt(sum_c |x_c - x*_c|^2 / sum_c |x*_c|^2).
#pragma once

#include "multires/hierarchy.h"
#include "multires/multigrid_preconditioner.h"

#include <array>
#include <vector>

namespace waxwork {

using ChannelVectors = std::array<std::vector<double>, 3>;

struct CoarseStartBound {
    size_t fine_vertices = 0;
    size_t coarse_vertices = 0;      // level 1
    double interpolation_error = 0;  // |P S x* - x*| / |x*|: Eq. 16 applied to the solution's level-1 values
    double eq17_start_error = 0;     // |P y - x*| / |x*|, y the exact solution of level 1's Eq. 17 system
    double galerkin_start_error = 0; // the same for P^T M P y = P^T b
    // Level-0 Jacobi CG iterations (every channel the same count) to reach the target error from each
    // start; -1 when not reached within the iteration limit.
    int iterations_from_zero = 0;
    int iterations_from_eq17 = 0;
    int iterations_from_galerkin = 0;
};

// Level 1's Eq. 17 system M^1 y = b^1 (b^1 the injection of b, Eq. 17) solved by sparse LU, for one
// channel. Throws InvalidArgumentError when the hierarchy has no level 1 or b has the wrong size,
// AlgorithmError when M^1 is singular.
std::vector<double> solve_level1_eq17(const MultiresHierarchy& hierarchy, int channel, const std::vector<double>& b);

// The Galerkin level-1 system (P^0)^T M^0 P^0 y = (P^0)^T b solved by sparse LDL^T, for one channel.
// Throws as solve_level1_eq17.
std::vector<double> solve_level1_galerkin(const MultiresHierarchy& hierarchy, int channel, const std::vector<double>& b);

// The smallest k <= max_iterations such that k Jacobi CG iterations on level 0 from `start` (per
// channel) reach error(x) <= target_error against `reference`, found by doubling and bisection (the
// error is taken as non-increasing in k); -1 when max_iterations does not reach it.
int jacobi_cg_iterations_to(const MultiresHierarchy& hierarchy, const ChannelVectors& b, const ChannelVectors& start,
                            const ChannelVectors& reference, double target_error, int max_iterations);

// The same count for CG preconditioned by the multigrid V-cycle on the same hierarchy
// (multigrid_cg.h) from a zero start: what the hierarchy's interpolation weights
// (HierarchyOptions::weights) give the project's fastest solver.
int multigrid_cg_iterations_to(MultigridPreconditioner& preconditioner, const ChannelVectors& b,
                               const ChannelVectors& reference, double target_error, int max_iterations);

// sqrt(sum_c |x_c - reference_c|^2 / sum_c |reference_c|^2), the error every number here uses.
double combined_relative_error(const ChannelVectors& x, const ChannelVectors& reference);

// All of CoarseStartBound. reference: the exact level-0 solutions of b. Throws InvalidArgumentError on
// sizes that do not match the hierarchy, no level 1, or a target_error not in (0, 1).
CoarseStartBound measure_coarse_start_bound(const MultiresHierarchy& hierarchy, const ChannelVectors& b,
                                            const ChannelVectors& reference, double target_error = 1e-2,
                                            int max_iterations = 10000);

}  // namespace waxwork
