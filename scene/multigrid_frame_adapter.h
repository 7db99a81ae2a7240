// The CPU multigrid CG as a frame solver: multires/multigrid_frame_solver.h (the V-cycle in float,
// phi and the level-0 products in double) run by multigrid_frame.h. The hierarchy and the
// preconditioner are built at matrix_rebuilt, while the mesh is at hand; after an edit with a vertex
// map they are rebuilt from the previous ones (rebuild_multires_hierarchy; the preconditioner copies
// the Galerkin rows the edit left unchanged). Building throws AlgorithmError when the V-cycle cannot be
// built (LiveSolver then solves with Jacobi CG until the next rebuild).
#pragma once

#include "multires/multigrid_frame_solver.h"
#include "scene/multigrid_frame_adapter_base.h"

#include <memory>
#include <optional>

namespace waxwork {

class MultigridFrameAdapter : public MultigridFrameAdapterBase {
public:
    explicit MultigridFrameAdapter(const MultigridOptions& options) : MultigridFrameAdapterBase(options) {}
    // Going on from the GPU multigrid CG after a device failure: built at the next frame from the rest
    // positions the device solver was built from and, when the operators waiting for the device are
    // this matrix's, their hierarchy; `error`: the device's last estimates.
    MultigridFrameAdapter(const MultigridOptions& options, std::vector<Eigen::Vector3d> positions,
                          MultigridOperators waiting, const std::array<double, 3>& error);

    void matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                        std::span<const int32_t> new_of_old_vertex) override;

    // The deadline is checked between V-cycles (at least one runs).
    FrameResult iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                        std::array<std::vector<double>, 3>& phi, const FrameLimits& limits, double relative_tolerance,
                        const std::array<bool, 3>& skip) override;

    const MultiresHierarchy* multires_hierarchy() const override;
    const MultigridPreconditioner* multigrid_preconditioner() const override;
    std::string description() const override;

private:
    // The solver for `matrix`: on `hierarchy` when one was built for it (around an edit, copying from
    // `previous`'s preconditioner the Galerkin rows the edit left unchanged), else built here.
    void build(std::span<const Eigen::Vector3d> positions, const DiffusionMatrix& matrix,
               std::optional<MultiresHierarchy> hierarchy = std::nullopt,
               const MultigridFrameSolver* previous = nullptr, std::span<const int32_t> new_of_old_vertex = {});
    bool has_solver() const override { return solver_ != nullptr; }

    // positions_ and waiting_ are set only after a GPU fallback, until the next frame builds the
    // solver: the mesh's rest positions and the operators that were waiting for the device (their
    // hierarchy is this matrix's unless painting cleared them since).
    std::unique_ptr<MultigridFrameSolver> solver_;  // null on an empty matrix, or until built
};

}  // namespace waxwork
