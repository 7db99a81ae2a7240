#include "multires/gpu_multires_solver.h"

#include "base/error.h"

namespace waxwork {

std::string GpuMultiresReport::fallback_reasons() const {
    static constexpr const char* kChannels[] = {"red", "green", "blue"};
    std::string reasons;
    for (int c = 0; c < 3; ++c) {
        std::string channel;
        for (size_t k = 0; k < coarse_levels.size(); ++k)
            if (coarse_levels[k][c].reverted)
                channel += (channel.empty() ? "" : "; ") + ("level " + std::to_string(coarse_levels.size() - k) + ": " +
                                                            to_string(coarse_levels[k][c].status) + ", start vector kept");
        if (!channel.empty()) reasons += (reasons.empty() ? "" : "; ") + (kChannels[c] + (": " + channel));
    }
    return reasons;
}
namespace {

RgbCsrView level_view(const HierarchyLevel& level) {
    return {level.offsets, level.columns, level.diagonal, {level.values[0], level.values[1], level.values[2]}};
}

std::unique_ptr<GpuInterpolation> upload_interpolation(const GlApi& gl, const InterpolationOperator& p) {
    return std::make_unique<GpuInterpolation>(gl, p.offsets, p.columns, p.weights);
}

}  // namespace

GpuMultiresSolver::GpuMultiresSolver(const GlApi& gl, const DiffusionMatrix& matrix, const MultiresHierarchy& hierarchy)
    : fine_(gl, matrix) {
    if (hierarchy.levels.empty() || hierarchy.levels[0].size() != matrix.size())
        throw InvalidArgumentError("GPU multires: the hierarchy was not built from this matrix");
    if (hierarchy.level_count() > 1) fine_interpolation_ = upload_interpolation(gl, hierarchy.levels[0].interpolation);
    for (size_t l = 1; l < hierarchy.level_count(); ++l) {
        const HierarchyLevel& level = hierarchy.levels[l];
        Level gpu{GpuMatrix(gl, level_view(level), GpuMatrixFormat::SellCSigma), fine_.kernels().vector(level.size()),
                  GpuBuffer::from<int32_t>(gl, level.original_vertex), nullptr, level.size()};
        GpuBuffer diag = fine_.kernels().vector(level.size());
        fine_.kernels().extract_diagonal(gpu.matrix, diag, gpu.inv_diag);
        if (l + 1 < hierarchy.level_count()) gpu.interpolation = upload_interpolation(gl, level.interpolation);
        levels_.push_back(std::move(gpu));
    }
    check_gpu_error(gl, "uploading the multires hierarchy");
}

void GpuMultiresSolver::update_rows(const DiffusionMatrix& matrix, const MultiresHierarchy& hierarchy,
                                    const std::vector<std::vector<int32_t>>& level_rows) {
    if (hierarchy.level_count() != levels_.size() + 1 || level_rows.size() > hierarchy.level_count())
        throw InvalidArgumentError("GPU multires update_rows: the hierarchy does not match the uploaded one");
    if (!level_rows.empty()) fine_.update_rows(matrix, level_rows[0]);
    GpuKernels& K = fine_.kernels();
    for (size_t l = 1; l < level_rows.size(); ++l) {
        if (level_rows[l].empty()) continue;
        const HierarchyLevel& level = hierarchy.levels[l];
        Level& gpu = levels_[l - 1];
        if (level.size() != gpu.rows)
            throw InvalidArgumentError("GPU multires update_rows: level " + std::to_string(l) + " changed size");
        K.upload_rows(gpu.matrix, level_view(level), level_rows[l]);
        GpuBuffer diag = K.vector(level.size());
        K.extract_diagonal(gpu.matrix, diag, gpu.inv_diag);
    }
}

GpuMultiresReport GpuMultiresSolver::solve(const MultiresSolveOptions& options, GpuCgOptions fine_options) {
    GpuMultiresReport report;
    GpuKernels& K = fine_.kernels();
    if (levels_.empty()) {
        fine_.set_solution(std::vector<std::array<double, 3>>(size(), {0.0, 0.0, 0.0}));
    } else {
        GpuBuffer coarse_x;
        for (size_t l = levels_.size(); l-- > 0;) {
            const Level& level = levels_[l];
            GpuBuffer b = K.vector(level.rows);
            K.gather(level.rows, level.original_vertex, fine_.right_hand_side_buffer(), b);
            GpuBuffer x = K.vector(level.rows);
            const bool coarsest = l + 1 == levels_.size();
            if (!coarsest) K.interpolate(*level.interpolation, coarse_x, x);
            BicgstabOptions bicg;
            // Float cannot reach the CPU's 1e-6 on the coarsest level reliably; 1e-5 is its floor here.
            bicg.relative_tolerance = coarsest ? std::max(options.coarsest_tolerance, 1e-5) : options.level_tolerance;
            bicg.max_iterations = coarsest ? options.coarsest_max_iterations : options.level_max_iterations;
            report.coarse_levels.push_back(solve_gpu_bicgstab(K, level.matrix, level.inv_diag, b, x, bicg));
            coarse_x = std::move(x);
        }
        K.interpolate(*fine_interpolation_, coarse_x, fine_.solution_buffer());
    }
    fine_options.relative_tolerance = options.relative_tolerance;
    fine_options.max_iterations = options.max_iterations;
    fine_options.use_eigenvalue_hints = false;
    report.fine = fine_.solve(fine_options);
    return report;
}

}  // namespace waxwork
