#include "scene/gpu_multigrid_frame_adapter.h"

#include "base/error.h"
#include "scene/multigrid_frame.h"
#include "scene/multigrid_frame_adapter.h"
#include "scene/rebuilt_hierarchy.h"

#include <optional>
#include <string>
#include <utility>

namespace waxwork {

namespace {

// The device multigrid's host operators for `matrix` after an edit: the hierarchy rebuilt from
// `previous_hierarchy` and the preconditioner rebuilt from `previous_preconditioner` (built on it),
// copying the rows the edit left unchanged; nothing without a fitting vertex map (the device solver
// then builds both). A preconditioner that cannot be built is left to the device solver's
// construction, which fails the same way and is reported there.
MultigridOperators rebuilt_multigrid_operators(const MultiresHierarchy* previous_hierarchy,
                                               const MultigridPreconditioner* previous_preconditioner,
                                               std::span<const int32_t> new_of_old_vertex, const DiffusionMatrix& matrix,
                                               std::span<const Eigen::Vector3d> positions,
                                               const MultigridOptions& options) {
    MultigridOperators operators;
    std::optional<MultiresHierarchy> hierarchy =
        rebuilt_hierarchy(previous_hierarchy, new_of_old_vertex, matrix, positions);
    if (!hierarchy) return operators;
    operators.hierarchy = std::make_unique<MultiresHierarchy>(std::move(*hierarchy));
    if (previous_preconditioner) {
        try {
            operators.preconditioner = std::make_unique<MultigridPreconditioner>(
                *operators.hierarchy, *previous_preconditioner, new_of_old_vertex, options);
        } catch (const AlgorithmError&) {
            operators.preconditioner.reset();
        }
    }
    return operators;
}

}  // namespace

void GpuMultigridFrameAdapter::matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                                              std::span<const int32_t> new_of_old_vertex) {
    // The operators of the previous matrix live on the host: the ones waiting for the next frame, or
    // the device solver's (freed below).
    const MultigridOperators previous_waiting = std::exchange(waiting_, MultigridOperators{});
    const MultiresHierarchy* previous_hierarchy = nullptr;
    const MultigridPreconditioner* previous_preconditioner = nullptr;
    if (previous_waiting.hierarchy) {
        previous_hierarchy = previous_waiting.hierarchy.get();
        previous_preconditioner = previous_waiting.preconditioner.get();
    } else if (device_) {
        previous_hierarchy = &device_->solver->hierarchy();
        previous_preconditioner = &device_->solver->preconditioner();
    }
    forget_estimates();
    pending_ = PendingChanges{};  // nothing of the old matrix is pending; b and phi are
    positions_.clear();
    if (matrix.size() > 0) {
        // The device solver is built at the next frame, with the context current, from a copy of the
        // rest positions (the scene borrows the mesh only during its calls).
        positions_ = mesh.positions;
        waiting_ = rebuilt_multigrid_operators(previous_hierarchy, previous_preconditioner, new_of_old_vertex, matrix,
                                               mesh.positions, options_);
    }
    context_.free_device_for_new_matrix(device_);
}

FrameResult GpuMultigridFrameAdapter::iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                                              std::array<std::vector<double>, 3>& phi, const FrameLimits& limits,
                                              double relative_tolerance, const std::array<bool, 3>& skip) {
    FrameResult result;
    if (matrix.size() == 0 || (skip[0] && skip[1] && skip[2])) {
        result.channels = idle_gpu_frame(matrix.size(), skip);
        return result;
    }
    SolverGlContext& context = context_.open();
    const CurrentContext current(context);
    const GlApi& gl = context.gl();
    const bool made = context_.make_device(device_, gl, [&] {
        FrameSolverOptions frame_options;
        frame_options.multigrid = options_;
        return waiting_.hierarchy ? std::make_unique<GpuMultigridFrameSolver>(
                                        gl, matrix, std::exchange(waiting_, MultigridOperators{}), frame_options)
                                  : std::make_unique<GpuMultigridFrameSolver>(gl, matrix, positions_, frame_options);
    });
    if (made) pending_ = PendingChanges{};  // a new device copy: the current values; b and phi to send
    GpuMultigridFrameSolver& solver = *device_->solver;
    result.channels = multigrid_frame(solver, pending_, error_, matrix, b, phi, limits, relative_tolerance, skip,
                                      [&] { phi = solver.phi(); });
    return result;
}

std::unique_ptr<FrameSolver> GpuMultigridFrameAdapter::cpu_successor() {
    return std::make_unique<MultigridFrameAdapter>(options_, std::move(positions_), std::move(waiting_), error_);
}

const MultiresHierarchy* GpuMultigridFrameAdapter::multires_hierarchy() const {
    if (waiting_.hierarchy) return waiting_.hierarchy.get();
    return device_ ? &device_->solver->hierarchy() : nullptr;
}

const MultigridPreconditioner* GpuMultigridFrameAdapter::multigrid_preconditioner() const {
    if (waiting_.hierarchy) return waiting_.preconditioner.get();
    return device_ ? &device_->solver->preconditioner() : nullptr;
}

std::string GpuMultigridFrameAdapter::description() const {
    // Without rest positions (an empty matrix) there is no multigrid to run.
    const std::string text = context_.with_renderer(
        positions_.empty() ? "GPU Jacobi CG (float)" : "GPU multigrid CG, three channels per V-cycle (float)");
    return with_lumping_note(text, device_ ? &device_->solver->preconditioner() : nullptr);
}

}  // namespace waxwork
