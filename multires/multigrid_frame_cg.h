// The per-frame loop of the live editor's multigrid-preconditioned CG, shared by the CPU frame solver
// (multigrid_frame_solver.h: vectors in host memory, double) and the GPU one
// (gpu_multigrid_frame_solver.h: vectors in device buffers, float). Both run the same algorithm on
// the three rgb channels at once: per V-cycle z = B r, the sums r . z and phi . M phi for the error
// estimate and stopping rule (multigrid_cg_state.h), p = z + beta p, q = M p with p . q, phi += alpha p,
// r -= alpha q, and every residual_refresh_interval updates r = b - M phi recomputed and CG restarted.
// A claim of convergence from the recursive residual is confirmed with a recomputed one where the
// backend asks (confirms_convergence), and estimates from recomputed residuals that stop halving stop
// the solve at its precision floor instead of spending the budget.
// This class owns that loop, its budgets (V-cycles or milliseconds, solver/frame_budget.h) and the
// bookkeeping of what a new b, phi or operator invalidates; a subclass supplies the vector operations
// on its own storage, so one stopping rule and one restart policy serve both backends by construction.
#pragma once

#include "multires/hierarchy.h"
#include "multires/multigrid_cg_state.h"
#include "multires/multigrid_preconditioner.h"
#include "solver/diffusion_matrix.h"
#include "solver/frame_budget.h"

#include <array>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace waxwork {

struct FrameSolverOptions {
    HierarchyOptions hierarchy;
    MultigridOptions multigrid;
    double relative_tolerance = 1e-2;     // step() stops early once every channel's estimate is below
    int residual_refresh_interval = 50;   // CG updates between recomputing r = b - M phi exactly
};

struct FrameStep {
    std::array<double, 3> estimated_relative_error{};  // per channel (multigrid_frame_solver.h)
    int vcycles = 0;                                    // V-cycles run (<= budget)
    bool converged = false;                             // every estimate <= tolerance, of the current phi
    // Stopped early, above the tolerance: the true residual refuted a claim of convergence and the
    // refutations stopped halving the error (the backend's precision floor on this matrix, see
    // confirms_convergence). More V-cycles would not help; a more precise backend might.
    bool at_precision_floor = false;
};

// How far a recomputed residual r moved from the recursive one it replaced, r_old: the largest over
// the channels of ||r - r_old|| / ||r|| in the D^-1 norm, from the per-channel sums ||r - r_old||^2
// (sums[0..2]) and ||r||^2 (sums[3..5]). 0 when nothing moved, infinity when r = 0 but r_old was not.
double residual_drift(const std::array<double, 6>& sums);

class MultigridFrameCg {
public:
    virtual ~MultigridFrameCg() = default;
    MultigridFrameCg(const MultigridFrameCg&) = delete;
    MultigridFrameCg& operator=(const MultigridFrameCg&) = delete;

    // The three channels' right-hand sides (diffusion_right_hand_side) of the current light. Cheap:
    // the residual follows the change of b. Throws InvalidArgumentError on a size mismatch and
    // AlgorithmError on non-finite values (the state is then unchanged).
    virtual void set_right_hand_side(const std::array<std::span<const double>, 3>& b) = 0;
    // phi = 0 (forgets the warm start and the eigenvalue estimates).
    virtual void reset() = 0;
    // Warm start from given solutions (e.g. a saved frame); the eigenvalue estimates are kept (same
    // operator). When a right-hand side is set, the residual is recomputed here, not in the next step.
    // Throws InvalidArgumentError on a size mismatch, AlgorithmError on non-finite values.
    virtual void set_phi(const std::array<std::span<const double>, 3>& phi) = 0;
    // After update_diffusion_matrix rewrote `changed_rows` (ascending) with an unchanged pattern
    // (painting): updates level 0, the preconditioner's affected coarse rows and the residual. The
    // hierarchy's Eq. 17 matrices (levels >= 1) are left as they were: these solvers do not use them.
    // Throws InvalidArgumentError for another pattern or a row out of range.
    virtual void update_values(const DiffusionMatrix& matrix, std::span<const int32_t> changed_rows) = 0;

    // Runs at most `budget` V-cycles (each followed by one CG update unless converged). Throws
    // InvalidArgumentError when no right-hand side was set or budget < 1, AlgorithmError when the
    // matrix or preconditioner turns out not to be positive definite.
    FrameStep step(int budget);
    // The same within a frame budget: budget.max_iterations counts V-cycles (0: no limit),
    // budget.max_milliseconds runs on `clock` (empty: steady_clock) from the call and is checked between
    // V-cycles (each with its CG update finishes; at least one runs). Stopping between V-cycles leaves
    // the same state as a V-cycle budget would: a budget that ran k V-cycles equals step(k) bit for bit,
    // and the next frame resumes from it. Throws InvalidArgumentError for an invalid budget
    // (validate(FrameBudget)) and as step(int).
    FrameStep step(const FrameBudget& budget, const MillisecondClock& clock = {});

