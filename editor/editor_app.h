// The interactive editor: a GLFW window with an OpenGL 4.5 core context, Dear ImGui panels around a
// 3D viewport drawn by SurfaceRenderer (the renderer `waxwork render` uses, so both show the same
// image), an orbit camera, and background tasks for everything slow.
//
// Threading: the UI thread owns every piece of editor state and never waits. Loading (reading,
// meshing, building the SceneCore: document and live scene, scene/scene_core.h) runs as one
// BackgroundTask; after that a second task runs SceneCore::tick one after another on a worker: each
// applies the queued edits (apply, undo, redo, saves) and lighting changes to the document and live
// scene, advances the solve by the per-frame budget and prepares the next image input. Only the worker
// touches the SceneCore while a tick runs; the UI thread sees copies (EditorScene) that it installs
// when it polls the finished tick, and queues new work for the next one.
#pragma once

#include "editor/background_task.h"
#include "editor/file_dialog.h"
#include "editor/input_script.h"
#include "editor/orbit_camera.h"
#include "editor/reference_view.h"
#include "editor/repair_choices.h"
#include "editor/view_cache.h"
#include "editor/viewport_tools.h"
#include "render/image_background.h"
#include "render/render_input.h"
#include "render/surface_renderer.h"
#include "render/view_modes.h"
#include "scene/document.h"
#include "scene/live_scene.h"
#include "scene/recent_files.h"
#include "scene/recovery_files.h"
#include "scene/scene_core.h"
#include "scene/session.h"
#include "solver/light_spec.h"
#include "solver/ray_caster.h"

#include <chrono>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

struct GLFWwindow;

