// One frame solver of the live editor (live_solver.h): a method on a backend, warm-started from the
// previous frame's phi and told what an edit changed, so that it redoes only that. LiveSolver chooses
// the implementation and performs the fallbacks between them; each implementation only solves.
//
//   jacobi_frame_solver.h          CPU Jacobi CG (double)
//   multigrid_frame_adapter.h      CPU multigrid CG (multires/multigrid_frame_solver.h)
//   multires_frame_adapter.h       CPU multires (multires/multires_solver.h)
//   gpu_jacobi_frame_solver.h      GPU Jacobi CG (float, solver/gpu/gpu_conjugate_gradient.h)
//   gpu_multigrid_frame_adapter.h  GPU multigrid CG (multires/gpu_multigrid_frame_solver.h)
//   gpu_multires_frame_adapter.h   GPU multires (multires/gpu_multires_solver.h)
#pragma once

#include "gl/gpu_compute.h"
#include "solver/diffusion_matrix.h"
#include "solver/frame_budget.h"
#include "solver/lighting.h"
#include "solver/shading_surface.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace waxwork {

class MultigridPreconditioner;
struct MultiresHierarchy;

struct LiveSolverChannel {
    int iterations = 0;
    double estimated_relative_error = 1;
    bool converged = false;
};

// What one frame may spend.
struct FrameLimits {
    int iterations;                 // per channel (Jacobi CG iterations; 0: none)
    const FrameDeadline& deadline;  // of a time-budgeted frame; unbounded otherwise
    const MillisecondClock& clock;  // the clock the deadline reads
};

// A budget of `max_iterations` (> 0) and the `parts`-th share of what is left of `deadline` (bounded),
// for the solver objects that take a FrameBudget. A deadline already passed still gives a positive
// (vanishing) time limit: 0 would mean "no time limit", and the solver then runs its one iteration.
FrameBudget budget_until(const FrameDeadline& deadline, int parts, int max_iterations);

struct FrameResult {
    std::array<LiveSolverChannel, 3> channels;
    // Set when the frame found out whether the method runs as meant (the multires coarse-to-fine
    // pass: the levels it skipped and why, or "" when it skipped none); LiveSolver reports it as
    // method_fallback_reason().
    std::optional<std::string> method_note;
};

class FrameSolver {
public:
    virtual ~FrameSolver() = default;

    // What changed since the last iterate(), as LiveSolver's functions of the same names say (rows:
    // ascending and unique, not empty); each only marks work for the next frame. `mesh` is borrowed
    // for the call only.
    virtual void matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                                std::span<const int32_t> new_of_old_vertex) = 0;
    virtual void values_changed() = 0;
    virtual void rows_changed(std::span<const int32_t> rows) = 0;
    virtual void right_hand_sides_changed() = 0;
    virtual void solution_changed() = 0;

    // Brings what the host keeps of the system up to date before a frame: the multires hierarchy,
    // which either backend solves from. Separate from iterate() because its errors are the system's,
    // not the device's, and its time is not the device's cost per iteration.
    virtual void apply_host_changes(const DiffusionMatrix& /*matrix*/) {}
    // One frame from `phi` (the warm start and the result) within `limits`; channels flagged in
    // `skip` are not iterated. Throws AlgorithmError on a breakdown (a multigrid implementation also
    // when its V-cycle cannot be built or applied; phi is then still the last frame's), GpuError or
    // another Error when the device fails.
    virtual FrameResult iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                                std::array<std::vector<double>, 3>& phi, const FrameLimits& limits,
                                double relative_tolerance, const std::array<bool, 3>& skip) = 0;
    // Whether the solver stops at FrameLimits::deadline itself. A device queue cannot stop part-way:
    // an implementation that does not is given an iteration count predicted from the measured cost of
    // earlier frames instead (LiveSolver::gpu_iteration_time).
    virtual bool checks_deadline() const { return true; }
    // For those that do not: whether the next frame costs its iterations only (no upload of the whole
    // matrix, no coarse-to-fine pass), so that its time measures what an iteration costs.
    virtual bool next_frame_measures_iterations() const { return false; }

    // GPU implementations: E on the device from the resident phi (LiveSolver::radiance_on_device),
    // null before the first frame. Throws GpuError when the device fails.
    virtual std::shared_ptr<const GpuBuffer> radiance_on_device(
        const BoundarySurface& /*surface*/, const ShadingSurface& /*shading*/,
        const std::vector<std::array<double, 3>>& /*shading_q*/, std::vector<std::array<float, 3>>* /*host_copy*/) {
        return nullptr;
    }
    // GPU implementations: the CPU implementation of the same method that goes on from what this one
    // keeps on the host (the host phi is the last frame's read-back), after a device failure. Called
    // once, just before this object is destroyed. CPU implementations: null.
    virtual std::unique_ptr<FrameSolver> cpu_successor() { return nullptr; }

    // The hierarchy and the multigrid preconditioner, where the method has them (LiveSolver's
    // multires_hierarchy() and multigrid_preconditioner() say which).
    virtual const MultiresHierarchy* multires_hierarchy() const { return nullptr; }
    virtual const MultigridPreconditioner* multigrid_preconditioner() const { return nullptr; }
    // What runs, for the panel and logs (LiveSolver::description).
    virtual std::string description() const = 0;
};

}  // namespace waxwork
