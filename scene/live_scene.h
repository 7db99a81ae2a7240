// The solver state the editor and scripted sessions keep between frames for one document:
// connectivity, boundary surface with its shadow BVH and incident light q, the TransCut matrix
// (Eqs. 10-14) with its right-hand sides (Eq. 12), and the current fluence phi per channel. Each frame
// advances the solve a bounded number of iterations from the previous frame's phi (warm start), so
// light follows edits progressively instead of stalling the frame.
//
// Reacting to a change (Document's ChangeReport), the scene redoes only what the change invalidates:
//   materials of some tets   rewrite only the matrix rows of their vertices (paper Sec. 5, "we only
//                            update the rows ... affected"; diffusion_matrix.h update_diffusion_matrix);
//                            q only at boundary vertices whose eta changed; phi kept as warm start
//   all materials            recompute matrix values on the kept pattern and geometry; warm start
//   piece transforms         boundary surface, shadow BVH and q (pieces shadow each other); the matrix
//                            is invariant under rigid motion; warm start
//   positions (relaxation,   the rows of the moved vertices' tets (geometry and values, same pattern;
//   deformation)             the solver's hierarchy keeps its graph), surface and lighting; warm start
//   topology (cut, fracture, connectivity (reused from the report when the edit built it), matrix,
//   weld, their undo)        lighting; warm start through the edit's vertex map and vertex origins
//                            (ChangeReport), else cold
//   lights (set_lighting)    q and the right-hand sides only; warm start
//
// Solver choice: Jacobi-preconditioned CG in double, warm-started, per channel. The multires solver
// (multires/multires_solver.h) is not the default: between rebuilds its frames are this same warm
// Jacobi CG, and its hierarchy adds to every cut (rebuilt around the cut from the previous one).
// Multigrid CG converges in fewer, cheaper frames but adds its setup (hierarchy and Galerkin
// operators, both rebuilt around the cut from the previous ones) to every cut. From a cut to an image under 1%
// error the three come out even, because the phi carried through the cut is already a close start
// (bench/live_solver_bench.cpp BM_CutToSettledImage; docs/performance.md).
// LiveSceneOptions::method and backend select multigrid CG, the paper's multires or the GPU instead
// (live_solver.h).
//
// Threading: every public member locks one internal mutex, so the window may call step() on a worker
// thread while the UI thread applies edits; apply_change() and set_lighting() then wait for the
// running step() to finish (one frame). The TetMesh passed to the constructor and apply_change() is
// borrowed: it must outlive the scene and must not be modified while any member runs (the document
// changes it only inside Document::apply/undo/redo: call those and apply_change() under the same
// external lock or on the same thread). Only the constructor and apply_change() read the mesh: the
// other members work from the scene's own surface, shading and phi.
// A window's loop, for example:
//   UI thread:     { lock edit_mutex; report = document.apply(op); scene.apply_change(document.mesh(), report); }
//   solver thread: scene.step(FrameBudget::milliseconds(12)); E = scene.radiance_factors();
//                  upload E
#pragma once

#include "render/render_input.h"
#include "scene/document.h"
#include "scene/live_solver.h"
#include "solver/diffusion_matrix.h"
#include "solver/diffusion_solve.h"
#include "solver/environment_transfer.h"
#include "solver/lighting.h"
#include "solver/ray_caster.h"
#include "solver/shading_surface.h"
#include "solver/solved_scene.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

namespace waxwork {

struct LiveSceneOptions {
    double mm_per_unit = 1.0;
    // converge() and converged() stop at this estimated relative error of phi (conjugate_gradient.h).
    double relative_tolerance = 1e-3;
    // The per-frame solver (live_solver.h): method, backend, and the GPU backend's context (null: an
    // OSMesa context of its own). A failing GPU falls back to the CPU (LiveScene::gpu_fallback_reason).
    LiveMethod method = LiveMethod::JacobiCg;
    LiveBackend backend = LiveBackend::Cpu;
    std::shared_ptr<SolverGlContext> gl_context;
    // The clock of step(FrameBudget)'s time limits (LiveSolverOptions::clock); empty: steady_clock.
    MillisecondClock clock;
    MultigridOptions multigrid;  // LiveSolverOptions::multigrid
    // Where the image splits the surface's shading (solver/shading_surface.h), in [0, 180] degrees.
    double crease_angle_degrees = kDefaultCreaseAngleDegrees;
};

// One frame of the solve.
struct FrameReport {
    // CG iterations per rgb channel this frame; multigrid CG: V-cycles, each serving all three channels
    // (the same count in each; live_solver.h maps an iteration budget k to max(1, k / 4) of them).
    std::array<int, 3> iterations{};
    std::array<double, 3> estimated_relative_error{}; // after this frame
    bool converged = false;                          // every channel within the tolerance
    double milliseconds = 0;

