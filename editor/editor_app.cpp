#include "editor/editor_app.h"
#include "io/output_folder.h"
#include "io/video_encoder.h"
#include "render/turntable.h"

#include "base/error.h"
#include "base/progress.h"
#include "base/timing.h"
#include "editor/stroke_tools.h"
#include "io/surface_reader.h"
#include "io/volume_file.h"
#include "solver/material.h"
#include "solver/mesh_resolution.h"
#include "tetops/connectivity.h"
#include "tetops/model_scale.h"
#include "tetops/tetrahedralize.h"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <numbers>
#include <sstream>
#include <thread>

namespace waxwork {

namespace fs = std::filesystem;

namespace {

std::string glfw_error_text;

void on_glfw_error(int code, const char* description) {
    glfw_error_text = description ? description : ("GLFW error " + std::to_string(code));
}

EditorApp* app_of(GLFWwindow* window) { return static_cast<EditorApp*>(glfwGetWindowUserPointer(window)); }

void* gl_proc_address(const char* name) { return reinterpret_cast<void*>(glfwGetProcAddress(name)); }

// GLFW windows: ask for 4.5 core, then 4.3 core (the renderer's minimum: its shaders are GLSL 4.30).
GLFWwindow* create_window(int width, int height, bool visible) {
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_SAMPLES, 0);  // the renderer multisamples into its own framebuffer
    glfwWindowHint(GLFW_SCALE_TO_MONITOR, GLFW_TRUE);
    glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
    for (const int minor : {5, 3}) {
        glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
        glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, minor);
        if (GLFWwindow* window = glfwCreateWindow(width, height, "Waxwork", nullptr, nullptr)) return window;
    }
    return nullptr;
}

}  // namespace

EditorApp::EditorApp(GLFWwindow* window, const EditorOptions& options)
    : window_(window), options_(options), scene_(std::make_unique<Scene>()) {
    gl_ = load_gl_api(gl_proc_address);
    renderer_ = std::make_unique<SurfaceRenderer>(gl_);
    view_cache_ = std::make_unique<ViewCache>(gl_);
    reference_ = std::make_unique<ReferenceView>(gl_);

    lighting_ = default_lighting();
    if (!options.lights.empty()) lighting_.lights = options.lights;
    live_options_.mm_per_unit = options.scale.value_or(1.0);  // until a model loads with its own
    live_options_.crease_angle_degrees = options.crease_angle_degrees;
    choose_solver(options.solver_method, options.solver_backend);
    if (options.frame_ms) {
        frame_budget_in_ms_ = true;
        frame_ms_ = static_cast<float>(*options.frame_ms);
    }
    const std::vector<std::string> presets = material_preset_names();
    selected_preset_ = static_cast<int>(std::find(presets.begin(), presets.end(), "marble") - presets.begin());
    // A brush that shows on the default marble: ketchup's red absorbs most of blue and green.
    brush_preset_ = static_cast<int>(std::find(presets.begin(), presets.end(), "ketchup") - presets.begin());
    brush_material_ = material_preset("ketchup");

    // Our callbacks go in first: ImGui's GLFW backend (install_callbacks = true) chains to them.
    glfwSetWindowUserPointer(window_, this);
    glfwSetDropCallback(window_, [](GLFWwindow* w, int count, const char** paths) {
        std::vector<fs::path> list(paths, paths + count);
        app_of(w)->on_drop(list);
    });
    glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int mods) {
        if (action == GLFW_PRESS) app_of(w)->on_key(key, mods);
    });
    glfwSetCursorPosCallback(window_, [](GLFWwindow* w, double x, double y) { app_of(w)->on_cursor(x, y); });
    glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int button, int action, int mods) {
        app_of(w)->on_mouse_button(button, action, mods);
    });
    glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double dy) { app_of(w)->on_scroll(dy); });
    // The close button asks first, as Ctrl+Q does: the window closes once request_quit agrees.
    glfwSetWindowCloseCallback(window_, [](GLFWwindow* w) {
        glfwSetWindowShouldClose(w, GLFW_FALSE);
        app_of(w)->request_quit();
    });

    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;  // a fixed layout, no imgui.ini left in the working directory
    float scale_x = 1, scale_y = 1;
    glfwGetWindowContentScale(window_, &scale_x, &scale_y);
    ui_scale_ = std::clamp(std::max(scale_x, scale_y), 1.0f, 4.0f);
    apply_theme(ui_scale_);
    ImGui_ImplGlfw_InitForOpenGL(window_, true);
    if (!ImGui_ImplOpenGL3_Init("#version 430 core")) throw Error("editor: ImGui's OpenGL 3 backend failed to start");

    state_dir_ = state_directory();
    recent_ = read_recent_files(state_dir_ / "recent.json");
    own_recovery_ = own_recovery_files(state_dir_);
    abandoned_ = abandoned_recovery_files(state_dir_);
    open_recovery_popup_ = !abandoned_.empty();

    if (!options.session.empty()) open_session(options.session);
    else if (!options.file.empty()) open_file(options.file);
    else status_ = "Open a surface (OBJ, OFF, PLY, STL) or a volume (VTU, MSH, MESH) with Ctrl+O or drop it here";
}

