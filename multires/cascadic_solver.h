// Cascadic conjugate gradients (Bornemann and Deuflhard, "The cascadic multigrid method for elliptic
// problems", Numer. Math. 75, 1996) on the independent-set hierarchy: the coarse-to-fine pass of Li et
// al. 2013 (Sec. 4.2: the coarsest level solved, interpolated by Eq. 16 to the next finer level as its
// start, a few iterations there, and so on down to level 0, where CG finishes) with Galerkin coarse
// systems instead of Eq. 17's.
//
// Why. The paper's pass cannot halve Jacobi CG's time on our systems even with exact coarse solves
// that cost nothing (bench/studies/coarse_start_bound.h; docs/benchmarks.md): the exact
// solution of level 1's Eq. 17 system, interpolated, leaves a 12% error on spot at 486,745 tets. Eq. 17
// collocates the fine equations at the retained vertices (S M^l P^l y = S b), so its solution is not the
// best element of range(P) in any norm. The Galerkin system P^T M P y = P^T b gives exactly that best
// element in the energy norm (3.4% on the same system), which is the start the level-0 CG, an
// energy-norm minimiser, can use best. Its operators are symmetric positive definite, so every level
// runs CG (Jacobi-preconditioned) instead of BiCGSTAB, and the short recurrence cannot break down the
// way BiCGSTAB's rho and omega can.
//
// The operators are MultigridPreconditioner's (the same hierarchy, Eq. 16's P, Galerkin products with
// small entries dropped and lumped into the diagonal, the coarsest level factorised exactly), so a
// scene that has the multigrid CG pays for no second setup. Following Bornemann and Deuflhard, coarser
// levels, which cost less per iteration, get more iterations: level l >= 1 gets
// round(level_iterations * growth^(l - 1)).
//
// Fallback. A coarse level whose CG throws (a matrix that is not positive definite in that channel;
// the setup already checks diagonals and the coarsest factorisation) keeps its interpolated start and
// records why; the result is always finite and the level-0 CG alone decides the accuracy.
#pragma once

#include "multires/multigrid_preconditioner.h"
#include "solver/conjugate_gradient.h"

#include <span>
#include <string>
#include <vector>

namespace waxwork {

struct CascadicOptions {
    // Jacobi CG iterations on level 1. 0 by default: on spot at 486,745 tets (multires_bench,
    // BM_CascadicTo1Percent) 4 or 16 iterations on level 1 (growth 2) bring the start from 24% to 9%
    // and 7% but save at most one level-0 iteration (17 -> 16, about 1 ms) and add 4 and 8 ms to the
    // 20 ms solve.
    int level_iterations = 0;
    double growth = 2.0;                // each coarser level gets this many times its finer neighbour's
    int max_level_iterations = 200;     // cap per level
    double relative_tolerance = 1e-3;   // level-0 CG: estimated relative error (conjugate_gradient.h)
    int max_iterations = 10000;         // level-0 CG iteration budget
};

struct CascadicLevelReport {
    int level = 0;
    int iterations = 0;
    bool skipped = false;  // the level's CG failed; its interpolated start was passed on
    std::string reason;
};

struct CascadicReport {
    std::vector<CascadicLevelReport> coarse_levels;  // coarsest first; the coarsest is solved exactly (0 iterations)
    ConjugateGradientResult fine;
    double coarse_ms = 0;  // restriction, the coarse levels and the interpolation to level 0
    double fine_ms = 0;
};

// Checks a CascadicOptions: iteration counts >= 0, growth >= 1 and finite, tolerance in (0, 1).
// Throws InvalidArgumentError naming the field.
void validate(const CascadicOptions& options);

// One level's iterations: `iterations` Jacobi CG steps on a x = b from x (the level's report, level
// left 0). When CG refuses the level (a matrix that is not positive definite, a non-finite value) x is
// restored to its start, skipped is set and the reason recorded: the finer levels get the
// interpolated coarser solution instead.
CascadicLevelReport iterate_level(const CsrMatrixView<double>& a, std::span<const double> b, std::span<double> x,
                                  int iterations);

class CascadicSolver {
public:
    // Borrows the operators, which must outlive the solver (as they borrow their hierarchy).
    explicit CascadicSolver(MultigridPreconditioner& operators);

    // M^0 x = b for one channel from a zero start (x's content is ignored). Throws InvalidArgumentError
    // on sizes, a bad channel or options, AlgorithmError for a non-finite b or when the level-0 CG fails.
    CascadicReport solve(std::span<const double> b, int channel, std::span<double> x, const CascadicOptions& options = {});

    // The start the coarse pass hands to level 0 (P^0 of level 1's iterate), without the level-0 CG.
    // For measuring the pass against its exact limit (coarse_start_bound.h).
    CascadicReport coarse_pass(std::span<const double> b, int channel, std::span<double> x,
                               const CascadicOptions& options = {});

private:
    MultigridPreconditioner& operators_;
    std::vector<std::vector<double>> b_, x_;  // per level: restricted right-hand side and iterate
};

}  // namespace waxwork
