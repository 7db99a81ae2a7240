// The per-frame diffusion solver behind LiveScene: one interface for the methods and
// backends a live editor can use, each warm-started from the previous frame's phi and told what an
// edit changed, so it redoes only that.
//
//   CPU Jacobi CG        conjugate_gradient.h in double, per channel (the default: on spot it is as
//                        fast to 1% as the multires solver, live_scene.h).
//   CPU multigrid CG     multires/multigrid_frame_solver.h: CG preconditioned by the V-cycle on the
//                        hierarchy of Li et al. 2013 (Sec. 4.1, Eq. 16), the three rgb channels in one
//                        pass (one sweep over the pattern per level serves all three). Its state (phi,
//                        residual, search directions) persists across frames: a light change only
//                        moves the residual by the change of b (set_right_hand_side), painting updates
//                        the changed level-0 rows and the coarse Galerkin rows depending on them
//                        (update_values; a whole-object material every row), a new matrix (cut,
//                        relaxation) rebuilds it. solver.phi(c) is copied into the host phi after
//                        each frame (phi(), the radiance, saves, a cut's warm start). Its budget is
//                        counted in V-cycles: an iteration budget of k maps to max(1, k / 4) V-cycles
//                        (kIterationsPerVcycle: one costs about 4 Jacobi CG iterations of the three
//                        channels; 0 runs none), and FrameReport counts V-cycles as each
//                        channel's iterations. Its error estimate lags one CG update when the budget runs
//                        out (an upper estimate, multigrid_frame_solver.h).
//   multires             multires/multires_solver.h (CPU) or multires/gpu_multires_solver.h (GPU): the
//                        paper's own per-frame scheme (Sec. 4). The first frame after a (re)build (or a
//                        replaced phi) solves coarse to fine (BiCGSTAB on the coarse levels of the Eq. 17
//                        hierarchy, Eq. 16 interpolation, CG on level 0 within the frame's budget): from
//                        zero in a new scene, and as a correction of the host phi when there is one (a
//                        cut's carried phi, a relaxation's; MultiresSolver::set_warm_start, computed on
//                        the host for the GPU backend too, so both start from the same vector); later
//                        frames run only the level-0 Jacobi CG, warm from the previous frame's phi (a light
//                        change: new right-hand sides, same warm start). Painting updates the changed
//                        level-0 rows and the coarse rows depending on them (MultiresSolver::update_values
//                        with rows), and the GPU re-uploads only those rows of every level (update_rows).
//                        The hierarchy lives on the host for both backends (the device copy is built from
//                        it, and a fallback to the CPU keeps solving with it).
//   GPU CG               solver/gpu/gpu_conjugate_gradient.h (float, OpenGL 4.3 compute shaders): matrix,
//                        right-hand sides and phi stay on the device between frames; painting uploads
//                        only the rewritten rows (GpuDiffusionSolver::update_rows). phi is read back
//                        after each frame so the host copy (phi(), saves, the CPU radiance) stays valid.
//   GPU multigrid CG     multires/gpu_multigrid_frame_solver.h: the CPU multigrid CG's algorithm with phi,
//                        r, p, q and the V-cycle's levels on the device (float); the hierarchy and the
//                        Galerkin operators are built on the host at the first GPU frame after a
//                        (re)build (from the rest positions kept by matrix_rebuilt), painting uploads the
//                        recomputed rows of every level. Budgets as for the CPU multigrid (V-cycles;
//                        a time limit is checked between V-cycles, each CG step reads back its sums
//                        anyway, so no prediction is needed). After a GPU failure the CPU multigrid CG
//                        takes over; when the V-cycle cannot be built (AlgorithmError) GPU Jacobi CG does.
//
// The GPU backend runs on a SolverGlContext: the editor's hidden window sharing the main window's
// objects, or an OSMesa context (tests, `waxwork run`). The context is made current around every GPU
// call, because the editor runs each frame on a new worker thread. When the context or a shader fails
// (no OpenGL 4.3, a driver bug, WAXWORK_GPU_FORCE_FAIL), the solver switches to the CPU method for
// good and says why (gpu_fallback_reason()): a driver problem never stops the editor.
//
// Likewise when the multigrid V-cycle cannot be built or applied (AlgorithmError: a coarse Galerkin
// operator that is not positive definite, as on volumes of extreme slivers; the stability study's
// "slivers, multigrid" table), the frame and the following ones run Jacobi CG from the last phi and
// method_fallback_reason() says why; the next matrix rebuild (a cut) tries the multigrid again.
#pragma once