EditorApp::~EditorApp() {
    load_task_.cancel();
    tick_task_.cancel();
    load_task_.wait();
    tick_task_.wait();
    remove_own_recovery();  // a clean exit: nothing to recover
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    view_cache_.reset();
    renderer_.reset();
}

void EditorApp::set_error(const std::string& message) {
    if (last_error_.empty()) last_error_ = message;
    show_error(message);
}

void EditorApp::show_error(const std::string& message) {
    status_ = "Error: " + message;
    ++errors_;
    error_message_ = message;
    show_error_popup_ = true;
    close_error_popup_ = false;
    refusal_.reset();
}

const std::string& EditorApp::unanswered_refusal() const {
    static const std::string none;
    return refusal_ ? refusal_->message : none;
}

void EditorApp::load_failed(const std::exception& error) {
    // Whatever the work ended with after Cancel (CancelledError, or a mesher's own error on the way
    // out), the user asked for it to stop: nothing was installed.
    if (load_task_.cancel_requested()) {
        status_ = "Cancelled loading " + load_task_.label();
        return;
    }
    const auto* refused = dynamic_cast<const SurfaceRefusedError*>(&error);
    if (!refused || !loading_) {
        set_error(error.what());
        return;
    }
    Refusal refusal{*loading_, error.what(),
                    repair_choices(refused->defects(), refused->wrapping_would_fix(), loading_->repair)};
    if (refusal.choices.empty()) {
        set_error(refusal.message);
        return;
    }
    show_error(refusal.message);
    refusal_ = std::move(refusal);
}

bool EditorApp::cancel_loading() {
    if (!load_task_.busy()) return false;
    load_task_.cancel();
    status_ = "Cancelling loading " + load_task_.label();
    return true;
}

void EditorApp::choose_repair(const std::string& id) {
    if (!refusal_) {
        set_error("repair '" + id + "': no refused surface is waiting for a repair");
        return;
    }
    const auto& choices = refusal_->choices;
    const auto it = std::find_if(choices.begin(), choices.end(), [&](const RepairChoice& c) { return c.id == id; });
    if (it == choices.end()) {
        std::string offered;
        for (const RepairChoice& c : choices) offered += (offered.empty() ? "" : ", ") + c.id;
        set_error("repair '" + id + "' is not offered for " + refusal_->request.path.filename().string() +
                  " (offered: " + offered + ")");
        return;
    }
    const LoadRequest request = refusal_->request;
    const SurfaceRepairOptions repair = it->repair;
    refusal_.reset();
    show_error_popup_ = false;
    close_error_popup_ = true;
    open_file(request.path, request.scale, repair);
}

void EditorApp::open_file(const fs::path& path, std::optional<double> scale, std::optional<SurfaceRepairOptions> repair) {
    if (load_task_.busy()) {
        set_error("still loading " + load_task_.label() + "; try again when it finishes");
        return;
    }
    if (path.extension() == ".json") {
        open_session(path);
        return;
    }
    Session setup;
    setup.name = path.filename().string();
    (is_volume_path(path) ? setup.input.volume : setup.input.surface) = fs::absolute(path);
    setup.input.max_tets = options_.max_tets;
    setup.input.edge = options_.edge;
    setup.input.mesher = options_.mesher;
    setup.input.min_dihedral_deg = options_.min_dihedral_deg;
    setup.input.max_radius_edge_ratio = options_.max_radius_edge_ratio;
    setup.input.repair = repair ? *repair : options_.repair;
    setup.material = options_.material.value_or(material_preset("marble"));
    setup.scale = scale ? scale : options_.scale;
    setup.tolerance = live_options_.relative_tolerance;
    setup.crease_angle_degrees = live_options_.crease_angle_degrees;
    setup.lighting = lighting_;
    setup.camera = next_camera_.value_or(options_.camera);
    next_camera_.reset();
    setup.frame_iterations = frame_iterations_;
    if (frame_budget_in_ms_) setup.frame_ms = frame_ms_;
    const std::string material_name = options_.material ? "custom" : "marble (or stored)";
    status_ = "Loading " + path.string();
    loading_ = LoadRequest{path, scale, setup.input.repair};
    load_task_.start(path.filename().string(), [this, path, setup, material_name, solver = live_options_](TaskProgress& progress) {
        // The reading, repair and meshing stages report themselves, and stop at the task's Cancel.
        SessionVolume input = read_session_input(setup, &progress);
        const LoadedModel model = measure_loaded_model(input);
        Session resolved = setup;
        resolved.scale = input.scale.mm_per_unit;
        progress.throw_if_cancelled();
        progress.set_stage("building the document and the live scene");
        auto core = std::make_shared<SceneCore>(std::move(input.mesh), resolved, solver);
        return BackgroundTask::Apply([this, path, core, material_name, model] {
            // Cancel pressed after the work's last check: the open document stays.
            if (load_task_.cancel_requested()) throw CancelledError("cancelled");
            install_core(core, path, material_name, {}, model);
        });
    });
}

