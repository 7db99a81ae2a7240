#include "scene/multires_frame_adapter.h"

#include "base/error.h"
#include "scene/rebuilt_hierarchy.h"

#include <algorithm>
#include <optional>
#include <utility>

namespace waxwork {

void MultiresHostState::matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                                       std::span<const int32_t> new_of_old_vertex) {
    const std::unique_ptr<MultiresSolver> previous = std::move(solver);
    error = {1, 1, 1};
    pending = PendingChanges{};  // nothing of the old matrix is pending; phi is
    if (matrix.size() == 0) return;
    std::optional<MultiresHierarchy> carried =
        rebuilt_hierarchy(previous ? &previous->hierarchy() : nullptr, new_of_old_vertex, matrix, mesh.positions);
    solver = carried ? std::make_unique<MultiresSolver>(std::move(*carried))
                     : std::make_unique<MultiresSolver>(matrix, mesh.positions);
}

void MultiresHostState::values_changed() {
    error = {1, 1, 1};
    pending.values_changed();
}

void MultiresHostState::rows_changed(std::span<const int32_t> rows) {
    error = {1, 1, 1};
    if (solver) pending.rows_changed(rows);  // a hierarchy built later takes the current values
}

void MultiresHostState::solution_changed() {
    error = {1, 1, 1};
    pending.solution = true;  // start from the new host phi, corrected coarse to fine
}

std::vector<std::vector<int32_t>> MultiresHostState::apply_values(const DiffusionMatrix& matrix) {
    std::vector<std::vector<int32_t>> level_rows;
    if (!solver) return level_rows;
    if (pending.all_values) {
        solver->update_values(matrix);  // all values on the kept pattern and selection
    } else if (!pending.rows.empty()) {
        // Paint: the changed level-0 rows and the Eq. 17 coarse rows that read them.
        level_rows = solver->update_values(matrix, pending.rows);
    }
    pending.values_applied();
    return level_rows;
}

MultiresSolver& MultiresHostState::solver_for(const DiffusionMatrix& matrix) {
    if (!solver || solver->hierarchy().levels[0].size() != matrix.size())
        throw InvalidArgumentError(
            "live solver: the multires hierarchy was not built for this matrix (matrix_rebuilt first)");
    return *solver;
}

void append_coarse_fallbacks(std::string& notes, int c, const MultiresSolveReport& report) {
    static constexpr const char* kChannelNames[] = {"red", "green", "blue"};
    if (const std::string reasons = report.fallback_reasons(); !reasons.empty())
        notes += (notes.empty() ? "" : "; ") + (kChannelNames[c] + (": " + reasons));
}

std::string coarse_pass_note(const std::string& notes) {
    // A skipped level costs level-0 iterations, not accuracy (the level-0 CG converges from any start),
    // but a user watching the multires method should know its coarse start did not work as meant.
    return notes.empty() ? ""
                         : "multires: the coarse-to-fine pass skipped " + notes + " (level-0 CG converges regardless)";
}

MultiresFrameAdapter::MultiresFrameAdapter(MultiresHostState host) : host_(std::move(host)) {
    host_.pending.solution = true;
}

FrameResult MultiresFrameAdapter::iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                                          std::array<std::vector<double>, 3>& phi, const FrameLimits& limits,
                                          double relative_tolerance, const std::array<bool, 3>& skip) {
    FrameResult result;
    auto& out = result.channels;
    if (matrix.size() == 0) {
        for (auto& channel : out) channel = {0, 0.0, true};
        return result;
    }
    MultiresSolver& solver = host_.solver_for(matrix);
    const int iteration_budget = limits.iterations;
    if (iteration_budget > 0 && host_.pending.solution) {
        // solve_frame then runs the coarse-to-fine pass: on its own from a zero phi (a new scene), as a
        // correction of the host phi otherwise (carried through a cut, or kept through a relaxation).
        solver.reset_warm_start();
        for (int c = 0; c < 3; ++c)
            if (phi[c].size() == solver.hierarchy().levels[0].size()) solver.set_warm_start(c, phi[c]);
        host_.pending.solution = false;
    }
    MultiresSolveOptions options;
    options.relative_tolerance = relative_tolerance;
    int channels_left = static_cast<int>(std::count(skip.begin(), skip.end(), false));
    std::string coarse_fallbacks;
    bool coarse_pass = false;
    for (int c = 0; c < 3; ++c) {
        if (skip[c]) {
            out[c] = {0, 0.0, true};
            continue;
        }
        const int parts = channels_left--;
        if (iteration_budget <= 0) {
            out[c] = {0, host_.error[c], host_.error[c] <= relative_tolerance};
            continue;
        }
        MultiresSolveReport report;
        // As for Jacobi CG: each channel's level-0 CG gets its share of the frame's time left.
        const std::span<const double> solved =
            limits.deadline.bounded()
                ? solver.solve_frame(b[c], c, budget_until(limits.deadline, parts, iteration_budget), &report, options,
                                     limits.clock)
                : solver.solve_frame(b[c], c, iteration_budget, &report, options);
        std::copy(solved.begin(), solved.end(), phi[c].begin());  // the host copy: radiance, saves, cuts
        if (!report.coarse_levels.empty()) {
            coarse_pass = true;
            append_coarse_fallbacks(coarse_fallbacks, c, report);
        }
        host_.error[c] = report.fine.estimated_relative_error;
        out[c] = {report.fine.iterations, report.fine.estimated_relative_error, report.fine.converged};
    }
    if (coarse_pass) result.method_note = coarse_pass_note(coarse_fallbacks);
    return result;
}

}  // namespace waxwork