namespace waxwork {

struct EditorOptions {
    std::filesystem::path file;          // surface or volume to open; empty: start empty
    std::filesystem::path session;       // a session (session.h) to open instead: its input, material,
                                         // lights and camera, with its edit steps replayed
    std::optional<size_t> max_tets;      // meshing a surface: about this many tets (default by material)
    std::optional<double> edge;          // meshing a surface: this edge length instead (model units)
    Mesher mesher = Mesher::TetGen;      // meshing a surface: the mesher, its quality bounds and the
    double min_dihedral_deg = MeshingOptions{}.min_dihedral_deg;  // opt-in repairs (as `waxwork mesh`)
    double max_radius_edge_ratio = MeshingOptions{}.max_radius_edge_ratio;
    SurfaceRepairOptions repair;
    std::optional<TetMaterial> material; // applied to the whole volume after loading
    std::filesystem::path screenshot;    // non-empty: render `frames` frames, save the window, exit
    int frames = 10;                     // frames drawn after loading and solving finished
    bool hide_ui = false;                // the 3D view alone fills the window (compare with `waxwork render`)
    int width = 1280;                    // window size in screen coordinates
    int height = 800;
    std::vector<Light> lights;           // empty: default_key_light
    std::optional<double> scale;         // millimetres per model unit; nullopt: the volume's stored scale,
                                         // else one chosen from the model's size (tetops/model_scale.h)
    double crease_angle_degrees = kDefaultCreaseAngleDegrees;  // where the surface folds (--crease-angle)
    CameraSettings camera;               // the first view (as `waxwork render --view`)
    ViewOptions view;                    // what the 3D view shows (as `waxwork render --show`)
    std::optional<InputScript> input;    // replayed into the window once the object shows (--input)
    LiveMethod solver_method = LiveMethod::JacobiCg;  // the live solver (live_solver.h); the solver
    LiveBackend solver_backend = LiveBackend::Cpu;    // panel switches both
    std::optional<double> frame_ms;      // a time budget per solver step instead of iterations (--frame-ms);
                                         // also wins over an opened session's
    double autosave_seconds = 60;        // unsaved edits are copied to the recovery folder this often
                                         // (scene/recovery_files.h; --autosave)
};

// Opens the window and runs until it is closed (or, with a screenshot, until it is saved). Throws
// waxwork::Error when no window or OpenGL 4.3+ context can be created, and what loading throws in
// screenshot mode (interactively, errors are shown in the window instead).
struct EditorRunStats {
    int frames = 0;              // frames drawn after loading and solving finished
    double mean_frame_ms = 0;    // per frame, UI + 3D view, GPU finished (screenshot mode)
    double mean_view_ms = 0;     // drawing the 3D view (only when it changed; else a cached copy)
    double tick_ms = 0;          // mean worker tick (edits, solver step, image input) while converging
    int ticks = 0;
    size_t tets = 0, vertices = 0;
    double mm_per_unit = 0;      // the scale the model was shown at
    std::string gl_version, gl_renderer;
    std::string solver_backend;       // "cpu" or "gpu": what solved the last frame
    std::string gpu_fallback_reason;  // why the GPU backend was given up, if it was
    std::string method_fallback_reason;  // why the chosen method ran as Jacobi CG, if it did
    bool view_reads_device_radiance = false;  // the 3D view drew E from the GPU solver's buffer
    // Frames drawn while an input script ran, and while a reference was being traced (View > Render
    // reference): their UI and view work (not the screenshot mode's waits between frames), mean and
    // longest.
    int script_frames = 0;
    double mean_script_frame_ms = 0;
    double max_script_frame_ms = 0;
    int frames_while_tracing = 0;
    double mean_frame_ms_while_tracing = 0;
    double max_frame_ms_while_tracing = 0;
    double tick_ms_while_tracing = 0;  // the worker's mean tick meanwhile
    bool modified = false;             // edits not saved when the window closed
    std::string title;                 // the window's title then
};
EditorRunStats run_editor(const EditorOptions& options);

// True when a window can be opened here (a display is set and GLFW initialises). `waxwork demo` asks
// before opening the editor so it stays headless on servers.
bool display_available();

// For `waxwork demo`: opens the editor on `options` when display_available(), returns whether it did
// (false on a server: the caller carries on headless). Errors after the window opened propagate.
bool try_open_editor(const EditorOptions& options);

class EditorApp;
// Drives `app` in `window` through GLFW's installed callbacks (viewport_input.cpp), for --input.
std::unique_ptr<ScriptTarget> make_window_script_target(GLFWwindow* window, EditorApp& app);

// What the UI thread knows about the scene: copies refreshed after every tick.
struct EditorScene {
    std::shared_ptr<SceneCore> core;  // used by one worker tick at a time, never while a tick runs
    size_t tets = 0, vertices = 0;
    bool can_undo = false, can_redo = false;
    size_t history_size = 0;
    std::string material_name;

    std::optional<SurfaceRenderInput> render_input;  // the latest image input
    std::shared_ptr<const TriangleBvh> surface_bvh;  // of render_input's triangles (paint picking)
    std::vector<int32_t> surface_piece;              // per render_input vertex: its piece
    std::vector<RigidTransform> piece_transforms;
    float automatic_exposure = 1.0f;
    bool exposure_locked = false;  // set at the first convergence: relighting then changes brightness
    FrameReport last_frame;        // the latest solver step
    bool converged = false;
    std::optional<double> estimated_error;
    double tick_ms = 0;
    double tick_ms_sum = 0;
    int ticks = 0;
    double tick_ms_sum_while_tracing = 0;  // the ticks that ran while a reference was being traced
    int ticks_while_tracing = 0;
    double min_dihedral_deg = 0;
    std::string trust_warning;  // SceneTickResult::trust_warning, kept until the next one
    // Moves whenever the light shown may differ from before: an edit, undo or redo, new lights or
    // crease angle. A reference tagged with an older one shows an earlier state.
    long long light_version = 0;
    // Of the loaded volume, for the size in mm beside the scale and the mesh's fit to the rule at it.
    Eigen::Vector3d extent = Eigen::Vector3d::Zero();  // bounding box, model units
    double surface_edge = 0;                           // mean_surface_edge_length, model units
    TetMaterial setup_material;                        // the material the rule sizes for
    std::filesystem::path source_surface;              // the surface it was meshed from (empty: a volume)
    SurfaceRepairOptions source_repair;                // and the repairs it was opened with
    LiveBackend solver_backend = LiveBackend::Cpu;  // after the latest tick (Cpu after a fallback)
    std::string solver_description;
    std::string gpu_fallback_reason;
    std::string method_fallback_reason;
};

// Everything the window shows and edits. UI-thread only.
class EditorApp {
public:
    EditorApp(GLFWwindow* window, const EditorOptions& options);
    ~EditorApp();
    EditorApp(const EditorApp&) = delete;
    EditorApp& operator=(const EditorApp&) = delete;