void EditorApp::open_session(const fs::path& path) {
    status_ = "Loading session " + path.string();
    loading_.reset();
    load_task_.start(path.filename().string(), [this, path, solver = live_options_](TaskProgress& progress) {
        progress.set_stage("reading the session");
        Session session = read_session(path);
        SessionVolume input = load_session_input(session, &progress);
        const LoadedModel model = measure_loaded_model(input);
        // Edits are replayed (and become undoable); the last light and camera steps set the scene's.
        std::vector<EditOperation> edits;
        for (const SessionStep& step : session.steps) {
            if (const auto* op = std::get_if<EditOperation>(&step)) edits.push_back(*op);
            if (const auto* light = std::get_if<LightStep>(&step)) session.lighting = light->lighting;
            if (const auto* camera = std::get_if<CameraStep>(&step)) session.camera = camera->camera;
        }
        Session setup = session;
        setup.steps.clear();
        setup.scale = input.scale.mm_per_unit;
        progress.throw_if_cancelled();
        progress.set_stage("building the document and the live scene");
        auto core = std::make_shared<SceneCore>(std::move(input.mesh), setup, solver);
        return BackgroundTask::Apply([this, path, core, edits, model] {
            if (load_task_.cancel_requested()) throw CancelledError("cancelled");
            install_core(core, path, "session", edits, model);
            adopt_frame_budget(core->setup());
        });
    });
}

EditorApp::LoadedModel EditorApp::measure_loaded_model(const SessionVolume& input) {
    return {describe_model_scale(input.scale, bounding_extent(input.mesh.positions)),
            mean_surface_edge_length(input.mesh)};
}

void EditorApp::install_core(std::shared_ptr<SceneCore> core, const fs::path& path, const std::string& material_name,
                             const std::vector<EditOperation>& replay, const LoadedModel& model) {
    pending_jobs_.clear();
    reference_snapshot_.reset();
    reference_->clear();
    snapshots_.clear();
    scene_ = std::make_unique<Scene>();
    scene_->core = core;
    scene_->tets = core->document().mesh().tet_count();
    scene_->vertices = core->document().mesh().vertex_count();
    scene_->material_name = material_name;
    lighting_ = core->setup().lighting;
    live_options_.mm_per_unit = *core->setup().scale;
    scene_->extent = bounding_extent(core->document().mesh().positions);
    scene_->surface_edge = model.surface_edge;
    scene_->setup_material = core->setup().material;
    scene_->source_surface = core->setup().input.surface;
    scene_->source_repair = core->setup().input.repair;
    live_options_.relative_tolerance = core->setup().tolerance;
    live_options_.crease_angle_degrees = core->setup().crease_angle_degrees;
    options_.camera = core->setup().camera;
    camera_.reset();
    current_file_ = path;
    for (const EditOperation& op : replay) queue_edit(op);
    status_ = "Loaded " + path.filename().string() + ": " + std::to_string(scene_->tets) + " tets, " +
              std::to_string(scene_->vertices) + " vertices; " + model.scale_note;
    lighting_dirty_ = false;
    document_opened(path);
    crease_angle_dirty_ = false;
}

void EditorApp::queue_job(std::string label, SceneJob job) {
    if (!scene_->core) {
        set_error("open a file first");
        return;
    }
    pending_jobs_.emplace_back(std::move(label), std::move(job));
}

void EditorApp::queue_edit(const EditOperation& op) {
    if (scene_->core) mark_modified();
    queue_job(operation_name(op), [op](SceneCore& core) {
        const ChangeReport report = core.apply(op);
        std::ostringstream line;
        line << report.name << ": " << report.details << " (" << std::lround(report.milliseconds) << " ms)";
        if (!report.undoable) line << "; too large to undo";
        return line.str();
    });
}

void EditorApp::save_volume(const fs::path& path) {
    if (!scene_->core) return set_error("open a file first");
    mark_saved(path);
    queue_job("save", [path](SceneCore& core) {
        core.save_volume(path);
        return "Saved " + path.string();
    });
    current_file_ = path;
}

void EditorApp::export_surface(const fs::path& path) {
    if (scene_->core) remember_output(path, false);
    queue_job("export", [path](SceneCore& core) {
        // Pieces apart: what Blender's and a slicer's users expect of a fractured model.
        const bool coloured = core.export_surface(path, ShellGrouping::Separate);
        return "Exported the surface" + std::string(coloured ? " with its light" : "") + " to " + path.string();
    });
}

CameraSettings EditorApp::recorded_camera() const {
    if (!camera_) return options_.camera;
    const double aspect = static_cast<double>(view_w_) / std::max(view_h_, 1);
    Eigen::AlignedBox3d box;
    if (scene_->render_input)
        for (const Eigen::Vector3f& p : scene_->render_input->positions) box.extend(p.cast<double>());
    return camera_->settings(aspect, box);
}

double EditorApp::shown_exposure() const { return scene_->automatic_exposure * std::exp2(exposure_stops_); }

void EditorApp::snapshot() {
    if (!scene_->core || !camera_) {
        set_error("open a file first");
        return;
    }
    snapshots_.push_back({scene_->history_size, recorded_camera(), lighting_, shown_exposure()});
    status_ = "Snapshot " + std::to_string(snapshots_.size()) +
              " recorded: a session saved now renders this view at this point of the edits";
}

