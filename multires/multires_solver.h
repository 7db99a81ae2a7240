// The multi-resolution diffusion solver of Li et al. 2013 (TransCut, Sec. 4): solve the coarsest
// level to convergence, interpolate (Eq. 16) to the next finer level as its start vector, iterate
// there, and so on down to level 0. Coarse levels (non-symmetric, Eq. 17) use BiCGSTAB; level 0
// (symmetric positive definite, Eqs. 12-14) uses the project's Jacobi CG, warm-started.
//
// Fallback. Coarse matrices may be singular (Sec. 4.2). When BiCGSTAB breaks down or fails to
// improve on a level, that level's iterations are skipped: its start vector (the interpolated coarser
// solution, or zero on the coarsest level) is passed on unchanged and the reason is recorded. The
// result is always finite; the fine CG guarantees the accuracy.
//
// The object keeps its hierarchy and the last solution per channel, so a frame whose matrix pattern
// is unchanged (relighting, painting within tolerance) warm-starts from the previous frame
// (solve_frame) instead of repeating the coarse-to-fine pass.
//
// Corrected warm start (beyond the paper). After a rebuild the paper starts again from zero with the
// coarse-to-fine pass. When a close start exists (the last solution carried through a cut's vertex
// map, or the same vertices after relaxation), set_warm_start keeps it and lets the pass correct it:
// the pass runs on the residual equation M^0 e = b - M^0 x0 and level 0 starts at x0 + alpha e. The
// pass leaves a fraction of the error it is given; given x0's error rather than phi itself, it leaves
// a fraction of that. alpha = e.r / e.M^0 e minimises the energy norm of the error along e (M^0 is SPD),
// so the start is never worse than x0 in that norm, whatever the non-symmetric coarse levels returned.
#pragma once