    // One frame: events already polled; polls tasks, handles input, draws the view and the UI.
    void frame();
    // Nothing loading, queued or running, and the solve converged (screenshot mode waits for this).
    bool idle() const;
    // Screenshot mode: blocks until the running task finishes (the frame loop then installs it).
    void wait_for_tasks();
    Image read_window() const;
    // The 3D view's pixels alone (what `waxwork render` would write for the same scene and size).
    Image read_viewport() const;
    // True while something on screen changes without input (a stroke, a drag).
    bool animating() const { return tools_.active(); }
    // The loaded object is on screen (its camera exists): scripted input starts here.
    bool viewport_ready() const { return camera_.has_value() && scene_->render_input.has_value(); }
    // The first error of a failed load or solve (screenshot mode turns it into the exit status).
    const std::string& last_error() const { return last_error_; }
    // The refusal of a surface whose error dialog offers repairs, while none was chosen ("" if none):
    // screenshot mode waits for a script to answer it and fails with it otherwise.
    const std::string& unanswered_refusal() const;
    const GlApi& gl() const { return gl_; }
    const EditorScene& scene() const { return *scene_; }
    double view_ms() const { return last_render_ms_; }
    double mm_per_unit() const { return live_options_.mm_per_unit; }

    // Loads a surface (meshed with the current options) or a volume file, in the background, at
    // `scale` mm per unit when given (else --scale, else the volume's stored scale, else the model's),
    // with `repair` instead of the command line's repairs when given. The status bar shows its stages
    // with Cancel; a surface refused for its defects gets an error dialog offering the repairs that
    // apply (repair_choices.h).
    void open_file(const std::filesystem::path& path, std::optional<double> scale = std::nullopt,
                   std::optional<SurfaceRepairOptions> repair = std::nullopt);
    // The status bar's Cancel: asks the load running to stop; the document open before stays as it
    // was and the status says "Cancelled loading FILE". Returns false when nothing is loading.
    bool cancel_loading();
    // A button of the refused surface's error dialog: reopens the file with the repair whose id is
    // `id` (RepairChoice::id). An error when no refusal is shown or it does not offer that repair.
    void choose_repair(const std::string& id);
    void save_volume(const std::filesystem::path& path);
    void on_drop(const std::vector<std::filesystem::path>& paths);
    void on_key(int key, int mods);
    // Pointer input in window coordinates, from GLFW's callbacks (real or scripted input alike).
    void on_cursor(double x, double y);
    void on_mouse_button(int button, int action, int mods);
    void on_scroll(double steps);
    void select_tool(Tool tool);
    // The material panel's preset `name` becomes the brush's material (as clicking it in the panel).
    void select_brush_material(const std::string& name);
    // The View panel's crease angle (solver/shading_surface.h): sent to the live scene with the next
    // tick, the latest value only when several arrive while a tick runs (a dragged slider). Throws
    // InvalidArgumentError outside [0, 180].
    void set_crease_angle(double degrees);
    void save_session(const std::filesystem::path& path);
    // File > Snapshot: the view and lights as they are now, at this point of the edit history, become a
    // render step in the sessions saved from now on (dropped when an undo goes back past it).
    void snapshot();
    size_t snapshot_count() const { return snapshots_.size(); }
    // The view as a session records it: the camera relative to the shown model's box now (a cut model
    // frames differently from the loaded one) and the exposure it is drawn with.
    CameraSettings recorded_camera() const;
    double shown_exposure() const;
    // File > Export: the boundary surface (.ply, .obj, .stl), with the current light's radiance baked
    // into vertex colours where the format stores them (SceneCore::export_surface), in the background.
    void export_surface(const std::filesystem::path& path);
    // View > Render reference: converges the live light, copies the scene and traces the current view
    // with Monte Carlo in the background (ReferenceView), leaving the editor usable meanwhile.
    void render_reference();
    // The same with the Reference window's settings changed first where given (input scripts): the
    // time limit, the noise target in percent and the size as 1/divisor of the view (4, 2 or 1).
    void render_reference_with(std::optional<double> seconds, std::optional<double> noise_percent,
                               std::optional<int> size_divisor);
    // The Reference window's Cancel; false when no reference is being traced.
    bool cancel_reference();
    // The Reference window's Save: its comparison as PNG, its numbers beside it as JSON.
    void save_reference(const std::filesystem::path& path);
    // File > Save image: the 3D view as shown (its exposure and tone mapping, no panels: read_viewport)
    // as .png or .jpg/.jpeg, written once the current frame's view is drawn.
    void save_image(const std::filesystem::path& path);
    // File > Export turntable: `frames` pictures of the view circling the model's vertical axis
    // (render/turntable.h: the camera turned about its up vector) at the view's exposure, one per window
    // frame so the window keeps responding, into the folder named after `video` without its extension
    // (frame_0000.png, ...); then `video` itself through ffmpeg when it is on the PATH. Esc stops it.
    void export_turntable(const std::filesystem::path& video, int frames);
    // The View panel's background: "automatic", "environment" or a colour as parse_background reads
    // it (render/image_background.h). Throws InvalidArgumentError for others and for transparent.
    void set_background(const std::string& background);
    const ReferenceView& reference() const { return *reference_; }