#include "gl/gl_context.h"
#include "gl/gpu_compute.h"
#include "gl/shared_context.h"
#include "multires/multigrid_preconditioner.h"
#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "solver/frame_budget.h"
#include "solver/iteration_time_predictor.h"
#include "solver/shading_surface.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace waxwork {

class MultigridFrameCg;
class MultigridFrameSolver;
class MultiresSolver;
struct MultiresHierarchy;

enum class LiveMethod { JacobiCg, MultigridCg, Multires };
enum class LiveBackend { Cpu, Gpu };

// "jacobi" / "mgcg" / "multires" and "cpu" / "gpu" (command line and session files); parse_* throw
// InvalidArgumentError naming the accepted values.
const char* live_method_name(LiveMethod method);
const char* live_backend_name(LiveBackend backend);
LiveMethod parse_live_method(const std::string& name);
LiveBackend parse_live_backend(const std::string& name);

struct LiveSolverOptions {
    LiveMethod method = LiveMethod::JacobiCg;
    LiveBackend backend = LiveBackend::Cpu;
    // The GPU backend's context; null: an OSMesa context is opened at the first GPU frame.
    std::shared_ptr<SolverGlContext> gl_context;
    // The clock of time budgets (frame_budget.h); empty: steady_clock. Tests inject a fake one.
    MillisecondClock clock;
    // The multigrid method's V-cycle (smoother, dropping, lumping and its fallback).
    MultigridOptions multigrid;
};

struct LiveSolverChannel {
    int iterations = 0;
    double estimated_relative_error = 1;
    bool converged = false;
};

// Not thread-safe: LiveScene calls it under its mutex.
class LiveSolver {
public:
    explicit LiveSolver(const LiveSolverOptions& options = {});
    ~LiveSolver();  // frees the device buffers with the context current
    LiveSolver(const LiveSolver&) = delete;
    LiveSolver& operator=(const LiveSolver&) = delete;

    // What changed since the last iterate(); each only marks work for the next one.
    // A new matrix (pattern or geometry): every derived structure is rebuilt (multigrid CG: the
    // hierarchy now, its Eq. 16 weights from the mesh's rest positions; the device: at the next frame).
    // new_of_old_vertex: per vertex of the previous matrix its vertex in this one or -1 (the map of a
    // cut, fracture or weld; the identity after a relaxation), or empty when they are unrelated. With
    // it the multires and multigrid hierarchies are rebuilt from the previous ones, selecting again
    // only around the changed rows (rebuild_multires_hierarchy), and the multigrid copies the
    // Galerkin rows the edit left unchanged (on the GPU backend both now, on the host, for the device
    // solver built at the next frame); without it, everything is built from scratch.
    void matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                        std::span<const int32_t> new_of_old_vertex = {});
    void values_changed();                          // all values, same pattern
    void rows_changed(std::span<const int32_t> rows);  // update_diffusion_matrix's rows
    void right_hand_sides_changed();
    void solution_changed();                        // phi replaced on the host (a cut's vertex map)

    // At most `iteration_budget` iterations per channel from `phi` (the warm start and the result).
    // Channels flagged in `skip` are not iterated. Throws AlgorithmError on a CG breakdown.
    std::array<LiveSolverChannel, 3> iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                                             std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                             double relative_tolerance, const std::array<bool, 3>& skip);
    // The same within a frame budget (frame_budget.h; validated). budget.max_iterations means what
    // iteration_budget does (0: no limit). The time limit starts now, on LiveSolverOptions::clock:
    //   CPU Jacobi CG and multires  the level-0 CG of each channel stops at its share of the time left
    //                               (remaining / channels left, so a channel that finishes early leaves
    //                               its time to the next); at least one iteration per channel. The
    //                               multires frame after a rebuild runs its coarse-to-fine pass (or
    //                               its correction of the carried phi) whole.
    //   CPU multigrid CG            the deadline is checked between V-cycles (at least one runs).
    //   GPU multigrid CG            as the CPU multigrid CG: the deadline is checked between V-cycles.
    //   GPU (other methods)         the device queue cannot stop part-way: the budget becomes an
    //                               iteration count predicted from earlier GPU frames of either overload
    //                               (gpu_iteration_time(); frames that uploaded the matrix or ran the
    //                               coarse pass are not measured).
    // An iteration-only budget gives the int overload's result bit for bit.
    std::array<LiveSolverChannel, 3> iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                                             std::array<std::vector<double>, 3>& phi, const FrameBudget& budget,
                                             double relative_tolerance, const std::array<bool, 3>& skip);
    // The GPU backend's measured cost per iteration (what turns a time budget into iterations there).
    const IterationTimePredictor& gpu_iteration_time() const { return gpu_iteration_time_; }

    // The exitant radiance factor E (Eq. 3 without F_t, gpu_radiance.h) of every shading vertex
    // (solver/shading_surface.h: the boundary `surface` split at its creases), computed on the device
    // from the resident phi of each copy's volume vertex and the copy's own q (`shading_q`), 3 floats
    // per shading vertex: what a renderer in the context's share group binds as its radiance attribute
    // instead of uploading a CPU copy. A new buffer per call (the renderer may still draw the previous
    // one), complete when returned (glFinish: another context reads it next). Null unless the GPU
    // backend is running; a GPU failure here falls back like iterate(). The rows and weights are
    // rebuilt when the shading or an eta changed since the last call, q re-sent when it changed.
    // `host_copy`, when given, receives the same E read back (a few hundred KB at most), for what the
    // CPU needs of it (the automatic exposure) without computing E from phi on the CPU.
    std::shared_ptr<const GpuBuffer> radiance_on_device(const BoundarySurface& surface, const ShadingSurface& shading,
                                                        const std::vector<std::array<double, 3>>& shading_q,
                                                        std::vector<std::array<float, 3>>* host_copy = nullptr);

    LiveMethod method() const { return method_; }
    // The backend that solves now (Cpu after a fallback).
    LiveBackend backend() const { return backend_; }
    LiveBackend requested_backend() const { return requested_backend_; }
    // Why the GPU backend was given up ("" when it was not requested or runs).
    const std::string& gpu_fallback_reason() const { return gpu_fallback_reason_; }
    // Gives the GPU backend up for good, as after a driver failure, with `reason`: the CPU method goes on
    // from the host phi (the last read-back). For a tolerance below float's floor on this volume
    // (LiveScene::converge). Nothing happens on the CPU backend.
    void fall_back_to_cpu(const std::string& reason) {
        if (backend_ == LiveBackend::Gpu) fall_back(reason);
    }
    // Why the method does not run as chosen ("" when it does): the multigrid method solving with Jacobi
    // CG instead, or the multires method's last coarse-to-fine pass skipping levels (and why).
    const std::string& method_fallback_reason() const { return method_fallback_reason_; }
    // The hierarchy of the multires method or of the multigrid CG (on the GPU backend: the one waiting
    // for the next GPU frame, else the device solver's; nullptr with other methods, before the first
    // GPU frame, or on an empty mesh).
    const MultiresHierarchy* multires_hierarchy() const;
    // The multigrid CG's preconditioner: the CPU solver's, the one waiting for the next GPU frame, or
    // the device solver's host copy (nullptr with other methods or before the first GPU frame).
    const MultigridPreconditioner* multigrid_preconditioner() const;
    // "GPU Jacobi CG (float) (llvmpipe ...)", "CPU multigrid CG, three channels per V-cycle", ...: for the
    // panel and logs.
    std::string description() const;

