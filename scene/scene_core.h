// The scene controller the window and `waxwork run` share: one Document (the volume with undo), its
// LiveScene, and the session head they were made from. Every edit, undo and redo goes through here,
// so the live scene follows the document's ChangeReport the same way whichever front end drives it.
//
// tick() is one step of the window's worker: the queued jobs (edits, undo, saves) in order, a new
// crease angle and lighting, one solver step within the frame budget and, when anything shown changed,
// the next image input (make_render_input, the optional view, the picking BVH). `waxwork run`
// (session.h run_session) calls the single operations instead and renders converged or counted frames.
//
// Not synchronised: one thread at a time uses a SceneCore (the window's worker while a tick runs; the
// UI thread only between ticks). The live scene borrows the document's mesh, so a SceneCore is neither
// copied nor moved.
#pragma once

#include "render/render_input.h"
#include "render/view_modes.h"
#include "scene/document.h"
#include "scene/edit_operation.h"
#include "scene/live_scene.h"
#include "scene/session.h"
#include "solver/frame_budget.h"
#include "solver/lighting.h"
#include "solver/ray_caster.h"
#include "tetops/boundary_shells.h"
#include "tetops/tet_mesh.h"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace waxwork {

class SceneCore;

// A picture asked for at one point of the editing (the editor's Snapshot): after the first `history`
// operations of the document's history, seen with `camera` under `lighting`.
struct SessionSnapshot {
    size_t history = 0;
    CameraSettings camera;
    Lighting lighting;
    std::optional<double> exposure;  // the one the view was shown with (nullopt: automatic)
};

// One queued piece of work for the next tick; returns a status line. Throws to report a failure
// (the document is then unchanged, Document::apply's guarantee).
using SceneJob = std::function<std::string(SceneCore&)>;

// What one tick does, handed over whole so the front end can queue the next batch meanwhile.
struct SceneTickRequest {
    std::vector<std::pair<std::string, SceneJob>> jobs;  // label and job, run in order
    std::optional<Lighting> lighting;                    // new lighting for the live scene
    std::optional<double> crease_angle;                  // degrees, already checked (is_crease_angle)
    FrameBudget budget = FrameBudget::iterations(10);    // of the tick's solver step
    bool first = false;     // nothing shown yet: make the image input whatever changed
    bool need_bvh = false;  // no picking BVH yet: build one with the image input
    ImageSettings image;    // the size and camera the automatic exposure is taken for
    ViewOptions view;       // what the image shows (render/view_modes.h)
    bool view_changed = false;  // `view` differs from the previous tick's: make the image input again
};

// What the tick produced: everything the front end shows of the scene, copied out of it.
struct SceneTickResult {
    std::vector<std::string> messages;  // the status line of each job that ran, then the crease angle's
    std::vector<std::string> errors;    // "label: what" of each job that threw
    bool geometry_changed = false;      // a job ran (or the crease angle changed the shading's vertices)
    std::optional<SurfaceRenderInput> input;     // the next image input, when anything shown changed
    std::shared_ptr<const ViewGeometry> view;    // the optional view applied to `input` (not Radiance)
    std::shared_ptr<const TriangleBvh> bvh;      // of input's triangles, when the geometry changed or asked
    std::vector<int32_t> surface_piece;          // with `bvh`: per input vertex, its piece
    std::vector<RigidTransform> piece_transforms;
    FrameReport frame;  // the tick's solver step
    bool converged = false;
    std::optional<double> estimated_error;
    bool can_undo = false, can_redo = false;
    size_t history = 0, tets = 0, vertices = 0;
    double min_dihedral = 0;
    // With the geometry (a job ran, or the first tick): diffusion_trust_warning of the materials, empty
    // when they are all in the regime where the live image can be trusted.
    std::optional<std::string> trust_warning;
    LiveBackend backend = LiveBackend::Cpu;  // after the step (Cpu after a fallback)
    std::string solver_description, gpu_fallback_reason, method_fallback_reason;
    double milliseconds = 0;  // the whole tick
};