    // The tolerance step() stops at (FrameSolverOptions::relative_tolerance), e.g. a tighter one to
    // converge a scene the frames left at a looser one. Throws InvalidArgumentError unless positive.
    void set_relative_tolerance(double tolerance);

    size_t size() const { return n_; }
    // The operators the V-cycle runs on (set by the subclass's constructor).
    const MultiresHierarchy& hierarchy() const { return *hierarchy_; }
    const MultigridPreconditioner& preconditioner() const { return *preconditioner_; }

protected:
    using Rgb = MultigridCgState::Rgb;

    // `who` prefixes the error messages ("frame solver", "GPU frame solver"). Throws
    // InvalidArgumentError for a non-positive tolerance or a refresh interval < 1.
    MultigridFrameCg(size_t n, const FrameSolverOptions& options, std::string who);
    // Throws InvalidArgumentError unless `hierarchy` was built for a matrix of this size with
    // options.hierarchy (a hierarchy passed in, rebuilt after an edit).
    void check_hierarchy(const MultiresHierarchy& hierarchy) const;

    // The vector work of one CG step on the subclass's storage (all three channels).
    virtual void precondition() = 0;                                    // z = B r
    virtual MultigridCgState::StepSums step_sums() = 0;                 // r . z, then phi . M phi
    virtual void set_direction(const Rgb& beta, bool restart) = 0;      // p = z (restart) or z + beta p
    virtual Rgb multiply_direction() = 0;                               // q = M p; returns p . q
    virtual void update_solution(const Rgb& alpha) = 0;                 // phi += alpha p, r -= alpha q
    // r = b - M phi (r = b when zero). Returns the per-channel sums residual_drift takes, of the new r
    // against the one it replaced (zeros when phi is zero: r = b exactly).
    virtual std::array<double, 6> compute_residual(bool phi_is_zero) = 0;
    // After the V-cycles of a step (the GPU checks its driver's error state here).
    virtual void steps_done() {}
    // Whether an estimate within the tolerance from the recursive residual must be confirmed with a
    // recomputed r = b - M phi before the solver stops. A backend whose updates are less precise than
    // its recomputed residual says yes: the GPU updates r in float from a float copy of M but computes
    // b - M phi in double from the double matrix, so its recursive estimate measures the float system,
    // which on sliver meshes lies far from the double one (about 2e-4 at 1e-5 caps), while the confirmed
    // one measures the system the CPU solves. The refreshed residual then also corrects phi towards the
    // double solution (mixed-precision iterative refinement). The CPU updates in double: only for
    // tight tolerances. A refuted claim counts towards the precision floor (at_precision_floor).
    virtual bool confirms_convergence() const = 0;

    // What the subclasses' setters invalidate.
    // phi was set to zero (reset): the warm start and the eigenvalue estimates are gone.
    void phi_reset();
    // phi was set to given values: the residual is recomputed now when b is known.
    void phi_set();
    // Before b changes: whether r = b - M phi is current, so it can follow the change of b alone.
    bool residual_follows_b() const { return has_b_ && !refresh_; }
    // After b changed (and r followed it, if residual_follows_b()).
    void right_hand_side_set();
    // After the operator's values changed (painting): r is stale and the eigenvalue estimates no
    // longer hold.
    void operator_changed();
    // r = b - M phi now; returns residual_drift of the replaced r.
    double refresh_residual();
    // For update_values: checks `matrix` against level 0's pattern and the rows against its size, then
    // copies the rows' values into `level0` (and into `interleaved`, 3 per stored entry, when given).
    void copy_changed_rows(const DiffusionMatrix& matrix, std::span<const int32_t> changed_rows,
                           HierarchyLevel& level0, std::vector<double>* interleaved) const;

    FrameSolverOptions options_;
    size_t n_ = 0;
    std::unique_ptr<MultiresHierarchy> hierarchy_;
    std::unique_ptr<MultigridPreconditioner> preconditioner_;

private:
    FrameStep step_within(int max_vcycles, const FrameDeadline& deadline);
    // A new system or start: earlier refuted claims of convergence say nothing about it.
    void forget_refuted_claims();
    // Given the estimates from a recomputed residual, above the tolerance: whether the solve stops at
    // its precision floor (FrameStep::at_precision_floor).
    bool stopped_at_floor(const Rgb& estimates);

    std::string who_;
    bool has_b_ = false, refresh_ = true;
    bool phi_zero_ = true;  // phi is exactly zero (a cold start): r = b needs no product
    int updates_since_refresh_ = 0;
    // A claim of convergence is being confirmed (the residual was recomputed; the next V-cycle's
    // estimate decides); the largest channel estimate from the last recomputed residual this solve
    // judged (infinity: none) and the CG updates since; the claims refuted so far.
    bool confirming_ = false;
    double last_true_estimate_ = std::numeric_limits<double>::infinity();
    int updates_since_true_estimate_ = 0;
    int refuted_claims_ = 0;
    MultigridCgState cg_;  // the scalars, the stopping rule and the Lanczos estimate of lambda_min
};

}  // namespace waxwork