private:
    struct Gpu;
    std::array<LiveSolverChannel, 3> iterate_cpu(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                                                 std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                                 double relative_tolerance, const std::array<bool, 3>& skip);
    std::array<LiveSolverChannel, 3> iterate_multigrid(const DiffusionMatrix& matrix,
                                                       const std::array<std::vector<double>, 3>& b,
                                                       std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                                       double relative_tolerance, const std::array<bool, 3>& skip);
    // The multigrid and multires estimates a frame of no iterations reports go back to 1 (unknown).
    void forget_estimates();
    // Multires (both backends): applies pending value changes to the host hierarchy and queues the
    // changed rows of every level for the device.
    void update_multires_values(const DiffusionMatrix& matrix);
    std::array<LiveSolverChannel, 3> iterate_multires(const std::array<std::vector<double>, 3>& b,
                                                      std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                                      double relative_tolerance, const std::array<bool, 3>& skip);
    std::array<LiveSolverChannel, 3> iterate_gpu_multires(const DiffusionMatrix& matrix,
                                                          const std::array<std::vector<double>, 3>& b,
                                                          std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                                          double relative_tolerance);
    std::array<LiveSolverChannel, 3> iterate_gpu_multigrid(const DiffusionMatrix& matrix,
                                                           const std::array<std::vector<double>, 3>& b,
                                                           std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                                           double relative_tolerance, const std::array<bool, 3>& skip);
    // The multigrid runs on the device (or will at the next GPU frame).
    bool gpu_multigrid() const { return backend_ == LiveBackend::Gpu && !multigrid_positions_.empty(); }
    // The CPU multigrid frame solver for `matrix` (sets method_fallback_reason_ when it cannot be built).
    // `hierarchy`: one already built for `matrix` (rebuilt around an edit); else it is built here.
    // `previous`: the solver before that edit (new_of_old_vertex its vertex map), whose unchanged
    // Galerkin rows the new preconditioner copies.
    void build_cpu_multigrid(std::span<const Eigen::Vector3d> positions, const DiffusionMatrix& matrix,
                             std::optional<MultiresHierarchy> hierarchy = std::nullopt,
                             const MultigridFrameSolver* previous = nullptr, std::span<const int32_t> new_of_old_vertex = {});
    std::array<LiveSolverChannel, 3> iterate_gpu(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                                                 std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                                 double relative_tolerance, const std::array<bool, 3>& skip);
    void fall_back(const std::string& reason);
    void release_gpu();
    struct PendingChanges;
    // A frame of either multigrid frame solver (CPU or device): sends the pending changes (values, b,
    // phi), runs the V-cycles the budget allows, `read_phi` copies the solver's phi to the host.
    std::array<LiveSolverChannel, 3> multigrid_frame(MultigridFrameCg& solver, PendingChanges& pending,
                                                     const DiffusionMatrix& matrix,
                                                     const std::array<std::vector<double>, 3>& b,
                                                     std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                                     double relative_tolerance, const std::array<bool, 3>& skip,
                                                     const std::function<void()>& read_phi);
    // After a multires coarse-to-fine pass: method_fallback_reason() names its skipped levels ("" when
    // none was skipped).
    void note_coarse_fallbacks(const std::string& reasons);

    LiveMethod method_;
    LiveBackend backend_, requested_backend_;
    std::shared_ptr<SolverGlContext> context_;
    std::string gpu_fallback_reason_;
    std::string method_fallback_reason_;
    MultigridOptions multigrid_options_;
    std::string renderer_;
    std::array<double, 3> eigenvalue_hint_{};
    // What changed since one copy of the system last caught up; each copy (the multigrid frame
    // solver, the multires hierarchy, the device) applies its own record at its next frame, so a
    // change reaches every copy exactly once whichever of them runs when.
    struct PendingChanges {
        bool all_values = false;    // every matrix value changed (same pattern); rows is then empty
        std::vector<int32_t> rows;  // else the rows that changed, ascending and unique
        bool right_hand_sides = true;
        bool solution = true;  // the host phi was replaced (or never sent): start from it

        void values_changed() {
            all_values = true;
            rows.clear();
        }
        void rows_changed(std::span<const int32_t> ascending_unique);  // nothing to add after all_values
        void values_applied() {
            all_values = false;
            rows.clear();
        }
    };

    std::unique_ptr<MultigridFrameSolver> multigrid_;
    PendingChanges multigrid_pending_;  // values, b, and phi as a warm start
    // The multigrid method on the GPU backend: the mesh's rest positions (the hierarchy's Eq. 16
    // weights), kept from matrix_rebuilt for the device solver built at the next GPU frame and for a
    // CPU multigrid after a fallback. Empty when the method is not (or no longer) run on the device;
    // the device solver takes its changes through gpu_pending_.
    std::vector<Eigen::Vector3d> multigrid_positions_;
    // With multigrid_positions_ after an edit with a vertex map: the hierarchy and preconditioner
    // rebuilt around the edit from the device solver's (or from the ones still waiting here), for the
    // device solver built at the next GPU frame. Empty otherwise, and after painting (stale values).
    MultigridOperators multigrid_waiting_;
    // The last frame's estimates, reported by a frame of no V-cycles (1 after a change).
    std::array<double, 3> multigrid_error_{1, 1, 1};
    std::unique_ptr<MultiresSolver> multires_;
    // Values, and `solution`: the next frame solves coarse to fine (after a rebuild or a replaced phi),
    // correcting the host phi unless it is zero; between those frames the CPU's warm starts are the
    // solver's own last solutions, the device's its resident phi.
    PendingChanges multires_pending_;
    std::array<double, 3> multires_error_{1, 1, 1};  // reported by a frame of no iterations
    // Rows per level the device copy of the hierarchy has not received yet (ascending, unique); all of
    // them when gpu_pending_.all_values.
    std::vector<std::vector<int32_t>> gpu_level_rows_;
    std::unique_ptr<Gpu> gpu_;
    // Device work, applied at the next GPU iterate with the context current. Rows are collected only
    // while the GPU backend runs (a device made later is sent everything).
    PendingChanges gpu_pending_;
    // Time budgets: the clock, the deadline of the frame being solved (unbounded outside a budgeted
    // iterate(): the CPU paths read it), and the GPU's cost per iteration.
    MillisecondClock clock_;
    FrameDeadline deadline_;
    IterationTimePredictor gpu_iteration_time_;
};

}  // namespace waxwork