    // Document safety (document_safety.cpp). Edits since the last save of the volume or session
    // (undoing back to it still counts as modified); the title shows them with " *".
    bool modified() const { return modified_; }
    const std::string& title() const { return shown_title_; }
    // Ctrl+Q, File > Quit and the window's close button: asks Save / Discard / Cancel first when
    // modified, else closes the window.
    void request_quit();
    // Opens `path` (File > Open, Open Recent, a drop, the start screen), asking first when modified.
    // `camera`: the first view instead of the command line's (the examples' front views).
    void request_open(const std::filesystem::path& path, std::optional<CameraSettings> camera = std::nullopt);
    // A button of the unsaved-changes dialog: "save", "discard" or "cancel". Save writes the session
    // or volume the document came from or was last saved as (`file` instead when given; a Save
    // dialog when there is neither), then carries on. An error when no dialog is asking.
    void answer_unsaved_dialog(const std::string& button, const std::filesystem::path& file = {});
    // The recovery offer of a run that did not exit cleanly: opens its volume, or removes its files.
    // Errors when nothing is offered.
    void recover();
    void discard_recovery();
    // Writes the recovery copy now (it is written every EditorOptions::autosave_seconds of unsaved
    // edits).
    void autosave();
    // The start screen (start_screen.cpp): shown while no document is open or loading. Opens the
    // bundled example `name` (example_models()) as a click on it does.
    bool start_screen_shown() const { return !scene_->core && !load_task_.busy(); }
    void open_example(const std::string& name);

private:
    using Scene = EditorScene;
    // editor_panels.cpp: the ImGui parts.
    void draw_ui();
    void draw_menu_bar();
    void draw_tool_palette();
    void draw_side_panel();
    void draw_material_panel();
    void draw_brush_panel();
    void draw_deform_panel();
    void draw_light_panel();
    void draw_environment_controls();
    void draw_solver_panel();
    // editor_solver_choice.cpp: the method and backend combos, and the GPU context they need.
    void draw_solver_choice();
    void choose_solver(LiveMethod method, LiveBackend backend);
    // frame_budget_choice.cpp: "iterations / frame" or "ms / frame" and the budget each tick solves with.
    void draw_frame_budget_choice();
    FrameBudget frame_budget() const;
    void adopt_frame_budget(const Session& session);  // an opened session's, unless --frame-ms was given
    void draw_view_panel();
    void draw_view_mode_panel();  // view_mode_panel.cpp: the optional views and their legend
    void draw_view_mode_menu();   // view_mode_panel.cpp: View > Show
    void draw_status_bar();
    void draw_overlays();
    void apply_theme(float scale);