void EditorApp::render_reference() {
    if (!scene_->core || !camera_) {
        set_error("open a file first");
        return;
    }
    if (reference_->busy() || reference_snapshot_) {
        status_ = "A reference is being traced already (Cancel it in the Reference window)";
        return;
    }
    // The view as it is now, at the size the Reference window asks for.
    const std::array<int, 2> size = reference_->image_size(view_w_, view_h_);
    const CameraFrame frame = camera_->frame(static_cast<double>(view_w_) / std::max(view_h_, 1));
    reference_camera_ = pixel_camera(frame.eye, frame.view, frame.projection, size[0], size[1]);
    auto snapshot = std::make_shared<ReferenceSnapshot>();
    reference_snapshot_ = snapshot;
    reference_->show();
    queue_job("reference", [snapshot](SceneCore& core) {
        snapshot->taken = true;
        snapshot->scene = std::make_shared<const ReferenceScene>(snapshot_reference_scene(core));
        return std::string("Tracing the reference of the view");
    });
}

void EditorApp::render_reference_with(std::optional<double> seconds, std::optional<double> noise_percent,
                                      std::optional<int> size_divisor) {
    ReferenceView::Settings& settings = reference_->settings();
    if (seconds) settings.seconds = static_cast<float>(*seconds);
    if (noise_percent) settings.target_error_percent = static_cast<float>(*noise_percent);
    if (size_divisor) {
        const auto& divisors = ReferenceView::kSizeDivisors;
        const auto it = std::find(divisors.begin(), divisors.end(), *size_divisor);
        if (it != divisors.end()) settings.size = static_cast<int>(it - divisors.begin());
    }
    render_reference();
}

bool EditorApp::cancel_reference() {
    if (!reference_->busy()) return false;
    reference_->cancel();
    return true;
}

void EditorApp::save_reference(const fs::path& path) {
    try {
        reference_->save(path);
        remember_output(path, false);
        status_ = "Saved the reference comparison to " + path.string();
    } catch (const std::exception& e) {
        set_error(e.what());
    }
}

void EditorApp::save_image(const fs::path& path) {
    if (!is_image_extension(path)) {
        set_error("save image: " + path.string() + ": the image must be .png, .jpg or .jpeg");
        return;
    }
    image_to_save_ = path;
}

void EditorApp::export_turntable(const fs::path& video, int frames) {
    if (!scene_->render_input || !camera_) return set_error("export turntable: nothing is shown yet");
    if (turntable_ || video_task_.busy()) return set_error("export turntable: a turntable is being exported already");
    if (frames < 1 || frames > 100000) return set_error("export turntable: the frame count must be between 1 and 100000");
    TurntableExport t;
    t.video = video;
    t.folder = video.parent_path() / video.stem();
    std::error_code error;
    fs::create_directories(t.folder, error);
    if (error || !fs::is_directory(t.folder))
        return set_error("export turntable: " + t.folder.string() + ": cannot create the folder" +
                         (error ? " (" + error.message() + ")" : ""));
    t.frames = frames;
    t.start = recorded_camera();
    t.input = *scene_->render_input;
    t.input.width = view_w_;
    t.input.height = view_h_;
    t.input.samples = msaa_samples_;
    t.input.exposure = static_cast<float>(shown_exposure());  // one exposure for all: no flicker
    t.input.ground = ground_plane_;
    turntable_ = std::move(t);
}

void EditorApp::set_background(const std::string& background) {
    const ImageBackground parsed = background == "automatic" ? ImageBackground{} : parse_background(background);
    if (parsed.kind == BackgroundKind::Transparent)
        throw InvalidArgumentError("background: a window cannot show a transparent background");
    background_ = parsed;
    view_cache_->invalidate();
}

void EditorApp::advance_turntable() {
    TurntableExport& t = *turntable_;
    try {
        t.input.camera = orbit_camera(t.start, t.next, t.frames);
        write_png(render_scene(*renderer_, t.input), contained_output_path(t.folder, turntable_frame_name(t.next)));
    } catch (const std::exception& e) {
        turntable_.reset();
        return set_error(std::string("export turntable: ") + e.what());
    }
    status_ = "Turntable: frame " + std::to_string(t.next + 1) + " of " + std::to_string(t.frames) + " (Esc stops)";
    if (++t.next < t.frames) return;
    const fs::path folder = t.folder, video = t.video;
    const int frames = t.frames;
    turntable_.reset();
    const std::string ffmpeg = find_on_path("ffmpeg");
    if (ffmpeg.empty()) {
        status_ = "Turntable: " + std::to_string(frames) + " frames in " + folder.string() +
                  " (ffmpeg is not on the PATH: no video; install ffmpeg for one)";
        return;
    }
    video_task_.start("video", [this, ffmpeg, folder, video, frames](TaskProgress& progress) {
        progress.set_stage("encoding " + video.string());
        const bool ok = encode_mp4(ffmpeg, folder, video, frames / kDefaultSecondsPerTurn);
        return BackgroundTask::Apply([this, ok, video, folder] {
            status_ = ok ? "Turntable: " + video.string() + " and its frames in " + folder.string()
                         : "Turntable: ffmpeg failed; the frames are in " + folder.string();
        });
    });
}

void EditorApp::write_saved_image() {
    const fs::path path = *image_to_save_;
    image_to_save_.reset();
    if (!scene_->render_input) {
        set_error("save image: nothing is shown yet");
        return;
    }
    try {
        write_image(read_viewport(), path);
        status_ = "Saved the view to " + path.string();
    } catch (const std::exception& e) {
        set_error(e.what());
    }
}