    int total_iterations() const { return iterations[0] + iterations[1] + iterations[2]; }
    double max_error() const {
        return std::max({estimated_relative_error[0], estimated_relative_error[1], estimated_relative_error[2]});
    }
};

// What apply_change()/set_lighting() redid.
struct SceneUpdate {
    bool rebuilt_connectivity = false;
    bool reassembled_matrix = false;     // pattern and/or geometry and all values
    bool recomputed_values = false;      // all values on the kept pattern
    std::vector<int32_t> updated_rows;   // rows rewritten by the incremental update (ascending)
    bool rebuilt_surface = false;        // boundary surface and shadow BVH
    size_t resampled_transfer = 0;       // surface vertices whose environment transfer was sampled at once
    // Surface vertices that can see what changed and keep their old transfer until the next frames
    // sample it again (LiveScene::deferred_transfer).
    size_t deferred_transfer = 0;
    bool recomputed_light = false;       // q and the right-hand sides
    bool warm_start = true;              // phi kept (possibly through a vertex map)
    double milliseconds = 0;
};

// How long a frame spends sampling deferred transfer vectors again before it iterates, and how many
// vertices it samples at a time: with 256 rays per vertex a chunk is about 65K rays, some 10 ms on
// one core, so a frame stays near 30 fps while a large cut's light settles within seconds.
inline constexpr double kTransferRefineMilliseconds = 12;
inline constexpr size_t kTransferRefineChunk = 256;

class LiveScene {
public:
    // Builds everything for `mesh` (which must store one material per tet, as Document guarantees).
    // Throws InvalidArgumentError for bad lights, options or materials.
    LiveScene(const TetMesh& mesh, const Lighting& lighting, const LiveSceneOptions& options = {});

    // After Document::apply/undo/redo changed `mesh` (the document's mesh, same object or not).
    SceneUpdate apply_change(const TetMesh& mesh, const ChangeReport& change);
    SceneUpdate set_lighting(const Lighting& lighting);
    // Splits the surface at creases of more than `degrees` from now on: the image shades each side as
    // itself, and the solve's q integrates each side's light (source_light), so the right-hand sides
    // change and the solve goes on warm from the current phi, as after a light change (the matrix is
    // untouched). Throws InvalidArgumentError outside [0, 180], before anything changes.
    SceneUpdate set_crease_angle(double degrees);

    // At most `iteration_budget` CG iterations per channel, from the current phi. Channels already
    // within the tolerance are not iterated (an idle scene costs nothing).
    FrameReport step(int iteration_budget);
    // Within a frame budget instead (solver/frame_budget.h; validated, InvalidArgumentError): an
    // iteration and/or millisecond limit, which the solver enforces itself (LiveSolver::iterate): one
    // warm CG (or V-cycle) run per channel stopped at the deadline, unlike step_for's restarted chunks.
    FrameReport step(const FrameBudget& budget);
    // A time budget instead: CG in chunks of `chunk_iterations` per channel until `milliseconds` have
    // passed or the tolerance is reached (each chunk restarts CG from the current phi, which costs a
    // little convergence against one longer run; at least one chunk runs). Multigrid CG runs max(1, chunk / 4)
    // V-cycles per chunk and resumes its CG across chunks instead.
    FrameReport step_for(double milliseconds, int chunk_iterations = 4);
    // Iterates until the tolerance (or `max_iterations` per channel: AlgorithmError if not reached,
    // naming the precision floor when the solve stopped at it). On the GPU backend, a tolerance below
    // float's floor on this volume is reached in double on the CPU, which solves from then on
    // (LiveSolver::fall_back_to_cpu; gpu_fallback_reason() says why).
    FrameReport converge(int max_iterations = 10000);
    // False while phi is outside the tolerance or some transfer vectors still wait to be sampled.
    bool converged() const;
    // After an edit, the surface vertices and split copies whose environment transfer stands in for
    // the full sampling (carried over although they can see what changed, or sampled with few rays):
    // each step() samples some of them again (about kTransferRefineMilliseconds), converge() all, and
    // the light they give follows; the result then equals a fresh scene's.
    size_t deferred_transfer() const;
    // The estimated relative error of phi (max over channels) after the last step(), or nullopt when
    // nothing was solved since the last change.
    std::optional<double> estimated_error() const;

    // A copy of the current state in the form render_pipeline.h renders (make_render_input), with the
    // exitant radiance factors computed from the current phi (unless `with_radiance` is false: a
    // caller that has E from the device leaves radiance_factor empty).
    SolvedScene solved_scene(bool with_radiance = true) const;
    // Only the exitant radiance factors E per shading vertex (solved_scene().shading) from the current
    // phi (what a window re-uploads each frame while the surface is unchanged).
    std::vector<std::array<float, 3>> radiance_factors() const;

