// The per-frame diffusion solver behind LiveScene: one interface for the methods and backends a live
// editor can use, each warm-started from the previous frame's phi and told what an edit changed, so it
// redoes only that. Each method and backend is a FrameSolver of its own (frame_solver.h):
//
//   CPU Jacobi CG        jacobi_frame_solver.h: conjugate_gradient.h in double, per channel (the
//                        default: on spot it is as fast to 1% as the multires solver, live_scene.h).
//   CPU multigrid CG     multigrid_frame_adapter.h: CG preconditioned by the V-cycle on the hierarchy of
//                        Li et al. 2013 (Sec. 4.1, Eq. 16), the three rgb channels in one pass, its
//                        state persisting across frames (multigrid_frame.h). Its budget is counted in
//                        V-cycles: an iteration budget of k maps to max(1, k / 4) V-cycles (one costs
//                        about 4 Jacobi CG iterations of the three channels; 0 runs none), and
//                        FrameReport counts V-cycles as each channel's iterations.
//   multires             multires_frame_adapter.h (CPU) or gpu_multires_frame_adapter.h (GPU): the
//                        paper's own per-frame scheme (Sec. 4): coarse to fine after a (re)build or a
//                        replaced phi, then the level-0 Jacobi CG warm from the previous frame's phi. The
//                        hierarchy lives on the host for both backends.
//   GPU CG               gpu_jacobi_frame_solver.h: solver/gpu/gpu_conjugate_gradient.h (float, OpenGL
//                        4.3 compute shaders), matrix, right-hand sides and phi resident on the device.
//   GPU multigrid CG     gpu_multigrid_frame_adapter.h: the CPU multigrid CG's algorithm on the device
//                        (float), its budgets as for the CPU multigrid.
// Every implementation copies its phi into the host phi after each frame (phi(), the CPU radiance,
// saves, a cut's warm start).
//
// This class chooses the implementation (make_frame_solver) and performs the fallbacks between them.
// The GPU backend runs on a SolverGlContext (gpu_frame_context.h): the editor's hidden window sharing
// the main window's objects, or an OSMesa context (tests, `waxwork run`). When the context or a shader
// fails (no OpenGL 4.3, a driver bug, WAXWORK_GPU_FORCE_FAIL), the solver switches to the CPU
// implementation of the same method for good, continuing from the host phi, and says why
// (gpu_fallback_reason()): a driver problem never stops the editor.
//
// Likewise when the multigrid V-cycle cannot be built or applied (AlgorithmError: a coarse Galerkin
// operator that is not positive definite, as on volumes of extreme slivers; the stability study's
// "slivers, multigrid" table), the frame and the following ones run Jacobi CG (on the same backend)
// from the last phi and method_fallback_reason() says why; the next matrix rebuild (a cut) tries the
// multigrid again.
#pragma once

#include "gl/gl_context.h"
#include "gl/gpu_compute.h"
#include "gl/shared_context.h"
#include "multires/multigrid_preconditioner.h"
#include "scene/frame_solver.h"
#include "scene/gpu_frame_context.h"
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
    // The implementation for `method` on the current backend (the one place that chooses).
    std::unique_ptr<FrameSolver> make_frame_solver(LiveMethod method);
    // A frame of the current implementation; a multigrid one whose V-cycle cannot be built or applied
    // is replaced by Jacobi CG, which solves the frame instead.
    FrameResult run_frame(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                          std::array<std::vector<double>, 3>& phi, int iteration_budget, double relative_tolerance,
                            const std::array<bool, 3>& skip);
    // Jacobi CG on the current backend instead of the multigrid, until the next matrix rebuild.
    void use_jacobi_instead(const std::exception& e);
    void fall_back(const std::string& reason);

    LiveMethod method_;
    LiveBackend backend_, requested_backend_;
    MultigridOptions multigrid_options_;
    // Time budgets: the clock, the deadline of the frame being solved (unbounded outside a budgeted
    // iterate()), and the GPU's cost per iteration.
    MillisecondClock clock_;
    FrameDeadline deadline_;
    IterationTimePredictor gpu_iteration_time_;
    std::string gpu_fallback_reason_;
    std::string method_fallback_reason_;
    GpuFrameContext gpu_context_;  // outlives solver_, whose device objects live in it
    std::unique_ptr<FrameSolver> solver_;
    // Whether solver_ is the method's own implementation. Jacobi CG stands in for the multires and
    // multigrid methods until the first matrix_rebuilt (their hierarchy needs the mesh), and for the
    // multigrid after its V-cycle failed, until the next one.
    bool runs_method_;
};

}  // namespace waxwork
