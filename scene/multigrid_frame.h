// A frame of either multigrid frame solver (the CPU's, multires/multigrid_frame_solver.h, or the
// device's, multires/gpu_multigrid_frame_solver.h): CG preconditioned by the V-cycle on the hierarchy
// of Li et al. 2013 (Sec. 4.1, Eq. 16), the three rgb channels in one pass. Its state (phi, residual,
// search directions) persists across frames: a light change only moves the residual by the change of
// b, painting updates the changed level-0 rows and the coarse Galerkin rows depending on them, a new
// matrix rebuilds it.
//
// Its budget is counted in V-cycles: an iteration budget of k maps to max(1, k / 4) V-cycles (one costs
// about 4 Jacobi CG iterations of the three channels; 0 runs none), and the frame reports the V-cycles
// as each channel's iterations. A time limit is checked between V-cycles (at least one runs). Its error
// estimate lags one CG update when the budget runs out (an upper estimate, multigrid_frame_solver.h).
#pragma once

#include "multires/multigrid_frame_cg.h"
#include "multires/multigrid_preconditioner.h"
#include "scene/frame_solver.h"
#include "scene/pending_changes.h"

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace waxwork {

// Sends `solver` the changes `pending` records (values, b, phi as a warm start), runs the V-cycles
// `limits` allow and, when any ran, calls `read_phi` to copy the solver's phi to the host. `error`
// holds the last estimates, which a frame of no V-cycles reports (1 after a change).
std::array<LiveSolverChannel, 3> multigrid_frame(MultigridFrameCg& solver, PendingChanges& pending,
                                                 std::array<double, 3>& error, const DiffusionMatrix& matrix,
                                                 const std::array<std::vector<double>, 3>& b,
                                                 std::array<std::vector<double>, 3>& phi, const FrameLimits& limits,
                                                 double relative_tolerance, const std::array<bool, 3>& skip,
                                                 const std::function<void()>& read_phi);

// `text` followed by a note when `preconditioner` (may be null) runs with absolute lumping because
// its row-sum setup failed.
std::string with_lumping_note(std::string text, const MultigridPreconditioner* preconditioner);

}  // namespace waxwork