Session EditorApp::view_session() const {
    // The view and lights as they are now, not as the session started.
    Session current;
    current.lighting = lighting_;
    current.camera = recorded_camera();
    current.width = view_w_;
    current.height = view_h_;
    current.frame_iterations = frame_iterations_;  // the budget as the panel has it now
    if (frame_budget_in_ms_) current.frame_ms = frame_ms_;
    current.crease_angle_degrees = live_options_.crease_angle_degrees;
    return current;
}

Session EditorApp::with_view(Session setup, const Session& view) {
    setup.frame_iterations = view.frame_iterations;
    setup.frame_ms = view.frame_ms;
    setup.crease_angle_degrees = view.crease_angle_degrees;
    setup.lighting = view.lighting;
    setup.camera = view.camera;
    setup.width = view.width;
    setup.height = view.height;
    return setup;
}

void EditorApp::save_session(const fs::path& path) {
    if (!scene_->core) return set_error("open a file first");
    const Session current = view_session();
    mark_saved(path);
    const double exposure = shown_exposure();
    queue_job("save session", [path, current, snapshots = snapshots_, exposure](SceneCore& core) {
        core.save_session(path, with_view(core.setup(), current), snapshots, exposure);
        return "Saved the session (" + std::to_string(core.document().history().size()) + " edits, " +
               std::to_string(snapshots.size()) + " snapshots) to " + path.string();
    });
}

void EditorApp::rebuild_live_scene() {
    const LiveSceneOptions options = live_options_;
    queue_job("solver settings", [options](SceneCore& core) {
        core.set_solver_options(options);
        return std::string("Solver settings changed: solving again");
    });
    if (scene_->core) scene_->exposure_locked = false;
}

void EditorApp::on_drop(const std::vector<fs::path>& paths) {
    if (!paths.empty()) request_open(paths.front());
}

void EditorApp::on_key(int key, int mods) {
    // Letters typed into a text field are text, not shortcuts.
    if (ImGui::GetCurrentContext() && ImGui::GetIO().WantTextInput) return;
    const bool ctrl = (mods & GLFW_MOD_CONTROL) != 0;
    const bool shift = (mods & GLFW_MOD_SHIFT) != 0;
    if (ctrl) {
        switch (key) {
        case GLFW_KEY_O: open_dialog(FileDialog::Mode::Open); break;
        case GLFW_KEY_S: open_dialog(FileDialog::Mode::Save); break;
        case GLFW_KEY_Z: shift ? redo() : undo(); break;
        case GLFW_KEY_Y: redo(); break;
        case GLFW_KEY_Q: request_quit(); break;
        default: break;
        }
        return;
    }
    switch (key) {
    case GLFW_KEY_ESCAPE: {
        if (turntable_) {
            status_ = "Turntable stopped after " + std::to_string(turntable_->next) + " frames in " +
                      turntable_->folder.string();
            turntable_.reset();
            break;
        }
        const bool deforming = tools_.active() && is_deform_tool(tools_.tool());
        if (!tools_.cancel(viewport_context())) select_tool(Tool::Orbit);
        else if (deforming) queue_cancel_deform();
        break;
    }
    case GLFW_KEY_C: select_tool(Tool::Cut); break;
    case GLFW_KEY_X: select_tool(Tool::RemoveCut); break;
    case GLFW_KEY_R: select_tool(Tool::Relax); break;
    case GLFW_KEY_F: select_tool(Tool::Fracture); break;
    case GLFW_KEY_D: remove_fragments(); break;
    case GLFW_KEY_M: select_tool(Tool::MovePiece); break;
    case GLFW_KEY_P: select_tool(Tool::Paint); break;
    case GLFW_KEY_L: select_tool(Tool::Light); break;
    case GLFW_KEY_G: select_tool(Tool::Grab); break;
    case GLFW_KEY_B: select_tool(Tool::Bend); break;
    case GLFW_KEY_T: select_tool(Tool::Twist); break;
    case GLFW_KEY_N: select_tool(Tool::Pin); break;
    case GLFW_KEY_HOME: camera_.reset(); break;
    case GLFW_KEY_TAB: options_.hide_ui = !options_.hide_ui; break;
    default: break;
    }
}

void EditorApp::request_solve() {
    if (scene_->core) lighting_dirty_ = true;
}

void EditorApp::set_crease_angle(double degrees) {
    if (!is_crease_angle(degrees))
        throw InvalidArgumentError("crease angle " + number_text(degrees) + " degrees: must be between 0 and 180");
    live_options_.crease_angle_degrees = degrees;
    if (scene_->core) crease_angle_dirty_ = true;
}

bool EditorApp::idle() const {
    if (load_task_.busy() || tick_task_.busy() || !pending_jobs_.empty() || lighting_dirty_ || crease_angle_dirty_ ||
        turntable_ || video_task_.busy() ||
        reference_->busy() || reference_snapshot_)
        return false;
    return !scene_->core || (scene_->converged && scene_->render_input && scene_->exposure_locked && !view_dirty_);
}

