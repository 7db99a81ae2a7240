// The interactive editor: a GLFW window with an OpenGL 4.5 core context, Dear ImGui panels around a
// 3D viewport drawn by SurfaceRenderer (the renderer `waxwork render` uses, so both show the same
// image), an orbit camera, and background tasks for everything slow. Threading: the UI thread owns
// every piece of editor state; loading/meshing and solving run as BackgroundTasks on worker threads
// with their own copies of the inputs, and the UI thread installs their results when it polls them.
#pragma once

#include "editor/background_task.h"
#include "editor/file_dialog.h"
#include "editor/orbit_camera.h"
#include "editor/render_pipeline.h"
#include "editor/surface_renderer.h"
#include "editor/view_cache.h"
#include "solver/diffusion_solve.h"
#include "solver/ray_caster.h"
#include "tetops/connectivity.h"

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

struct GLFWwindow;

namespace waxwork {

struct EditorOptions {
    std::filesystem::path file;          // surface or volume to open; empty: start empty
    std::optional<size_t> max_tets;      // meshing a surface: about this many tets (default by material)
    std::optional<TetMaterial> material; // applied to the whole volume after loading
    std::filesystem::path screenshot;    // non-empty: render `frames` frames, save the window, exit
    int frames = 10;                     // frames drawn after loading and solving finished
    bool hide_ui = false;                // the 3D view alone fills the window (compare with `waxwork render`)
    int width = 1280;                    // window size in screen coordinates
    int height = 800;
    std::vector<Light> lights;           // empty: default_key_light
    double scale = 1.0;                  // millimetres per model unit
    CameraSettings camera;               // the first view (as `waxwork render --view`)
};

// Opens the window and runs until it is closed (or, with a screenshot, until it is saved). Throws
// waxwork::Error when no window or OpenGL 4.3+ context can be created, and what loading throws in
// screenshot mode (interactively, errors are shown in the window instead).
struct EditorRunStats {
    int frames = 0;              // frames drawn after loading and solving finished
    double mean_frame_ms = 0;    // per frame, UI + 3D view, GPU finished (screenshot mode)
    double mean_view_ms = 0;     // drawing the 3D view (only when it changed; else a cached copy)
    double solve_ms = 0;         // the last solve: lighting + assembly + CG + radiance
    size_t tets = 0, vertices = 0;
    std::string gl_version, gl_renderer;
};
EditorRunStats run_editor(const EditorOptions& options);

// True when a window can be opened here (a display is set and GLFW initialises). `waxwork demo` asks
// before opening the editor so it stays headless on servers.
bool display_available();

enum class Tool { Orbit, Cut, ExactCut, Relax, Fracture, MovePiece, Paint, Light };

struct ToolInfo {
    Tool tool;
    const char* name;
    const char* shortcut;  // shown in the menus; empty: none
};
const std::vector<ToolInfo>& tool_infos();

// The loaded volume and what was last solved on it. Shared pointers: a running solve keeps its own
// references, so replacing the scene on the UI thread never pulls data from under a worker.
struct EditorScene {
    std::shared_ptr<const TetMesh> mesh;
    std::shared_ptr<const TetConnectivity> connectivity;
    std::vector<TetMaterial> materials;  // per tet
    std::string material_name;           // preset applied to the whole volume, or "stored"/"custom"

    std::optional<SurfaceRenderInput> render_input;  // the latest solved image input
    std::shared_ptr<const TriangleBvh> surface_bvh;  // of render_input's triangles (paint picking)
    float automatic_exposure = 1.0f;
    DiffusionSolution stats;                         // phi dropped: iterations, errors, times
    double lighting_ms = 0;
    double radiance_ms = 0;
    int solve_count = 0;
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
    bool idle() const { return !load_task_.busy() && !solve_task_.busy() && !solve_pending_; }
    // Screenshot mode: blocks until the running task finishes (the frame loop then installs it).
    void wait_for_tasks();
    Image read_window() const;
    // The 3D view's pixels alone (what `waxwork render` would write for the same scene and size).
    Image read_viewport() const;
    // True while something on screen changes without input (a stroke, a drag).
    bool animating() const { return stroke_active_; }
    // The first error of a failed load or solve (screenshot mode turns it into the exit status).
    const std::string& last_error() const { return last_error_; }
    const GlApi& gl() const { return gl_; }
    const EditorScene& scene() const { return *scene_; }
    double view_ms() const { return last_render_ms_; }

    // Loads a surface (meshed with the current options) or a volume file, in the background.
    void open_file(const std::filesystem::path& path);
    void save_volume(const std::filesystem::path& path);
    void on_drop(const std::vector<std::filesystem::path>& paths);
    void on_key(int key, int mods);

private:
    using Scene = EditorScene;
    // editor_panels.cpp: the ImGui parts.
    void draw_ui();
    void draw_menu_bar();
    void draw_tool_palette();
    void draw_side_panel();
    void draw_material_panel();
    void draw_light_panel();
    void draw_solver_panel();
    void draw_view_panel();
    void draw_status_bar();
    void draw_overlays();
    void apply_theme(float scale);

    void open_dialog(FileDialog::Mode mode);
    void file_dialog_result();
    void undo();
    void redo();
    bool can_undo() const;
    bool can_redo() const;
    void set_whole_material(const TetMaterial& material, const std::string& name);
    void finish_stroke();
    void drag_light(double dx, double dy);
    void layout_viewport(int fb_w, int fb_h);
    void poll_tasks();
    void request_solve();
    void start_solve();
    void handle_viewport_input();
    void draw_viewport(int fb_h);
    void set_error(const std::string& message);

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

    // The scene: the volume, its materials and lights, the latest solved image input.
    std::unique_ptr<Scene> scene_;
    Lighting lighting_;
    DiffusionOptions diffusion_;
    float exposure_stops_ = 0;                 // added to the automatic exposure
    std::optional<OrbitCamera> camera_;
    std::filesystem::path current_file_;

    BackgroundTask load_task_;
    BackgroundTask solve_task_;
    bool solve_pending_ = false;  // inputs changed while a solve ran: solve again when it ends

    Tool tool_ = Tool::Orbit;
    int selected_light_ = 0;
    int selected_preset_ = 0;
    std::vector<std::array<float, 2>> stroke_;  // the stroke being drawn (viewport pixels)
    bool stroke_active_ = false;
    std::optional<TetMaterial> custom_material_;  // the material panel's current material
    float brush_radius_ = 0.05f;                  // paint brush sigma, fraction of the scene radius
    bool show_light_gizmos_ = true;

    // Viewport rectangle in framebuffer pixels (origin top-left) and the scale from window to
    // framebuffer coordinates (HiDPI).
    int view_x_ = 0, view_y_ = 0, view_w_ = 1, view_h_ = 1;
    double framebuffer_scale_ = 1.0;

    FileDialog file_dialog_;
    std::string status_;
    std::string last_error_;
    std::string error_message_;
    bool show_error_popup_ = false;
    double last_render_ms_ = 0;
};

}  // namespace waxwork
