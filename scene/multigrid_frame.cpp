#include "scene/multigrid_frame.h"

#include <algorithm>
#include <numeric>

namespace waxwork {

namespace {

// The editor's iteration budget (Jacobi CG iterations per channel) in multigrid V-cycles, so that a
// budget costs about the same frame time in either method: one V-cycle for the three channels costs
// about as much as 4 Jacobi CG iterations on the three channels (bench/live_solver_bench.cpp, spot at
// 100K tets: 3.5-4 ms against 1.0 ms). For that time it does much more: relighting at budget 8, one
// frame per 3 degrees, leaves 0.08% (l2) error where Jacobi CG leaves 1.06%, in 16 ms frames instead
// of 19 ms (BM_RelightFrames). A positive budget runs at least one V-cycle.
constexpr int kIterationsPerVcycle = 4;

int vcycle_budget(int iteration_budget) {
    return iteration_budget <= 0 ? 0 : std::max(1, iteration_budget / kIterationsPerVcycle);
}

}  // namespace

std::array<LiveSolverChannel, 3> multigrid_frame(MultigridFrameCg& solver, PendingChanges& pending,
                                                 std::array<double, 3>& error, const DiffusionMatrix& matrix,
                                                 const std::array<std::vector<double>, 3>& b,
                                                 std::array<std::vector<double>, 3>& phi, const FrameLimits& limits,
                                                 double relative_tolerance, const std::array<bool, 3>& skip,
                                                 const std::function<void()>& read_phi) {
    if (pending.all_values) {
        // All values on the kept pattern: every row changed (the hierarchy's graphs and Eq. 16 weights
        // depend on the pattern and rest positions only, so they stay).
        std::vector<int32_t> all(matrix.size());
        std::iota(all.begin(), all.end(), 0);
        solver.update_values(matrix, all);
    } else if (!pending.rows.empty()) {
        solver.update_values(matrix, pending.rows);  // paint: the changed rows and their coarse rows
    }
    pending.values_applied();
    if (pending.right_hand_sides) solver.set_right_hand_side({b[0], b[1], b[2]});
    pending.right_hand_sides = false;
    if (pending.solution) {
        // A zero phi is where the solver starts anyway (no product to form its residual).
        const bool zero = std::all_of(phi.begin(), phi.end(), [](const std::vector<double>& v) {
            return std::all_of(v.begin(), v.end(), [](double x) { return x == 0.0; });
        });
        if (zero)
            solver.reset();
        else
            solver.set_phi({phi[0], phi[1], phi[2]});
    }
    pending.solution = false;
    solver.set_relative_tolerance(relative_tolerance);

    std::array<LiveSolverChannel, 3> out;
    int vcycles = 0;
    // The channels are solved together: a channel within the tolerance rides along with the others.
    if (!(skip[0] && skip[1] && skip[2]) && vcycle_budget(limits.iterations) > 0) {
        const FrameStep step =
            limits.deadline.bounded()
                ? solver.step(budget_until(limits.deadline, 1, vcycle_budget(limits.iterations)), limits.clock)
                : solver.step(vcycle_budget(limits.iterations));
        vcycles = step.vcycles;
        error = step.estimated_relative_error;
        read_phi();  // the host copy: radiance, saves, cuts
    }
    for (int c = 0; c < 3; ++c) {
        if (skip[c]) {
            out[c] = {0, 0.0, true};
            continue;
        }
        // An estimate within the tolerance bounds the current phi's error even when it lags the last
        // update (the update only lowers the energy-norm error).
        out[c] = {vcycles, error[c], error[c] <= relative_tolerance};
    }
    return out;
}

std::string with_lumping_note(std::string text, const MultigridPreconditioner* preconditioner) {
    if (preconditioner && !preconditioner->lumping_fallback_reason().empty())
        text += ", absolute lumping (the row-sum setup failed)";
    return text;
}

}  // namespace waxwork