void EditorApp::start_tick() {
    // What this tick does, handed over whole: the UI thread queues the next batch meanwhile.
    std::shared_ptr<SceneCore> core = scene_->core;
    auto request = std::make_shared<SceneTickRequest>();
    request->jobs.assign(std::make_move_iterator(pending_jobs_.begin()), std::make_move_iterator(pending_jobs_.end()));
    pending_jobs_.clear();
    if (lighting_dirty_) request->lighting = lighting_;
    lighting_dirty_ = false;
    if (crease_angle_dirty_) request->crease_angle = live_options_.crease_angle_degrees;  // checked by set_crease_angle
    crease_angle_dirty_ = false;
    request->budget = frame_budget();
    request->first = !scene_->render_input;
    request->need_bvh = !scene_->surface_bvh;
    ImageSettings& settings = request->image;
    settings.width = std::max(view_w_, 1);
    settings.height = std::max(view_h_, 1);
    if (camera_) {
        settings.camera.eye_direction = camera_->eye_direction();
        settings.camera.up = camera_->up();
    } else {
        settings.camera = options_.camera;
    }
    request->view = view_options_;
    request->view_changed = view_dirty_;
    view_dirty_ = false;
    const std::string label = request->jobs.empty() ? "solve" : request->jobs.front().first;
    Scene* target = scene_.get();

    tick_task_.start(label, [this, target, core, request](TaskProgress& progress) {
        auto r = std::make_shared<SceneTickResult>(
            core->tick(*request, [&progress](const std::string& stage) { progress.set_stage(stage); }));
        return BackgroundTask::Apply([this, target, r, request] {
            if (scene_.get() != target) return;  // another file was opened meanwhile
            Scene& s = *scene_;
            if (r->history != s.history_size || r->can_undo != s.can_undo || r->can_redo != s.can_redo ||
                request->lighting || request->crease_angle)
                ++s.light_version;
            // A snapshot of a state an undo went back past shows what no longer exists.
            std::erase_if(snapshots_, [&](const SessionSnapshot& shot) { return shot.history > r->history; });
            for (const std::string& m : r->messages) status_ = m;
            for (const std::string& e : r->errors) set_error(e);
            if (r->input) {
                if (!s.exposure_locked) s.automatic_exposure = r->input->exposure;
                s.render_input = std::move(r->input);
                view_geometry_ = r->view;
                ++scene_version_;
            }
            if (r->bvh) {
                s.surface_bvh = r->bvh;
                s.surface_piece = std::move(r->surface_piece);
            }
            s.piece_transforms = std::move(r->piece_transforms);
            s.last_frame = r->frame;
            s.converged = r->converged;
            s.estimated_error = r->estimated_error;
            if (s.converged && s.render_input) s.exposure_locked = true;
            s.can_undo = r->can_undo;
            s.can_redo = r->can_redo;
            s.history_size = r->history;
            s.tets = r->tets;
            s.vertices = r->vertices;
            s.min_dihedral_deg = r->min_dihedral;
            if (r->trust_warning) s.trust_warning = *r->trust_warning;
            s.solver_backend = r->backend;
            s.solver_description = r->solver_description;
            s.gpu_fallback_reason = r->gpu_fallback_reason;
            s.method_fallback_reason = r->method_fallback_reason;
            s.tick_ms = r->milliseconds;
            if (reference_->busy()) {
                s.tick_ms_sum_while_tracing += r->milliseconds;
                ++s.ticks_while_tracing;
            }
            if (!s.converged || r->frame.total_iterations() > 0) {
                s.tick_ms_sum += r->milliseconds;
                ++s.ticks;
            }
        });
    });
}

void EditorApp::poll_tasks() {
    try {
        load_task_.poll();
    } catch (const std::exception& e) {
        load_failed(e);
    }
    try {
        tick_task_.poll();
    } catch (const std::exception& e) {
        set_error(std::string("solver: ") + e.what());
        scene_->converged = true;  // do not retry a failing step every frame
        scene_->exposure_locked = true;
    }
    // The snapshot a tick took for Render reference: the trace starts from it, tagged with the light
    // it shows.
    if (reference_snapshot_ && !tick_task_.busy() && reference_snapshot_->taken) {
        // A snapshot that threw was reported by its tick; there is nothing to trace then.
        if (reference_snapshot_->scene)
            reference_->start(std::move(reference_snapshot_->scene), reference_camera_, scene_->light_version);
        reference_snapshot_.reset();
    }
    if (const std::optional<std::string> ended = reference_->poll()) status_ = *ended;
    try {
        video_task_.poll();
    } catch (const std::exception& e) {
        set_error(std::string("export turntable: ") + e.what());
    }
    // Keep one tick running while there is anything to do.
    if (scene_->core && !tick_task_.busy() && !load_task_.busy() &&
        (!pending_jobs_.empty() || lighting_dirty_ || crease_angle_dirty_ || !scene_->converged ||
         !scene_->render_input || view_dirty_))
        start_tick();
}

void EditorApp::wait_for_tasks() {
    load_task_.wait();
    tick_task_.wait();
}