    // What a Save dialog writes when confirmed.
    enum class SaveKind { Volume, Session, Surface, Reference, Image, Turntable };
    void open_dialog(FileDialog::Mode mode, SaveKind kind = SaveKind::Volume);
    void write_saved_image();  // save_image's file, from the view just drawn
    void advance_turntable();  // the next frame of export_turntable's orbit
    void relax_last_cut();
    // What loading found out about the model, measured off the UI thread.
    struct LoadedModel {
        std::string scale_note;  // describe_model_scale: ends the status line
        double surface_edge = 0; // mean_surface_edge_length
    };
    static LoadedModel measure_loaded_model(const SessionVolume& input);
    void install_core(std::shared_ptr<SceneCore> core, const std::filesystem::path& path,
                      const std::string& material_name, const std::vector<EditOperation>& replay,
                      const LoadedModel& model);
    void draw_scale_fit();  // editor_panels.cpp: the size in mm and the mesh's fit to the scale
    std::optional<PieceHit> piece_under(const Eigen::Vector2d& pixel) const;
    void file_dialog_result();
    void undo();
    void redo();
    void queue_history_step(bool redo);
    void remove_fragments();
    bool can_undo() const;
    bool can_redo() const;
    void set_whole_material(const TetMaterial& material, const std::string& name);
    void queue_edit(const EditOperation& op);
    void queue_job(std::string label, SceneJob job);
    void rebuild_live_scene();
    void open_session(const std::filesystem::path& path);
    // viewport_input.cpp: pointer events to ViewportTools and its outcome to edits.
    ViewportContext viewport_context();
    void pointer_event(PointerAction action, PointerButton button, int mods, double scroll = 0);
    bool ui_has_pointer() const;
    void apply_tool_outcome(const ToolOutcome& outcome);
    // Grab, Bend and Twist: a preview replaces the one still queued (the worker shows the latest), a
    // finished drag commits, a cancelled one restores the volume as it was before the drag.
    void queue_deform(const ToolOutcome& outcome);
    void queue_cancel_deform();
    void draw_tool_overlay();
    // The Paint tool's rings on the surface under the cursor (stroke_tools.h brush_cursor).
    void draw_brush_cursor();
    void update_piece_preview();
    SurfaceRenderInput with_piece_preview(const SurfaceRenderInput& input) const;
    void layout_viewport(int fb_w, int fb_h);
    void poll_tasks();
    void request_solve();  // the lights changed
    void start_tick();
    void handle_viewport_input();
    void draw_viewport(int fb_h);
    void set_error(const std::string& message);
    void show_error(const std::string& message);  // as set_error, not counted as the run's error
    void load_failed(const std::exception& error);
    // document_safety.cpp
    struct DocumentAction {  // what the unsaved-changes dialog holds back
        bool quit = false;
        std::filesystem::path open;
        std::optional<CameraSettings> camera;
    };
    void ask_or_do(DocumentAction action);
    void do_action(const DocumentAction& action);
    void mark_modified();
    void mark_saved(const std::filesystem::path& path);
    void remember_output(const std::filesystem::path& path, bool recent);
    void document_opened(const std::filesystem::path& path);  // unmodified, recent, recovery done
    void document_frame();          // title, autosave, carrying on after the dialog's Save
    void draw_document_dialogs();   // the unsaved-changes and recovery dialogs
    void draw_open_recent_menu();
    void remove_own_recovery();
    Session view_session() const;   // the view, lights and budget as they are now (saved sessions keep them)
    // `setup` (the SceneCore's session head) with view_session()'s fields from `view`: the head a saved
    // or autosaved session starts with.
    static Session with_view(Session setup, const Session& view);
    void draw_start_screen();       // start_screen.cpp

