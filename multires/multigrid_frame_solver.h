// The per-frame solver of the live editor: the three rgb channels of the diffusion system (Li et al.
// 2013, Eq. 8 assembled as solver/diffusion_matrix.h) solved together by conjugate gradients
// preconditioned with the multigrid V-cycle (multires/multigrid_preconditioner.h), warm-started from
// the previous frame and limited to a budget of V-cycles per frame.
//
// Why all three channels in one pass. The channels share the matrix pattern and differ only in
// values, so one sweep over the pattern can serve the three right-hand sides (MultigridPreconditioner::
// apply_rgb; the level-0 products here likewise). The column indices are read once instead of three
// times and a row's neighbours' entries share cache lines: at 500K tets the V-cycle is bound by
// memory traffic, which this cuts (bench/multires_bench.cpp, BM_LightTurn10Degrees modes 3-4).
//
// Why a V-cycle budget. A frame has a fixed time; the solver state (phi, the residual, the search
// directions) persists between frames, so a frame that ran out of budget resumes where it stopped.
// A new light only changes the right-hand side b: the residual r = b - M phi is updated by the change
// of b (no product with M) and CG restarts from the previous frame's phi.
//
// Estimated error. Each V-cycle z = B r gives the energy-norm estimate of solve_multigrid_cg
// (multigrid_cg.h): ||phi* - phi||_M / ||phi||_M <= sqrt((r . z) / lambda_min(B M) / (phi . M phi)), with
// lambda_min estimated by the smallest Ritz value of CG's Lanczos matrix (kept across frames as the
// smallest seen). A step ends either with every channel at or below the tolerance (phi unchanged since
// the estimate: `converged`) or with the budget spent; in the latter case the last V-cycle's estimate is
// of phi before the step's last CG update, which only lowers the energy-norm error, so it is an upper
// estimate (one V-cycle is saved per frame by not re-estimating after the update).
//
// Precision. phi, r and the level-0 products in double; the V-cycle in float (MultigridOptions).
// Deterministic: every sum has a fixed order, so the result is bit-identical on any thread count.
#pragma once

#include "multires/hierarchy.h"
#include "multires/multigrid_cg_state.h"
#include "multires/multigrid_preconditioner.h"
#include "solver/diffusion_matrix.h"
#include "solver/frame_budget.h"

#include <Eigen/Core>

#include <array>
#include <memory>
#include <span>
#include <vector>

namespace waxwork {

struct FrameSolverOptions {
    HierarchyOptions hierarchy;
    MultigridOptions multigrid;
    double relative_tolerance = 1e-2;     // step() stops early once every channel's estimate is below
    int residual_refresh_interval = 50;   // CG updates between recomputing r = b - M phi exactly
};

struct FrameStep {
    std::array<double, 3> estimated_relative_error{};  // per channel (see the header comment)
    int vcycles = 0;                                    // V-cycles run (<= budget)
    bool converged = false;                             // every estimate <= tolerance, of the current phi
};

class MultigridFrameSolver {
public:
    // Builds the hierarchy and the preconditioner for the matrix (positions: the mesh's, rest frame).
    // phi starts at zero. Throws as build_multires_hierarchy and MultigridPreconditioner.
    MultigridFrameSolver(const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                         const FrameSolverOptions& options = {});
    ~MultigridFrameSolver();
    MultigridFrameSolver(const MultigridFrameSolver&) = delete;
    MultigridFrameSolver& operator=(const MultigridFrameSolver&) = delete;

    // The three channels' right-hand sides (diffusion_right_hand_side) of the current light. Cheap:
    // the residual follows the change of b. Throws InvalidArgumentError on a size mismatch and
    // AlgorithmError on non-finite values (the state is then unchanged).
    void set_right_hand_side(const std::array<std::span<const double>, 3>& b);

    // Runs at most `budget` V-cycles (each followed by one CG update unless converged). Throws
    // InvalidArgumentError when no right-hand side was set or budget < 1, AlgorithmError when the
    // matrix or preconditioner turns out not to be positive definite.
    FrameStep step(int budget);
    // The same within a frame budget (solver/frame_budget.h): budget.max_iterations counts V-cycles
    // (0: no limit), budget.max_milliseconds runs on `clock` (empty: steady_clock) from the call and
    // is checked between V-cycles (each with its CG update finishes; at least one runs). Stopping
    // between V-cycles leaves the same state as a V-cycle budget would: a budget that ran k V-cycles
    // equals step(k) bit for bit, and the next frame resumes from it. Throws InvalidArgumentError for
    // an invalid budget (validate(FrameBudget)) and as step(int).
    FrameStep step(const FrameBudget& budget, const MillisecondClock& clock = {});

    // The tolerance step() stops at (FrameSolverOptions::relative_tolerance), e.g. a tighter one to
    // converge a scene the frames left at a looser one. Throws InvalidArgumentError unless positive.
    void set_relative_tolerance(double tolerance);

    // The current solution of one channel (valid until the next step or reset).
    std::span<const double> phi(int channel) const;
    // phi = 0 (forgets the warm start and the eigenvalue estimates).
    void reset();
    // Warm start from given solutions (e.g. a saved frame); the eigenvalue estimates are kept (same
    // operator). When a right-hand side is set, the residual is recomputed here, not in the next step.
    // Throws InvalidArgumentError on a size mismatch, AlgorithmError on non-finite values.
    void set_phi(const std::array<std::span<const double>, 3>& phi);

    // After update_diffusion_matrix rewrote `changed_rows` (ascending) with an unchanged pattern
    // (painting): updates level 0, the preconditioner's affected coarse rows and the residual. The
    // hierarchy's Eq. 17 matrices (levels >= 1) are left as they were: this solver does not use them.
    void update_values(const DiffusionMatrix& matrix, std::span<const int32_t> changed_rows);

    size_t size() const { return n_; }
    const MultiresHierarchy& hierarchy() const { return *hierarchy_; }
    const MultigridPreconditioner& preconditioner() const { return *preconditioner_; }

private:
    FrameStep step_within(int max_vcycles, const FrameDeadline& deadline);
    void refresh_residual();

    FrameSolverOptions options_;
    size_t n_ = 0;
    std::unique_ptr<MultiresHierarchy> hierarchy_;
    std::unique_ptr<MultigridPreconditioner> preconditioner_;
    std::vector<double> values_;  // level 0, the three channels interleaved (3 per stored entry)
    std::array<std::vector<double>, 3> phi_;
    std::vector<double> b_, r_, z_, p_, q_;  // interleaved: entry 3 i + c is channel c at vertex i
    bool has_b_ = false, refresh_ = true;
    bool phi_zero_ = true;  // phi is exactly zero (a cold start): r = b needs no product
    int updates_since_refresh_ = 0;
    MultigridCgState cg_;  // the scalars, the stopping rule and the Lanczos estimate of lambda_min
};

}  // namespace waxwork
