#include "scene/multigrid_frame_adapter.h"

#include "scene/multigrid_frame.h"
#include "scene/rebuilt_hierarchy.h"

#include <algorithm>
#include <utility>

namespace waxwork {

MultigridFrameAdapter::MultigridFrameAdapter(const MultigridOptions& options, std::vector<Eigen::Vector3d> positions,
                                             MultigridOperators waiting, const std::array<double, 3>& error)
    : MultigridFrameAdapterBase(options, std::move(positions), std::move(waiting), error) {}

void MultigridFrameAdapter::matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                                           std::span<const int32_t> new_of_old_vertex) {
    std::unique_ptr<MultigridFrameSolver> previous = std::move(solver_);
    forget_estimates();
    pending_ = PendingChanges{};  // nothing of the old matrix is pending; b and phi are
    positions_.clear();
    waiting_ = MultigridOperators{};
    if (matrix.size() == 0) return;
    // The hierarchy rebuilt around the edit from the previous solver's, and the Galerkin rows the edit
    // left unchanged copied from its preconditioner; the previous solver is freed once they are (at
    // 500K tets the two together hold several hundred MB for a moment).
    std::optional<MultiresHierarchy> carried =
        rebuilt_hierarchy(previous ? &previous->hierarchy() : nullptr, new_of_old_vertex, matrix, mesh.positions);
    const MultigridFrameSolver* source = carried ? previous.get() : nullptr;
    build(mesh.positions, matrix, std::move(carried), source, new_of_old_vertex);
    previous.reset();
}

void MultigridFrameAdapter::build(std::span<const Eigen::Vector3d> positions, const DiffusionMatrix& matrix,
                                  std::optional<MultiresHierarchy> hierarchy, const MultigridFrameSolver* previous,
                                  std::span<const int32_t> new_of_old_vertex) {
    FrameSolverOptions frame_options;
    frame_options.multigrid = options_;
    solver_ = hierarchy ? std::make_unique<MultigridFrameSolver>(matrix, std::move(*hierarchy), frame_options, previous,
                                                                 new_of_old_vertex)
                        : std::make_unique<MultigridFrameSolver>(matrix, positions, frame_options);
    pending_ = PendingChanges{};  // a new solver: b and phi to send
}

FrameResult MultigridFrameAdapter::iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                                           std::array<std::vector<double>, 3>& phi, const FrameLimits& limits,
                                           double relative_tolerance, const std::array<bool, 3>& skip) {
    FrameResult result;
    if (matrix.size() == 0) {
        for (auto& channel : result.channels) channel = {0, 0.0, true};
        return result;
    }
    if (!solver_) {
        // After a GPU fallback: built here (the device held the hierarchy), warm from the last
        // read-back phi. The hierarchy waiting for the device is this matrix's; its preconditioner
        // goes (the solver builds its own).
        std::optional<MultiresHierarchy> waiting;
        if (waiting_.hierarchy) {
            waiting_.preconditioner.reset();
            waiting = std::move(*waiting_.hierarchy);
        }
        waiting_ = MultigridOperators{};
        const std::vector<Eigen::Vector3d> positions = std::move(positions_);
        positions_.clear();
        build(positions, matrix, std::move(waiting));
    }
    MultigridFrameSolver& solver = *solver_;
    result.channels = multigrid_frame(solver, pending_, error_, matrix, b, phi, limits, relative_tolerance, skip, [&] {
        for (int c = 0; c < 3; ++c) {
            const std::span<const double> solved = solver.phi(c);
            std::copy(solved.begin(), solved.end(), phi[c].begin());
        }
    });
    return result;
}

const MultiresHierarchy* MultigridFrameAdapter::multires_hierarchy() const {
    return solver_ ? &solver_->hierarchy() : waiting_.hierarchy.get();
}

const MultigridPreconditioner* MultigridFrameAdapter::multigrid_preconditioner() const {
    return solver_ ? &solver_->preconditioner() : waiting_.preconditioner.get();
}

std::string MultigridFrameAdapter::description() const {
    // Without a solver (an empty matrix, or after a GPU fallback until the next frame builds it) no
    // multigrid runs; if it cannot be built, Jacobi CG will.
    if (!solver_) return "CPU Jacobi CG (double)";
    return with_lumping_note("CPU multigrid CG, three channels per V-cycle", &solver_->preconditioner());
}

}  // namespace waxwork
