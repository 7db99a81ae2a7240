// The multires method (Li et al. 2013, Sec. 4: the paper's own per-frame scheme) as a frame solver on
// the CPU: multires/multires_solver.h. The first frame after a (re)build (or a replaced phi) solves
// coarse to fine (BiCGSTAB on the coarse levels of the Eq. 17 hierarchy, Eq. 16 interpolation, CG on
// level 0 within the frame's budget): from zero in a new scene, and as a correction of the host phi
// when there is one (a cut's carried phi, a relaxation's; MultiresSolver::set_warm_start). Later frames
// run only the level-0 Jacobi CG, warm from the previous frame's phi (a light change: new right-hand
// sides, same warm start). Painting updates the changed level-0 rows and the coarse rows depending on
// them (MultiresSolver::update_values with rows).
//
// The hierarchy lives on the host for both backends (MultiresHostState): the GPU backend's device copy
// is made from it (gpu_multires_frame_adapter.h), and a fallback to the CPU keeps solving with it.
#pragma once

#include "multires/multires_solver.h"
#include "scene/frame_solver.h"
#include "scene/pending_changes.h"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace waxwork {

// The multires method's state on the host.
struct MultiresHostState {
    std::unique_ptr<MultiresSolver> solver;  // null until a non-empty matrix
    // Values, and `solution`: the next frame solves coarse to fine (after a rebuild or a replaced phi),
    // correcting the host phi unless it is zero; between those frames the CPU's warm starts are the
    // solver's own last solutions, the device's its resident phi.
    PendingChanges pending;
    std::array<double, 3> error{1, 1, 1};  // reported by a frame of no iterations (1 after a change)

    // A new hierarchy for `matrix`: rebuilt around the edit from the previous one when the vertex map
    // fits it (rebuild_multires_hierarchy), else built from scratch; none on an empty matrix.
    void matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix, std::span<const int32_t> new_of_old_vertex);
    void values_changed();
    void rows_changed(std::span<const int32_t> rows);
    void solution_changed();
    // Applies the pending value changes to the hierarchy. Returns the rows that changed on each level
    // after painting (what a device copy re-uploads); nothing after all values changed, or none.
    std::vector<std::vector<int32_t>> apply_values(const DiffusionMatrix& matrix);
    // The solver, which a non-empty matrix needs (throws InvalidArgumentError when matrix_rebuilt did
    // not build one for it).
    MultiresSolver& solver_for(const DiffusionMatrix& matrix);
};

// Adds channel c's skipped coarse levels, if any, to the notes of a coarse-to-fine pass ("red: level
// 3: ...; blue: ...").
void append_coarse_fallbacks(std::string& notes, int c, const MultiresSolveReport& report);
// What method_fallback_reason() says after a coarse-to-fine pass with those notes ("" when no level
// was skipped).
std::string coarse_pass_note(const std::string& notes);

class MultiresFrameAdapter : public FrameSolver {
public:
    MultiresFrameAdapter() = default;
    // Going on from the GPU multires after a device failure, with its host state (the next frame solves
    // coarse to fine from the host phi: the CPU hierarchy has no warm start of its own yet).
    explicit MultiresFrameAdapter(MultiresHostState host);

    void matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                        std::span<const int32_t> new_of_old_vertex) override {
        host_.matrix_rebuilt(mesh, matrix, new_of_old_vertex);
    }
    void values_changed() override { host_.values_changed(); }
    void rows_changed(std::span<const int32_t> rows) override { host_.rows_changed(rows); }
    void right_hand_sides_changed() override { host_.error = {1, 1, 1}; }
    void solution_changed() override { host_.solution_changed(); }

    void apply_host_changes(const DiffusionMatrix& matrix) override { host_.apply_values(matrix); }
    // The level-0 CG of each channel stops at its share of the time left (remaining / channels left);
    // at least one iteration per channel. The frame after a rebuild runs its coarse-to-fine pass (or
    // its correction of the carried phi) whole.
    FrameResult iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                        std::array<std::vector<double>, 3>& phi, const FrameLimits& limits, double relative_tolerance,
                        const std::array<bool, 3>& skip) override;

    const MultiresHierarchy* multires_hierarchy() const override {
        return host_.solver ? &host_.solver->hierarchy() : nullptr;
    }
    std::string description() const override {
        return "CPU multires, BiCGSTAB coarse to fine, warm CG per frame (double)";
    }

private:
    MultiresHostState host_;
};

}  // namespace waxwork