    Lighting lighting() const;
    const LiveSceneOptions& options() const { return options_; }
    // For tests and the bench; not synchronised (call when no step() runs).
    const DiffusionMatrix& matrix() const { return matrix_; }
    const TetConnectivity& connectivity() const { return *connectivity_; }
    std::vector<std::array<double, 3>> phi() const;
    // The backend solving now (Cpu after a GPU fallback), why the GPU was given up ("" if it was not),
    // and a line for the solver panel ("GPU CG (llvmpipe ...)").
    LiveBackend backend() const;
    std::string gpu_fallback_reason() const;
    // Why the chosen method runs as Jacobi CG ("" if it does not; LiveSolver::method_fallback_reason).
    std::string method_fallback_reason() const;
    std::string solver_description() const;
    // The level sizes and changed-row counts of the hierarchy of the multires method or the CPU
    // multigrid CG (level l: {vertices, HierarchyLevel::changed_vertices}); empty with other methods.
    std::vector<std::array<int64_t, 2>> multires_levels() const;
    // Galerkin rows the multigrid CG's preconditioner copied from the one before the last edit, summed
    // over its levels (MultigridPreconditioner::copied_operator_rows); -1 without one.
    int64_t multigrid_copied_rows() const;
    // With the GPU backend running: E per shading vertex (solved_scene().shading order) on the device,
    // from the resident phi (LiveSolver::radiance_on_device), for a renderer sharing the solver's
    // context to draw instead of the CPU's radiance_factor; else null. `host_copy`: as
    // LiveSolver::radiance_on_device.
    std::shared_ptr<const GpuBuffer> device_radiance(std::vector<std::array<float, 3>>* host_copy = nullptr);

private:
    // new_of_old_vertex: where the previous mesh's vertices went (a cut's map), or empty when unknown.
    void rebuild_all(std::shared_ptr<const TetConnectivity> connectivity, SceneUpdate& update,
                     std::span<const int32_t> new_of_old_vertex = {});
    // `vertex_map`: where the old volume vertices went (empty: the same numbering; nullopt: unknown),
    // so that the environment's transfer is carried over where nothing it integrates changed.
    void rebuild_surface(SceneUpdate& update, std::optional<std::span<const int32_t>> vertex_map = std::nullopt);
    void relight(SceneUpdate& update);
    // q and visibility of the shading's copies from the surface's (after either changed), and the
    // solve's q from the copies' (source_light); the caller refreshes the right-hand sides.
    void light_shading();
    // Computes transfer_ when the environment needs one it does not have (or of another order or
    // shadow setting), drops it without an environment.
    void refresh_transfer();
    void refresh_right_hand_sides();
    // Samples deferred transfer vectors again, chunk by chunk until `milliseconds` have passed (at
    // least one chunk), and relights those vertices.
    void refine_transfer(double milliseconds);
    void mark_unconverged();
    // `time_budget` (optional) replaces the iteration budget.
    FrameReport iterate(int iteration_budget, const FrameBudget* time_budget = nullptr);

    mutable std::mutex mutex_;
    const TetMesh* mesh_;
    LiveSceneOptions options_;
    Lighting lighting_;
    std::shared_ptr<const TetConnectivity> connectivity_;
    DiffusionMatrix matrix_;
    BoundarySurface surface_;
    TriangleBvh shadow_bvh_;
    // The environment's transfer per surface vertex (environment_transfer.h): computed when the
    // surface is rebuilt, so that a change of the environment alone costs a dot product per vertex.
    std::optional<EnvironmentTransfer> transfer_;
    std::optional<EnvironmentTransfer> copy_transfer_;  // per split copy of shading_ (split_copy_transfer)
    std::vector<int32_t> deferred_transfer_;    // surface vertices whose transfer_ is stale (deferred_transfer())
    std::vector<int32_t> deferred_copies_;      // split copies (into shading_.split_copies) whose copy_transfer_ is
                                                // coarse
    std::vector<Rgb> surface_q_;                // per surface vertex
    std::vector<float> surface_visibility_;     // per surface vertex and light (incident_light)
    ShadingSurface shading_;                    // the surface split at creases (options_.crease_angle_degrees)
    ShadingLight shading_light_;                // q and visibility per shading vertex
    std::vector<Rgb> q_;                        // per volume vertex: source_light
    std::vector<CornerLight> corners_;          // the rest of the light at creases: corner_light
    std::array<std::vector<double>, 3> b_;      // right-hand side per channel
    std::array<std::vector<double>, 3> phi_;    // current fluence per channel
    std::unique_ptr<LiveSolver> solver_;
    std::array<double, 3> error_{1, 1, 1};
    std::array<bool, 3> converged_{};
    bool solved_since_change_ = false;
};

}  // namespace waxwork