class SceneCore {
public:
    // A freshly loaded volume: InvalidArgumentError "NAME: the volume has no tets" for an empty one,
    // else the document (materials stored in `mesh` kept, setup.material on every tet otherwise) and its
    // live scene. `solver` gives the method, backend and context; setup's scale, tolerance and crease
    // angle replace its own (a setup without a scale gets default_mm_per_unit of the volume's size).
    SceneCore(TetMesh mesh, const Session& setup, LiveSceneOptions solver);
    // As above for a document already built (no emptiness check: the Document constructor's).
    SceneCore(Document document, const Session& setup, LiveSceneOptions solver);
    SceneCore(const SceneCore&) = delete;
    SceneCore& operator=(const SceneCore&) = delete;

    const Document& document() const { return document_; }
    const LiveScene& live() const { return *live_; }
    // The session head: input, material, scale (always set), tolerance, lighting, camera, frame budget
    // (no steps).
    const Session& setup() const { return setup_; }

    // Document::apply / undo / redo, each followed by the live scene's update from the report.
    ChangeReport apply(const EditOperation& op);
    std::optional<ChangeReport> undo();  // nullopt: nothing to undo (nothing changed)
    std::optional<ChangeReport> redo();
    // Document::preview_deform / commit_deform / cancel_deform (a Grab, Bend or Twist drag), each
    // followed by the live scene's update of the moved vertices.
    ChangeReport preview_deform(const DeformOp& op, int iterations);
    ChangeReport commit_deform(const DeformOp& op);
    std::optional<ChangeReport> cancel_deform();

    // A new live scene for `options` (method, backend, scale, tolerance, crease angle), lit as the
    // current one and solved again from scratch. The head follows these three setters.
    void set_solver_options(const LiveSceneOptions& options);
    void set_lighting(const Lighting& lighting);
    // Throws InvalidArgumentError outside [0, 180] before anything changes (LiveScene::set_crease_angle).
    void set_crease_angle(double degrees);

    // LiveScene::step and converge.
    FrameReport step(const FrameBudget& budget);
    FrameReport converge();

    // One tick (see the top); `stage` (optional) is told what runs now ("solving", a job's label, ...).
    // A job that throws is reported in errors and the others still run; a failing solver step throws.
    SceneTickResult tick(const SceneTickRequest& request,
                         const std::function<void(const std::string&)>& stage = {});

    // The volume (format from the extension, io/volume_file.h).
    void save_volume(const std::filesystem::path& path) const;
    // The boundary surface (io/surface_writer.h, format from the extension): converges the light first
    // and, where the format stores colours, bakes its exitant radiance (scene/surface_export.h, as
    // `waxwork export --radiance` bakes it). Returns whether colours were written.
    bool export_surface(const std::filesystem::path& path, ShellGrouping grouping);
    // The session that replays this document: `head` (usually setup() with what the front end changed
    // since: its view, lights, frame budget), the document's history as steps, then a converged render
    // and a save named after the file (NAME.json renders NAME.png and saves NAME.vtu). Each snapshot
    // becomes, at its point of the history, its camera, its lights and a render NAME_snapshot_K.png (K
    // from 1); the final render then returns to head's camera and lights, at `exposure` when given.
    void save_session(const std::filesystem::path& path, const Session& head,
                      const std::vector<SessionSnapshot>& snapshots = {},
                      std::optional<double> exposure = std::nullopt) const;

private:
    // Declared in this order: the live scene borrows the document's mesh, so it is destroyed first.
    Session setup_;
    Document document_;
    std::unique_ptr<LiveScene> live_;
    // The optional views' geometry (view_modes.h), rebuilt only when its versions move.
    ViewGeometryCache view_cache_;
    long long geometry_version_ = 0, solution_version_ = 0;
};

}  // namespace waxwork