void EditorApp::frame() {
    int fb_w = 0, fb_h = 0, win_w = 0, win_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    glfwGetWindowSize(window_, &win_w, &win_h);
    framebuffer_scale_ = win_w > 0 ? static_cast<double>(fb_w) / win_w : 1.0;

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    layout_viewport(fb_w, fb_h);
    poll_tasks();  // after the layout: a solve started now exposes for the current viewport
    document_frame();
    if (!options_.hide_ui) draw_ui();
    draw_document_dialogs();  // with the panels hidden too: a quit must still ask
    file_dialog_result();
    handle_viewport_input();
    if (!options_.hide_ui) draw_overlays();
    ImGui::Render();

    gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl_.Viewport(0, 0, fb_w, fb_h);
    gl_.ClearColor(0.09f, 0.09f, 0.11f, 1.0f);
    gl_.Clear(GL_COLOR_BUFFER_BIT);
    draw_viewport(fb_h);
    if (image_to_save_) write_saved_image();  // the view alone, before the panels are drawn over it
    if (turntable_) {
        advance_turntable();  // draws offscreen: the window's framebuffer is bound again below
        gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
        gl_.Viewport(0, 0, fb_w, fb_h);
    }
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

void EditorApp::layout_viewport(int fb_w, int fb_h) {
    if (options_.hide_ui) {
        view_x_ = 0;
        view_y_ = 0;
        view_w_ = fb_w;
        view_h_ = fb_h;
        return;
    }
    // ImGui works in window coordinates; the viewport in framebuffer pixels.
    const double s = framebuffer_scale_;
    const double top = ImGui::GetFrameHeight();            // main menu bar
    const double bottom = ImGui::GetFrameHeight() * 1.2;   // status bar
    const double left = kToolPaletteWidth * ui_scale_;
    const double right = kSidePanelWidth * ui_scale_;
    view_x_ = static_cast<int>(std::lround(left * s));
    view_y_ = static_cast<int>(std::lround(top * s));
    view_w_ = std::max(1, fb_w - view_x_ - static_cast<int>(std::lround(right * s)));
    view_h_ = std::max(1, fb_h - view_y_ - static_cast<int>(std::lround(bottom * s)));
}

void EditorApp::draw_viewport(int fb_h) {
    if (!scene_->render_input) return;
    SurfaceRenderInput& input = *scene_->render_input;
    if (!camera_) {
        // The first frame of a scene uses `waxwork render`'s framing of the same surface.
        Eigen::AlignedBox3d box;
        for (const Eigen::Vector3f& p : input.positions) box.extend(p.cast<double>());
        if (box.isEmpty()) return;
        camera_.emplace(box, options_.camera, static_cast<double>(view_w_) / view_h_);
    }
    input.width = view_w_;
    input.height = view_h_;
    input.samples = msaa_samples_;
    input.exposure = scene_->automatic_exposure * std::exp2(exposure_stops_);
    input.ground = ground_plane_;
    // An environment background with no environment lighting the scene falls back to the automatic one.
    ImageBackground background = background_;
    if (background.kind == BackgroundKind::Environment && !lighting_.environment) background.kind = BackgroundKind::Automatic;
    apply_background(background, input);
    const CameraFrame frame = camera_->frame(static_cast<double>(view_w_) / view_h_);
    const ViewKey key{frame.view, frame.projection, view_w_, view_h_, input.samples, input.exposure, scene_version_};
    const int y = fb_h - view_y_ - view_h_;
    if (!view_cache_->holds(key)) {
        const auto start = std::chrono::steady_clock::now();
        try {
            if (shown_preview_) renderer_->draw(with_piece_preview(input), frame, view_cache_->begin_update(key), 0, 0);
            else renderer_->draw(input, frame, view_cache_->begin_update(key), 0, 0);
        } catch (const std::exception& e) {
            view_cache_->invalidate();
            scene_->render_input.reset();
            set_error(std::string("drawing: ") + e.what());
            return;
        }
        last_render_ms_ = milliseconds_since(start);
    }
    view_cache_->blit(0, view_x_, y);
}

bool EditorApp::can_undo() const { return scene_->can_undo || !pending_jobs_.empty(); }
bool EditorApp::can_redo() const { return scene_->can_redo; }

void EditorApp::undo() { queue_history_step(false); }
void EditorApp::redo() { queue_history_step(true); }

void EditorApp::remove_fragments() {
    queue_edit(RemoveFragmentsOp{static_cast<double>(fragment_percent_) / 100.0});
}

void EditorApp::queue_history_step(bool redo) {
    if (scene_->core) mark_modified();
    queue_job(redo ? "redo" : "undo", [redo](SceneCore& core) {
        const auto report = redo ? core.redo() : core.undo();
        if (!report) return std::string(redo ? "Nothing to redo" : "Nothing to undo");
        return report->name;
    });
}

void EditorApp::set_whole_material(const TetMaterial& material, const std::string& name) {
    queue_edit(SetMaterialOp{material, std::nullopt});
    scene_->material_name = name;
}

void EditorApp::relax_last_cut() {
    if (!last_cut_) {
        set_error("relax: cut first (C), then relax its cross-section");
        return;
    }
    RelaxOp op;
    op.surface = *last_cut_;
    queue_edit(op);
}

Image EditorApp::read_window() const {
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    return read_framebuffer(gl_, fb_w, fb_h);
}

Image EditorApp::read_viewport() const {
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    const Image window = read_window();
    Image view;
    view.width = view_w_;
    view.height = view_h_;
    view.rgba.resize(4 * static_cast<size_t>(view_w_) * view_h_);
    for (int y = 0; y < view_h_; ++y) {
        for (int x = 0; x < view_w_; ++x) {
            const uint8_t* from = window.pixel(view_x_ + x, view_y_ + y);
            std::copy(from, from + 4, view.pixel(x, y));
        }
    }
    return view;
}

bool display_available() {
    const char* display = std::getenv("DISPLAY");
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if ((!display || !*display) && (!wayland || !*wayland)) return false;
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit()) return false;
    GLFWwindow* probe = create_window(64, 64, false);
    const bool ok = probe != nullptr;
    if (probe) glfwDestroyWindow(probe);
    glfwTerminate();
    return ok;
}

