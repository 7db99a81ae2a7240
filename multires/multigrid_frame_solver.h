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
#include "multires/multigrid_frame_cg.h"
#include "multires/multigrid_preconditioner.h"
#include "solver/diffusion_matrix.h"
#include "solver/frame_budget.h"

#include <Eigen/Core>

#include <array>
#include <memory>
#include <span>
#include <vector>

namespace waxwork {

class MultigridFrameSolver : public MultigridFrameCg {
public:
    // Builds the hierarchy and the preconditioner for the matrix (positions: the mesh's, rest frame).
    // phi starts at zero. Throws as build_multires_hierarchy and MultigridPreconditioner.
    MultigridFrameSolver(const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                         const FrameSolverOptions& options = {});
    // The same on a hierarchy built elsewhere for this matrix with options.hierarchy
    // (rebuild_multires_hierarchy after an edit). With `previous`, the solver before that edit
    // (new_of_old_vertex: the edit's level-0 vertex map; `hierarchy` rebuilt from previous->hierarchy()),
    // the preconditioner copies the Galerkin rows the edit left unchanged from previous's
    // (MultigridPreconditioner's rebuild constructor; the same operators either way). Throws
    // InvalidArgumentError when the hierarchy's level 0 is not the matrix's size, it was built with
    // other options, or the map does not fit `previous`.
    MultigridFrameSolver(const DiffusionMatrix& matrix, MultiresHierarchy hierarchy, const FrameSolverOptions& options = {},
                         const MultigridFrameSolver* previous = nullptr, std::span<const int32_t> new_of_old_vertex = {});
    ~MultigridFrameSolver();

    // As MultigridFrameCg says: step(), set_relative_tolerance(), and these on the host's vectors.
    void set_right_hand_side(const std::array<std::span<const double>, 3>& b) override;
    void reset() override;
    void set_phi(const std::array<std::span<const double>, 3>& phi) override;
    void update_values(const DiffusionMatrix& matrix, std::span<const int32_t> changed_rows) override;

    // The current solution of one channel (valid until the next step or reset).
    std::span<const double> phi(int channel) const;

private:
    void precondition() override;
    MultigridCgState::StepSums step_sums() override;
    void set_direction(const Rgb& beta, bool restart) override;
    Rgb multiply_direction() override;
    void update_solution(const Rgb& alpha) override;
    std::array<double, 6> compute_residual(bool phi_is_zero) override;
    // The double recursive residual drifts from b - M phi by rounding of order u * cond(M), which
    // matters only for tight tolerances (slivers push cond(M) to 1e8): those claims are confirmed (a
    // product with M, and a V-cycle when r moved), small against the many V-cycles they take; a
    // frame's 1e-2 is not.
    bool confirms_convergence() const override { return options_.relative_tolerance < 1e-6; }

    std::vector<double> values_;  // level 0, the three channels interleaved (3 per stored entry)
    std::array<std::vector<double>, 3> phi_;
    std::vector<double> b_, r_, z_, p_, q_;  // interleaved: entry 3 i + c is channel c at vertex i
};

}  // namespace waxwork