    static constexpr float kToolPaletteWidth = 132;  // logical pixels (times the UI scale)
    static constexpr float kSidePanelWidth = 340;

    GLFWwindow* window_;
    EditorOptions options_;
    GlApi gl_;
    std::unique_ptr<SurfaceRenderer> renderer_;
    std::unique_ptr<ViewCache> view_cache_;
    long long scene_version_ = 0;  // bumped whenever the render input changes (ViewKey)
    int msaa_samples_ = 4;
    float ui_scale_ = 1.0f;

    // The GPU solver's context (window_gl_context.h), shared with this window's; opened when the GPU
    // backend is first chosen. Declared before scene_: the live scenes using it are destroyed first.
    std::shared_ptr<SolverGlContext> solver_context_;
    std::string solver_context_error_;
    // The scene: the volume, its materials and lights, the latest solved image input.
    std::unique_ptr<Scene> scene_;
    Lighting lighting_;
    LiveSceneOptions live_options_;
    int frame_iterations_ = 10;                // CG iterations per channel and tick
    bool frame_budget_in_ms_ = false;          // the solver step's budget is frame_ms_, not frame_iterations_
    float frame_ms_ = 10;                      // milliseconds of solver step per tick
    float exposure_stops_ = 0;                 // added to the automatic exposure
    std::optional<OrbitCamera> camera_;
    std::filesystem::path current_file_;

    BackgroundTask load_task_;
    // What open_file asked load_task_ for (nullopt: a session), to reopen it with a repair.
    struct LoadRequest {
        std::filesystem::path path;
        std::optional<double> scale;
        SurfaceRepairOptions repair;
    };
    std::optional<LoadRequest> loading_;
    // A refused surface and the repairs its error dialog offers (cleared by the next error or a choice).
    struct Refusal {
        LoadRequest request;
        std::string message;
        std::vector<RepairChoice> choices;
    };
    std::optional<Refusal> refusal_;
    bool close_error_popup_ = false;  // a repair was chosen by a script: the dialog goes
    BackgroundTask tick_task_;
    // Render reference: the trace and its window; the snapshot job's result until the trace starts,
    // and the camera it traces through.
    std::unique_ptr<ReferenceView> reference_;
    struct ReferenceSnapshot {
        bool taken = false;  // the job ran (it may have thrown, leaving `scene` empty)
        std::shared_ptr<const ReferenceScene> scene;
    };
    std::shared_ptr<ReferenceSnapshot> reference_snapshot_;
    std::vector<SessionSnapshot> snapshots_;  // File > Snapshot, in the order taken
    PixelCamera reference_camera_;
    std::deque<std::pair<std::string, SceneJob>> pending_jobs_;  // for the next tick, in order
    bool lighting_dirty_ = false;                                // send lighting_ with the next tick
    bool crease_angle_dirty_ = false;                            // send live_options_'s crease angle too
    std::optional<std::variant<PlaneSurface, StrokeSurface>> last_cut_;  // what Relax relaxes towards
    int fracture_pieces_ = 5;
    // Edit > Remove fragments: parts under this % of the volume go.
    float fragment_percent_ = static_cast<float>(100 * kDefaultFragmentFraction);
    uint32_t fracture_seed_ = 1;

