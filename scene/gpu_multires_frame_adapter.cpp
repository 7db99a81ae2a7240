#include "scene/gpu_multires_frame_adapter.h"

#include <algorithm>
#include <iterator>
#include <numeric>
#include <string>
#include <utility>

namespace waxwork {

void GpuMultiresFrameAdapter::matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                                             std::span<const int32_t> new_of_old_vertex) {
    host_.matrix_rebuilt(mesh, matrix, new_of_old_vertex);
    device_pending_ = PendingChanges{};
    level_rows_.clear();
    context_.free_device_for_new_matrix(device_);
}

void GpuMultiresFrameAdapter::values_changed() {
    host_.values_changed();
    device_pending_.values_changed();
    level_rows_.clear();
}

void GpuMultiresFrameAdapter::right_hand_sides_changed() {
    device_pending_.right_hand_sides = true;
    host_.error = {1, 1, 1};
}

void GpuMultiresFrameAdapter::apply_host_changes(const DiffusionMatrix& matrix) {
    const bool all_values = host_.pending.all_values;
    const std::vector<std::vector<int32_t>> changed = host_.apply_values(matrix);
    if (all_values) {
        level_rows_.clear();  // device_pending_.all_values: the device takes every row
    } else if (!changed.empty() && !device_pending_.all_values) {
        level_rows_.resize(std::max(level_rows_.size(), changed.size()));
        for (size_t l = 0; l < changed.size(); ++l) {
            std::vector<int32_t> merged;
            std::set_union(level_rows_[l].begin(), level_rows_[l].end(), changed[l].begin(), changed[l].end(),
                           std::back_inserter(merged));
            level_rows_[l].swap(merged);
        }
    }
}

FrameResult GpuMultiresFrameAdapter::iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                                             std::array<std::vector<double>, 3>& phi, const FrameLimits& limits,
                                             double relative_tolerance, const std::array<bool, 3>& skip) {
    FrameResult result;
    auto& out = result.channels;
    if (matrix.size() == 0 || (skip[0] && skip[1] && skip[2])) {
        out = idle_gpu_frame(matrix.size(), skip);
        return result;
    }
    MultiresSolver& host = host_.solver_for(matrix);
    SolverGlContext& context = context_.open();
    const CurrentContext current(context);
    const GlApi& gl = context.gl();
    const MultiresHierarchy& hierarchy = host.hierarchy();
    if (context_.make_device(device_, gl, [&] { return std::make_unique<GpuMultiresSolver>(gl, matrix, hierarchy); })) {
        device_pending_ = PendingChanges{};  // a new device copy: the current values; b to send
        level_rows_.clear();
        host_.pending.solution = true;  // its phi starts at zero: start from the host phi (below)
    } else if (device_pending_.all_values) {
        // All values: every row of every level (the uploaded patterns stay).
        std::vector<std::vector<int32_t>> all(hierarchy.level_count());
        for (size_t l = 0; l < all.size(); ++l) {
            all[l].resize(hierarchy.levels[l].size());
            std::iota(all[l].begin(), all[l].end(), 0);
        }
        device_->solver->update_rows(matrix, hierarchy, all);
    } else if (!level_rows_.empty()) {
        device_->solver->update_rows(matrix, hierarchy, level_rows_);  // paint: O(changed entries)
    }
    device_pending_.values_applied();
    level_rows_.clear();
    GpuMultiresSolver& solver = *device_->solver;
    if (device_pending_.right_hand_sides) solver.set_right_hand_side(b);
    device_pending_.right_hand_sides = false;

    const int iteration_budget = limits.iterations;
    if (iteration_budget <= 0) {
        for (int c = 0; c < 3; ++c) out[c] = {0, host_.error[c], host_.error[c] <= relative_tolerance};
        return result;
    }
    GpuCgOptions fine;
    fine.relative_tolerance = relative_tolerance;
    fine.max_iterations = iteration_budget;
    fine.use_eigenvalue_hints = true;
    std::array<ConjugateGradientResult, 3> results;
    if (host_.pending.solution) {
        const bool warm = std::any_of(phi.begin(), phi.end(), [](const std::vector<double>& p) {
            return std::any_of(p.begin(), p.end(), [](double v) { return v != 0.0; });
        });
        if (warm) {
            // The host phi corrected coarse to fine (MultiresSolver::set_warm_start) on the host hierarchy
            // the device copy was made from, so both backends start the frame from the same vector; the
            // pass runs once per rebuild, and level 0 then iterates on the device.
            host.reset_warm_start();
            std::vector<std::array<double, 3>> start(phi[0].size());
            std::string coarse_fallbacks;
            for (int c = 0; c < 3; ++c) {
                host.set_warm_start(c, phi[c]);
                MultiresSolveReport report;
                const std::span<const double> corrected = host.solve_frame(b[c], c, 0, &report);
                for (size_t v = 0; v < start.size(); ++v) start[v][c] = corrected[v];
                append_coarse_fallbacks(coarse_fallbacks, c, report);
            }
            result.method_note = coarse_pass_note(coarse_fallbacks);
            solver.set_solution(start);
            results = solver.solve_fine(fine);
        } else {
            MultiresSolveOptions options;
            options.relative_tolerance = relative_tolerance;
            options.max_iterations = iteration_budget;
            const GpuMultiresReport report = solver.solve(options, fine);
            results = report.fine;
            result.method_note = coarse_pass_note(report.fallback_reasons());
        }
        host_.pending.solution = false;
    } else {
        results = solver.solve_fine(fine);  // warm from the resident phi
    }
    auto& staging = device_->staging;
    staging = solver.solution();
    const size_t n = staging.size();
    for (size_t v = 0; v < n; ++v)
        for (int c = 0; c < 3; ++c) phi[c][v] = staging[v][c];
    for (int c = 0; c < 3; ++c) {
        host_.error[c] = results[c].estimated_relative_error;
        out[c] = {results[c].iterations, results[c].estimated_relative_error, results[c].converged};
    }
    return result;
}

std::unique_ptr<FrameSolver> GpuMultiresFrameAdapter::cpu_successor() {
    return std::make_unique<MultiresFrameAdapter>(std::move(host_));
}

}  // namespace waxwork