bool try_open_editor(const EditorOptions& options) {
    if (!display_available()) return false;
    run_editor(options);
    return true;
}

EditorRunStats run_editor(const EditorOptions& options) {
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit()) throw Error("editor: cannot open a window (" + glfw_error_text + "); is DISPLAY set?");
    struct Terminate {
        ~Terminate() { glfwTerminate(); }
    } terminate;
    GLFWwindow* window = create_window(options.width, options.height, true);
    if (!window) throw Error("editor: cannot create an OpenGL 4.3+ core window: " + glfw_error_text);
    glfwMakeContextCurrent(window);
    const bool screenshot = !options.screenshot.empty();
    glfwSwapInterval(screenshot ? 0 : 1);

    EditorRunStats stats;
    {
        EditorApp app(window, options);
        std::optional<InputScriptPlayer> player;
        std::unique_ptr<ScriptTarget> script_target;
        if (options.input) {
            player.emplace(*options.input);
            script_target = make_window_script_target(window, app);
        }
        const auto script_running = [&] { return player && !player->done(); };
        stats.gl_version = reinterpret_cast<const char*>(app.gl().GetString(GL_VERSION));
        stats.gl_renderer = reinterpret_cast<const char*>(app.gl().GetString(GL_RENDERER));
        double frame_ms_sum = 0, view_ms_sum = 0, tracing_frame_ms_sum = 0, script_frame_ms_sum = 0;
        while (!glfwWindowShouldClose(window)) {
            if (screenshot || !app.idle() || app.animating() || script_running()) glfwPollEvents();
            else glfwWaitEventsTimeout(0.5);  // nothing moves: sleep until input arrives
            const auto start = std::chrono::steady_clock::now();
            if (player) player->advance(*script_target);
            const bool tracing = app.reference().busy(), scripted = script_running();
            app.frame();
            if (tracing || scripted) {
                app.gl().Finish();  // the frame's GPU work counts too
                const double ms = milliseconds_since(start);
                if (tracing) {
                    ++stats.frames_while_tracing;
                    tracing_frame_ms_sum += ms;
                    stats.max_frame_ms_while_tracing = std::max(stats.max_frame_ms_while_tracing, ms);
                }
                if (scripted) {
                    ++stats.script_frames;
                    script_frame_ms_sum += ms;
                    stats.max_script_frame_ms = std::max(stats.max_script_frame_ms, ms);
                }
            }
            if (screenshot) {
                if (!app.last_error().empty()) throw Error(app.last_error());
            // A refused surface's dialog waits for a repair the script may still choose.
            if (!app.unanswered_refusal().empty() && !script_running()) throw Error(app.unanswered_refusal());
                if (!app.idle() || script_running()) {
                    stats.frames = 0;
                    frame_ms_sum = view_ms_sum = 0;
                    // Not interactive: no point drawing hundreds of progress frames meanwhile.
                    std::this_thread::sleep_for(std::chrono::milliseconds(20));
                } else {
                    app.gl().Finish();  // count the GPU's work in the frame time
                    frame_ms_sum += milliseconds_since(start);
                    view_ms_sum += app.view_ms();
                    if (++stats.frames >= std::max(options.frames, 1)) {
                        write_png(app.read_window(), options.screenshot);
                        break;
                    }
                }
            }
            glfwSwapBuffers(window);
        }
        stats.mean_frame_ms = stats.frames ? frame_ms_sum / stats.frames : 0;
        stats.mean_view_ms = stats.frames ? view_ms_sum / stats.frames : 0;
        if (stats.frames_while_tracing) stats.mean_frame_ms_while_tracing = tracing_frame_ms_sum / stats.frames_while_tracing;
        if (stats.script_frames) stats.mean_script_frame_ms = script_frame_ms_sum / stats.script_frames;
        const EditorScene& scene = app.scene();
        stats.tets = scene.tets;
        stats.vertices = scene.vertices;
        stats.mm_per_unit = app.mm_per_unit();
        stats.ticks = scene.ticks;
        stats.tick_ms = scene.ticks ? scene.tick_ms_sum / scene.ticks : 0;
        stats.tick_ms_while_tracing = scene.ticks_while_tracing ? scene.tick_ms_sum_while_tracing / scene.ticks_while_tracing : 0;
        stats.solver_backend = live_backend_name(scene.solver_backend);
        stats.gpu_fallback_reason = scene.gpu_fallback_reason;
        stats.method_fallback_reason = scene.method_fallback_reason;
        stats.view_reads_device_radiance = scene.render_input && scene.render_input->device_radiance;
        stats.modified = app.modified();
        stats.title = app.title();
    }
    glfwDestroyWindow(window);
    return stats;
}

}  // namespace waxwork