    ViewportTools tools_;
    Eigen::Vector2d cursor_ = Eigen::Vector2d::Zero();  // window coordinates
    int mods_ = 0;                                       // of the latest button event
    std::optional<Eigen::Vector3d> shown_preview_;       // the piece translation the view shows
    int selected_light_ = 0;
    // The Lights panel's environment controls: the sky being edited and the .hdr path typed, kept
    // while the environment is off so that switching back restores them.
    SkySettings environment_sky_;
    std::array<char, 1024> environment_file_{};
    int selected_preset_ = 0;
    std::optional<TetMaterial> custom_material_;  // the material panel's current material
    // The paint brush, apart from the object's material: its preset, material and sigma (a fraction
    // of the scene radius). The Brush panel opens when the Paint tool is chosen.
    int brush_preset_ = 0;
    TetMaterial brush_material_;
    float brush_radius_ = 0.05f;
    bool open_brush_panel_ = false;
    // Grab, Bend, Twist and Pin: the handle's falloff radius (fraction of the scene radius), the
    // ARAP iterations each preview frame runs, and the pins placed (world space).
    float deform_radius_ = 0.25f;
    int deform_preview_iterations_ = 2;
    std::vector<PinSphere> pins_;
    bool show_light_gizmos_ = true;
    bool ground_plane_ = false;  // the View panel's: the model on a ground with its shadows
    ImageBackground background_;  // the View panel's: automatic, a colour, or the environment

    // Viewport rectangle in framebuffer pixels (origin top-left) and the scale from window to
    // framebuffer coordinates (HiDPI).
    int view_x_ = 0, view_y_ = 0, view_w_ = 1, view_h_ = 1;
    double framebuffer_scale_ = 1.0;

    FileDialog file_dialog_;
    SaveKind saving_ = SaveKind::Volume;
    struct TurntableExport {
        std::filesystem::path video, folder;
        int frames = 0, next = 0;
        CameraSettings start;        // the view when it began
        SurfaceRenderInput input;    // the scene as it was then, at the view's size and exposure
    };
    std::optional<TurntableExport> turntable_;
    BackgroundTask video_task_;  // ffmpeg on the frames
    std::optional<std::filesystem::path> image_to_save_;  // save_image's file, written after the view is drawn
    std::string status_;
    std::string last_error_;
    std::string error_message_;
    bool show_error_popup_ = false;
    double last_render_ms_ = 0;

    // The optional views (view_modes.h): the UI's choice (SceneCore caches their geometry).
    ViewOptions view_options_ = options_.view;
    bool view_dirty_ = false;  // the choice changed: the next tick rebuilds the image input
    std::shared_ptr<const ViewGeometry> view_geometry_;  // of the installed image input (the legend)

    // Document safety: the modified state, the dialog's held-back action, the recovery folders and
    // the recent files.
    bool modified_ = false;
    std::optional<std::chrono::steady_clock::time_point> unsaved_since_autosave_;
    std::filesystem::path save_target_;  // the session or volume the dialog's Save writes ("" : ask)
    std::optional<DocumentAction> unsaved_dialog_;   // asking Save / Discard / Cancel
    bool open_unsaved_popup_ = false;
    std::optional<DocumentAction> after_save_;        // carried on once the save finished
    int saves_ = 0, saves_before_ = 0;                // saves queued, and before the dialog's Save
    int errors_ = 0, errors_before_ = 0;              // errors shown, and before the dialog's Save
    std::filesystem::path state_dir_;
    RecentFiles recent_;
    RecoveryFiles own_recovery_;
    bool recovery_written_ = false;  // own_recovery_ may hold a copy (removed once saved)
    std::vector<RecoveryFiles> abandoned_;  // offered for recovery
    bool open_recovery_popup_ = false;
    std::optional<RecoveryFiles> recovering_;  // being opened: removed once its volume is open
    std::optional<CameraSettings> next_camera_;  // the next open's first view (request_open)
    std::string shown_title_;
};

}  // namespace waxwork
