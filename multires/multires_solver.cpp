#include "multires/multires_solver.h"

#include "base/error.h"
#include "base/timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

namespace waxwork {

std::string MultiresSolveReport::fallback_reasons() const {
    std::string reasons;
    for (const LevelSolveReport& level : coarse_levels)
        if (level.skipped) reasons += (reasons.empty() ? "" : "; ") + ("level " + std::to_string(level.level) + ": " + level.reason);
    return reasons;
}

namespace {

void check_channel(int channel) {
    if (channel < 0 || channel > 2)
        throw InvalidArgumentError("multires solve: channel " + std::to_string(channel) + " is not 0, 1 or 2");
}

}  // namespace

MultiresSolver::MultiresSolver(const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                               const HierarchyOptions& options)
    : hierarchy_(build_multires_hierarchy(matrix, positions, options)) {}

MultiresSolver::MultiresSolver(MultiresHierarchy hierarchy) : hierarchy_(std::move(hierarchy)) {
    if (hierarchy_.levels.empty()) throw InvalidArgumentError("multires solver: the hierarchy has no levels");
}

void MultiresSolver::update_values(const DiffusionMatrix& matrix) {
    HierarchyLevel& level0 = hierarchy_.levels[0];
    if (matrix.offsets != level0.offsets || matrix.columns != level0.columns)
        throw InvalidArgumentError("multires update_values: the matrix pattern changed (rebuild the solver)");
    level0.values = matrix.values;
    for (size_t l = 1; l < hierarchy_.level_count(); ++l)
        build_coarse_matrix(hierarchy_.levels[l - 1], hierarchy_.levels[l].parent_vertex, hierarchy_.levels[l]);
}

std::vector<std::vector<int32_t>> MultiresSolver::update_values(const DiffusionMatrix& matrix,
                                                               std::span<const int32_t> changed_rows) {
    HierarchyLevel& level0 = hierarchy_.levels[0];
    if (matrix.offsets.size() != level0.offsets.size() || matrix.columns.size() != level0.columns.size())
        throw InvalidArgumentError("multires update_values: the matrix pattern changed (rebuild the solver)");
    std::vector<int32_t> changed(changed_rows.begin(), changed_rows.end());
    std::sort(changed.begin(), changed.end());
    changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
    for (int32_t row : changed) {
        if (row < 0 || static_cast<size_t>(row) >= level0.size())
            throw InvalidArgumentError("multires update_values: row " + std::to_string(row) + " out of range");
        const auto begin = static_cast<size_t>(level0.offsets[static_cast<size_t>(row)]);
        const auto end = static_cast<size_t>(level0.offsets[static_cast<size_t>(row) + 1]);
        for (size_t ch = 0; ch < 3; ++ch)
            std::copy(matrix.values[ch].begin() + static_cast<std::ptrdiff_t>(begin),
                      matrix.values[ch].begin() + static_cast<std::ptrdiff_t>(end),
                      level0.values[ch].begin() + static_cast<std::ptrdiff_t>(begin));
    }
    std::vector<std::vector<int32_t>> level_rows(hierarchy_.level_count());
    level_rows[0] = changed;
    std::vector<int32_t> rows;
    for (size_t l = 1; l < hierarchy_.level_count() && !changed.empty(); ++l) {
        HierarchyLevel& coarse = hierarchy_.levels[l];
        // Coarse vertices keep their fine order, so parent_vertex is ascending: binary search per row.
        rows.clear();
        for (int32_t i : changed) {
            const auto it = std::lower_bound(coarse.parent_vertex.begin(), coarse.parent_vertex.end(), i);
            if (it != coarse.parent_vertex.end() && *it == i)
                rows.push_back(static_cast<int32_t>(it - coarse.parent_vertex.begin()));
        }
        update_coarse_rows(hierarchy_.levels[l - 1], coarse.parent_vertex, coarse, rows);
        level_rows[l] = rows;
        changed.swap(rows);
    }
    return level_rows;
}

void MultiresSolver::reset_warm_start() {
    for (auto& s : last_solution_) s.clear();
    correct_last_ = {};
    eigenvalue_hint_ = {};
}

void MultiresSolver::set_warm_start(int channel, std::span<const double> start) {
    check_channel(channel);
    const size_t n0 = hierarchy_.levels[0].size();
    if (start.size() != n0)
        throw InvalidArgumentError("multires set_warm_start: a start of size " + std::to_string(start.size()) + " for " +
                                   std::to_string(n0) + " vertices");
    if (!std::all_of(start.begin(), start.end(), [](double v) { return std::isfinite(v); }))
        throw InvalidArgumentError("multires set_warm_start: the start is not finite");
    const auto c = static_cast<size_t>(channel);
    if (std::all_of(start.begin(), start.end(), [](double v) { return v == 0.0; })) {
        last_solution_[c].clear();  // the cold pass, exactly as the paper runs it
        correct_last_[c] = false;
        return;
    }
    last_solution_[c].assign(start.begin(), start.end());
    correct_last_[c] = true;
}

void MultiresSolver::solve_fine(std::span<const double> b, int channel, std::span<double> x,
                                const MultiresSolveOptions& options, MultiresSolveReport& report,
                                const FrameDeadline& deadline) {
    const auto start = std::chrono::steady_clock::now();
    const HierarchyLevel& level0 = hierarchy_.levels[0];
    ConjugateGradientOptions cg;
    cg.relative_tolerance = options.relative_tolerance;
    cg.max_iterations = options.max_iterations;
    cg.smallest_eigenvalue_hint = eigenvalue_hint_[static_cast<size_t>(channel)];
    cg.deadline = deadline;  // the cold retry below shares it (and still runs at least one iteration)
    try {
        report.fine = solve_jacobi_cg<double>(level0.view(channel), b, x, cg);
    } catch (const AlgorithmError& error) {
        // A warm start cannot make an SPD system fail; if CG still objects, record it and retry from
        // zero so the answer does not depend on the coarse levels at all. A second failure is real.
        report.fine_failure = error.what();
        report.fine_restarted_cold = true;
        std::fill(x.begin(), x.end(), 0.0);
        cg.smallest_eigenvalue_hint = 0;
        report.fine = solve_jacobi_cg<double>(level0.view(channel), b, x, cg);
    }
    if (report.fine.smallest_eigenvalue_estimate > 0)
        eigenvalue_hint_[static_cast<size_t>(channel)] = report.fine.smallest_eigenvalue_estimate;
    report.fine_ms = milliseconds_since(start);
}

MultiresSolveReport MultiresSolver::solve(std::span<const double> b, int channel, std::span<double> x,
                                          const MultiresSolveOptions& options) {
    return solve_within(b, channel, x, options, FrameDeadline{});
}

MultiresSolveReport MultiresSolver::solve_within(std::span<const double> b, int channel, std::span<double> x,
                                                 const MultiresSolveOptions& options, const FrameDeadline& deadline) {
    check_channel(channel);
    const size_t n0 = hierarchy_.levels[0].size();
    if (b.size() != n0 || x.size() != n0)
        throw InvalidArgumentError("multires solve: vectors of size " + std::to_string(b.size()) + " and " +
                                   std::to_string(x.size()) + " for " + std::to_string(n0) + " vertices");
    MultiresSolveReport report;
    coarse_pass(b, channel, x, options, report);
    solve_fine(b, channel, x, options, report, deadline);
    std::vector<double>& last = last_solution_[static_cast<size_t>(channel)];
    if (last.data() != x.data()) last.assign(x.begin(), x.end());  // solve_frame passes `last` itself
    return report;
}

void MultiresSolver::coarse_pass(std::span<const double> b, int channel, std::span<double> x,
                                 const MultiresSolveOptions& options, MultiresSolveReport& report) {
    const auto start = std::chrono::steady_clock::now();
    const size_t levels = hierarchy_.level_count();
    std::vector<double> coarse_x;  // the current level's iterate, starting on the coarsest level at zero
    std::vector<double> level_b;
    for (size_t l = levels; l-- > 1;) {
        const HierarchyLevel& level = hierarchy_.levels[l];
        level_b.resize(level.size());
        restrict_right_hand_side(level, b, level_b);
        if (l == levels - 1) {
            coarse_x.assign(level.size(), 0.0);
        } else {
            std::vector<double> finer(level.size());
            interpolate(level.interpolation, coarse_x, finer);
            coarse_x.swap(finer);
        }
        const bool coarsest = l == levels - 1;
        BicgstabOptions bicg;
        bicg.relative_tolerance = coarsest ? options.coarsest_tolerance : options.level_tolerance;
        bicg.max_iterations = coarsest ? options.coarsest_max_iterations : options.level_max_iterations;
        const BicgstabResult result = solve_jacobi_bicgstab(level.view(channel), level.diagonal, level_b, coarse_x, bicg);
        LevelSolveReport entry;
        entry.level = static_cast<int>(l);
        entry.iterations = result.iterations;
        entry.initial_relative_residual = result.initial_relative_residual;
        entry.relative_residual = result.relative_residual;
        entry.status = result.status;
        // A breakdown after progress keeps the improved iterate (it is a valid start vector); a level
        // that made things worse is skipped: BiCGSTAB already handed back its start vector.
        entry.skipped = result.reverted;
        if (result.reverted || result.failed())
            entry.reason = std::string(to_string(result.status)) + (result.reverted ? ", start vector kept" : "");
        report.coarse_levels.push_back(std::move(entry));
    }
    if (levels > 1) {
        interpolate(hierarchy_.levels[0].interpolation, coarse_x, x);
    } else {
        std::fill(x.begin(), x.end(), 0.0);
    }
    report.coarse_ms = milliseconds_since(start);
}

void MultiresSolver::correct_start(std::span<const double> b, int channel, std::span<double> x,
                                   const MultiresSolveOptions& options, MultiresSolveReport& report) {
    const size_t n = x.size();
    const CsrMatrixView<double> matrix = hierarchy_.levels[0].view(channel);
    std::vector<double> residual(n), correction(n), product(n);
    multiply<double>(matrix, x, residual);
    for (size_t i = 0; i < n; ++i) residual[i] = b[i] - residual[i];
    coarse_pass(residual, channel, correction, options, report);
    multiply<double>(matrix, correction, product);
    double along = 0, curvature = 0;  // e.r and e.M e
    for (size_t i = 0; i < n; ++i) {
        along += correction[i] * residual[i];
        curvature += correction[i] * product[i];
    }
    // The energy of x + alpha e falls by along^2 / (2 curvature) at this alpha; a zero (one level, or
    // every coarse level skipped) or non-finite correction leaves x as it was.
    const double alpha = curvature > 0 && std::isfinite(along) && std::isfinite(curvature) ? along / curvature : 0.0;
    if (alpha != 0)
        for (size_t i = 0; i < n; ++i) x[i] += alpha * correction[i];
    report.start_correction = alpha;
}

std::span<const double> MultiresSolver::solve_frame(std::span<const double> b, int channel, int iteration_budget,
                                                    MultiresSolveReport* report, const MultiresSolveOptions& options) {
    return solve_frame_within(b, channel, std::max(iteration_budget, 0), report, options, FrameDeadline{});
}

std::span<const double> MultiresSolver::solve_frame(std::span<const double> b, int channel, const FrameBudget& budget,
                                                    MultiresSolveReport* report, const MultiresSolveOptions& options,
                                                    const MillisecondClock& clock) {
    validate(budget);
    // The deadline starts here, so a coarse-to-fine pass counts against the frame.
    const FrameDeadline deadline = FrameDeadline::of(budget, clock);
    const int max_iterations = budget.limits_iterations() ? budget.max_iterations : std::numeric_limits<int>::max();
    return solve_frame_within(b, channel, max_iterations, report, options, deadline);
}

std::span<const double> MultiresSolver::solve_frame_within(std::span<const double> b, int channel, int max_iterations,
                                                           MultiresSolveReport* report,
                                                           const MultiresSolveOptions& options,
                                                           const FrameDeadline& deadline) {
    check_channel(channel);
    MultiresSolveOptions budgeted = options;
    budgeted.max_iterations = max_iterations;
    std::vector<double>& last = last_solution_[static_cast<size_t>(channel)];
    MultiresSolveReport local;
    bool& correct = correct_last_[static_cast<size_t>(channel)];
    if (last.size() != hierarchy_.levels[0].size()) {
        last.assign(hierarchy_.levels[0].size(), 0.0);
        correct = false;
        local = solve_within(b, channel, last, budgeted, deadline);
    } else {
        if (b.size() != last.size())
            throw InvalidArgumentError("multires solve_frame: right-hand side of size " + std::to_string(b.size()) +
                                       " for " + std::to_string(last.size()) + " vertices");
        if (correct) {
            correct = false;
            correct_start(b, channel, last, budgeted, local);
        }
        solve_fine(b, channel, last, budgeted, local, deadline);
    }
    if (report) *report = std::move(local);
    return last;
}

}  // namespace waxwork