#include "multires/bicgstab.h"
#include "multires/hierarchy.h"
#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "solver/frame_budget.h"

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace waxwork {

struct MultiresSolveOptions {
    double coarsest_tolerance = 1e-6;   // relative residual on the coarsest level
    int coarsest_max_iterations = 2000;
    double level_tolerance = 1e-4;      // relative residual on intermediate levels
    // Iteration budget per intermediate level. 2 rather than more: on spot (bench/multires_bench.cpp)
    // 10 iterations per level saved only 2 level-0 CG iterations over 2 and cost three times as much.
    int level_max_iterations = 2;
    double relative_tolerance = 1e-3;   // level-0 CG: estimated relative error (conjugate_gradient.h)
    int max_iterations = 10000;         // level-0 CG iteration budget
};

struct LevelSolveReport {
    int level = 0;
    int iterations = 0;
    double initial_relative_residual = 0;
    double relative_residual = 0;
    BicgstabStatus status = BicgstabStatus::Converged;
    bool skipped = false;  // the level's iterate was discarded (fallback)
    std::string reason;    // why, when skipped
};

struct MultiresSolveReport {
    std::vector<LevelSolveReport> coarse_levels;  // coarsest first
    ConjugateGradientResult fine;
    bool fine_restarted_cold = false;  // level-0 CG rejected the warm start and ran from zero
    std::string fine_failure;          // what the level-0 CG reported, if anything
    double coarse_ms = 0;
    double fine_ms = 0;
    // A frame that corrected a warm start (set_warm_start): the step alpha taken along the coarse
    // correction (0: the correction did not help and the start was kept as it was). Empty otherwise.
    std::optional<double> start_correction;

    int fallbacks() const {
        int count = 0;
        for (const auto& l : coarse_levels) count += l.skipped ? 1 : 0;
        return count;
    }
    // The skipped levels and why, "level 3: rho breakdown, start vector kept; level 1: ...", coarsest
    // first; empty when none was skipped.
    std::string fallback_reasons() const;
};

class MultiresSolver {
public:
    // Builds the hierarchy from the assembled system and the mesh positions (Eq. 16 weights).
    MultiresSolver(const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                   const HierarchyOptions& options = {});
    // Takes a hierarchy built elsewhere (rebuild_multires_hierarchy after an edit). Throws
    // InvalidArgumentError for a hierarchy with no levels.
    explicit MultiresSolver(MultiresHierarchy hierarchy);

    const MultiresHierarchy& hierarchy() const { return hierarchy_; }
    // Mutable access for callers that update coarse values in place (and for fault-injection tests).
    MultiresHierarchy& hierarchy() { return hierarchy_; }

    // Coarse-to-fine solve of M^0 x = b for one channel. x: output (its content is ignored).
    MultiresSolveReport solve(std::span<const double> b, int channel, std::span<double> x,
                              const MultiresSolveOptions& options = {});

    // Per-frame mode: at most `iteration_budget` level-0 CG iterations, warm-started from this
    // channel's previous solution (the first call runs the coarse-to-fine pass). The solution stays
    // in the object; returns it.
    std::span<const double> solve_frame(std::span<const double> b, int channel, int iteration_budget,
                                        MultiresSolveReport* report = nullptr,
                                        const MultiresSolveOptions& options = {});
    // The same within a frame budget (solver/frame_budget.h): at most budget.max_iterations level-0 CG
    // iterations (0: no limit) and/or until budget.max_milliseconds have passed on `clock` (empty:
    // steady_clock) since the call, checked before each CG iteration (at least one runs). A frame that
    // must first run the coarse-to-fine pass runs that pass whole, however long it takes: it is the
    // start vector the later frames warm-start from, and BiCGSTAB stopped part-way on a coarse level
    // would hand the finer levels a worse start, not a cheaper frame; the level-0 CG then gets what is
    // left (at least one iteration). An iteration-only budget gives the int overload's result bit for
    // bit. Throws InvalidArgumentError for an invalid budget (validate(FrameBudget)).
    std::span<const double> solve_frame(std::span<const double> b, int channel, const FrameBudget& budget,
                                        MultiresSolveReport* report = nullptr,
                                        const MultiresSolveOptions& options = {}, const MillisecondClock& clock = {});

    // After a material change (painting) on the same mesh: takes the new level-0 values and recomputes
    // the coarse matrices (Eq. 17) on the kept graphs and interpolation, without a new selection.
    // Throws InvalidArgumentError when the matrix pattern differs from the one the hierarchy was built on.
    void update_values(const DiffusionMatrix& matrix);
    // The same after a local change (painting): only the level-0 rows `changed_rows` (ascending, e.g.
    // from update_diffusion_matrix) differ from the hierarchy's. Copies those rows and recomputes the
    // coarse rows that depend on them, level by level (Eq. 17 row c reads fine row parent_vertex[c]
    // only), in time proportional to the change. Equals update_values(matrix) bit for bit.
    // Throws InvalidArgumentError on a changed pattern or a row out of range.
    // Returns the rows that changed on each level (level 0: changed_rows sorted and unique), what a
    // device copy of the hierarchy re-uploads (GpuMultiresSolver::update_rows).
    std::vector<std::vector<int32_t>> update_values(const DiffusionMatrix& matrix, std::span<const int32_t> changed_rows);

    // Forget the previous frames' solutions (after an edit that changes the solution a lot).
    void reset_warm_start();
    // The next solve_frame of `channel` starts from `start` corrected by the coarse-to-fine pass (see
    // the top of this file) instead of from the pass alone; later frames warm-start from its result.
    // An all-zero start is the cold pass itself (as after reset_warm_start). Throws
    // InvalidArgumentError for a start whose size is not level 0's or that is not finite.
    void set_warm_start(int channel, std::span<const double> start);

private:
    MultiresSolveReport solve_within(std::span<const double> b, int channel, std::span<double> x,
                                     const MultiresSolveOptions& options, const FrameDeadline& deadline);
    std::span<const double> solve_frame_within(std::span<const double> b, int channel, int max_iterations,
                                               MultiresSolveReport* report, const MultiresSolveOptions& options,
                                               const FrameDeadline& deadline);
    void solve_fine(std::span<const double> b, int channel, std::span<double> x, const MultiresSolveOptions& options,
                    MultiresSolveReport& report, const FrameDeadline& deadline);
    // The coarse-to-fine pass for right-hand side b: x = the interpolated level-1 iterate (zero with one
    // level); fills report.coarse_levels and report.coarse_ms.
    void coarse_pass(std::span<const double> b, int channel, std::span<double> x, const MultiresSolveOptions& options,
                     MultiresSolveReport& report);
    // x = x + alpha e with e the coarse pass on b - M^0 x and alpha the energy-minimising step (top of
    // this file); records alpha in report.start_correction.
    void correct_start(std::span<const double> b, int channel, std::span<double> x, const MultiresSolveOptions& options,
                       MultiresSolveReport& report);

    MultiresHierarchy hierarchy_;
    std::array<std::vector<double>, 3> last_solution_;
    std::array<bool, 3> correct_last_{};  // set_warm_start: the next frame corrects last_solution_ first
    std::array<double, 3> eigenvalue_hint_{};
};

}  // namespace waxwork
