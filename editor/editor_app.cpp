#include "editor/editor_app.h"

#include "io/surface_reader.h"
#include "io/volume_file.h"
#include "solver/material.h"
#include "solver/mesh_resolution.h"
#include "tetops/connectivity.h"
#include "tetops/error.h"
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
#include <thread>

namespace waxwork {

namespace fs = std::filesystem;

namespace {

std::string glfw_error_text;

void on_glfw_error(int code, const char* description) {
    glfw_error_text = description ? description : ("GLFW error " + std::to_string(code));
}

double ms_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

bool is_volume_file(const fs::path& path) {
    std::string e = path.extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return e == ".vtu" || e == ".msh" || e == ".mesh" || e == ".node" || e == ".ele";
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

const std::vector<ToolInfo>& tool_infos() {
    static const std::vector<ToolInfo> tools = {
        {Tool::Orbit, "Orbit", "Esc"},        {Tool::Cut, "Cut", "C"},
        {Tool::ExactCut, "Exact cut", "X"},   {Tool::Relax, "Relax", "R"},
        {Tool::Fracture, "Fracture", "F"},    {Tool::MovePiece, "Move piece", "M"},
        {Tool::Paint, "Paint", "P"},          {Tool::Light, "Light", "L"},
    };
    return tools;
}

EditorApp::EditorApp(GLFWwindow* window, const EditorOptions& options)
    : window_(window), options_(options), scene_(std::make_unique<Scene>()) {
    gl_ = load_gl_api(gl_proc_address);
    renderer_ = std::make_unique<SurfaceRenderer>(gl_);
    view_cache_ = std::make_unique<ViewCache>(gl_);

    lighting_.lights = options.lights.empty() ? std::vector<Light>{default_key_light()} : options.lights;
    lighting_.ambient = {0.02, 0.02, 0.02};  // `waxwork render`'s default --ambient
    diffusion_.mm_per_unit = options.scale;
    const std::vector<std::string> presets = material_preset_names();
    selected_preset_ = static_cast<int>(std::find(presets.begin(), presets.end(), "marble") - presets.begin());

    // Our callbacks go in first: ImGui's GLFW backend (install_callbacks = true) chains to them.
    glfwSetWindowUserPointer(window_, this);
    glfwSetDropCallback(window_, [](GLFWwindow* w, int count, const char** paths) {
        std::vector<fs::path> list(paths, paths + count);
        app_of(w)->on_drop(list);
    });
    glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int mods) {
        if (action == GLFW_PRESS) app_of(w)->on_key(key, mods);
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

    if (!options.file.empty()) open_file(options.file);
    else status_ = "Open a surface (OBJ, OFF, PLY, STL) or a volume (VTU, MSH, MESH) with Ctrl+O or drop it here";
}

EditorApp::~EditorApp() {
    load_task_.cancel();
    solve_task_.cancel();
    load_task_.wait();
    solve_task_.wait();
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    view_cache_.reset();
    renderer_.reset();
}

void EditorApp::set_error(const std::string& message) {
    if (last_error_.empty()) last_error_ = message;
    status_ = "Error: " + message;
    error_message_ = message;
    show_error_popup_ = true;
}

void EditorApp::open_file(const fs::path& path) {
    if (load_task_.busy()) {
        set_error("still loading " + load_task_.label() + "; try again when it finishes");
        return;
    }
    const std::optional<size_t> max_tets = options_.max_tets;
    const std::optional<TetMaterial> chosen = options_.material;
    const double mm_per_unit = diffusion_.mm_per_unit;
    status_ = "Loading " + path.string();
    load_task_.start(path.filename().string(), [this, path, max_tets, chosen, mm_per_unit](TaskProgress& progress) {
        auto mesh = std::make_shared<TetMesh>();
        if (is_volume_file(path)) {
            progress.set_stage("reading the volume");
            *mesh = read_volume(path);
        } else {
            progress.set_stage("reading and checking the surface");
            const LoadedSurface loaded = load_closed_surface(path);
            progress.set_stage("filling it with tetrahedra");
            MeshingOptions meshing;
            if (max_tets) meshing.sizing.target_tets = max_tets;
            else meshing.sizing = default_mesh_sizing(loaded.surface, chosen.value_or(material_preset("marble")), mm_per_unit);
            *mesh = tetrahedralize(loaded.surface, meshing).mesh;
        }
        if (mesh->tet_count() == 0) throw InvalidArgumentError(path.string() + ": the volume has no tets");
        progress.set_stage("connectivity");
        auto connectivity = std::make_shared<TetConnectivity>(build_connectivity(*mesh));
        std::vector<TetMaterial> materials = resolve_materials(*mesh, chosen);
        const std::string material_name = chosen ? "custom" : mesh->has_materials() ? "stored" : "marble";
        // Installed on the UI thread.
        return [this, path, mesh, connectivity, materials = std::move(materials), material_name]() mutable {
            scene_ = std::make_unique<Scene>();
            scene_->mesh = mesh;
            scene_->connectivity = connectivity;
            scene_->materials = std::move(materials);
            scene_->material_name = material_name;
            camera_.reset();
            current_file_ = path;
            status_ = "Loaded " + path.filename().string() + ": " + std::to_string(mesh->tet_count()) + " tets, " +
                      std::to_string(mesh->vertex_count()) + " vertices";
            glfwSetWindowTitle(window_, ("Waxwork - " + path.filename().string()).c_str());
            request_solve();
        };
    });
}

void EditorApp::save_volume(const fs::path& path) {
    if (!scene_->mesh) {
        set_error("nothing to save: open a file first");
        return;
    }
    try {
        TetMesh copy = *scene_->mesh;
        copy.materials = scene_->materials;
        write_volume(copy, path);
        current_file_ = path;
        status_ = "Saved " + path.string();
    } catch (const std::exception& e) {
        set_error(e.what());
    }
}

void EditorApp::on_drop(const std::vector<fs::path>& paths) {
    if (!paths.empty()) open_file(paths.front());
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
        case GLFW_KEY_Q: glfwSetWindowShouldClose(window_, GLFW_TRUE); break;
        default: break;
        }
        return;
    }
    switch (key) {
    case GLFW_KEY_ESCAPE: tool_ = Tool::Orbit; stroke_.clear(); break;
    case GLFW_KEY_C: tool_ = Tool::Cut; break;
    case GLFW_KEY_X: tool_ = Tool::ExactCut; break;
    case GLFW_KEY_R: tool_ = Tool::Relax; break;
    case GLFW_KEY_F: tool_ = Tool::Fracture; break;
    case GLFW_KEY_M: tool_ = Tool::MovePiece; break;
    case GLFW_KEY_P: tool_ = Tool::Paint; break;
    case GLFW_KEY_L: tool_ = Tool::Light; break;
    case GLFW_KEY_HOME: camera_.reset(); break;
    case GLFW_KEY_TAB: options_.hide_ui = !options_.hide_ui; break;
    default: break;
    }
}

void EditorApp::request_solve() {
    if (!scene_->mesh) return;
    if (solve_task_.busy()) solve_pending_ = true;
    else start_solve();
}

void EditorApp::start_solve() {
    solve_pending_ = false;
    // The worker gets its own copies (or shared, immutable pointers): the UI may edit lights and
    // materials while it runs.
    auto mesh = scene_->mesh;
    auto connectivity = scene_->connectivity;
    auto materials = std::make_shared<const std::vector<TetMaterial>>(scene_->materials);
    const Lighting lighting = lighting_;
    const DiffusionOptions diffusion = diffusion_;
    ImageSettings settings;
    settings.width = std::max(view_w_, 1);
    settings.height = std::max(view_h_, 1);
    if (camera_) {
        settings.camera.eye_direction = camera_->eye_direction();
        settings.camera.up = camera_->up();
    } else {
        settings.camera = options_.camera;
    }
    Scene* target = scene_.get();
    solve_task_.start("solve", [this, target, mesh, connectivity, materials, lighting, diffusion,
                                settings](TaskProgress& progress) {
        progress.set_stage("lighting and diffusion");
        SolvedScene solved = solve_scene(*mesh, *connectivity, *materials, lighting, diffusion);
        progress.set_stage("radiance");
        const auto start = std::chrono::steady_clock::now();
        auto input = std::make_shared<SurfaceRenderInput>(make_render_input(*mesh, solved, lighting, settings));
        auto bvh = std::make_shared<const TriangleBvh>(input->positions, input->triangles);
        const double radiance_ms = ms_since(start);
        solved.diffusion.phi.clear();
        auto stats = std::make_shared<DiffusionSolution>(std::move(solved.diffusion));
        const double lighting_ms = solved.lighting_ms;
        return [this, target, input, bvh, stats, lighting_ms, radiance_ms] {
            if (scene_.get() != target) return;  // a different file was opened meanwhile
            scene_->automatic_exposure = input->exposure;
            scene_->render_input = std::move(*input);
            scene_->surface_bvh = bvh;
            scene_->stats = *stats;
            scene_->lighting_ms = lighting_ms;
            scene_->radiance_ms = radiance_ms;
            ++scene_->solve_count;
            ++scene_version_;
        };
    });
}

void EditorApp::poll_tasks() {
    try {
        load_task_.poll();
    } catch (const std::exception& e) {
        set_error(e.what());
    }
    try {
        if (solve_task_.poll() && solve_pending_) start_solve();
    } catch (const std::exception& e) {
        solve_pending_ = false;
        set_error(std::string("solve: ") + e.what());
    }
}

void EditorApp::wait_for_tasks() {
    load_task_.wait();
    solve_task_.wait();
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
    if (!options_.hide_ui) draw_ui();
    file_dialog_result();
    handle_viewport_input();
    if (!options_.hide_ui) draw_overlays();
    ImGui::Render();

    gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl_.Viewport(0, 0, fb_w, fb_h);
    gl_.ClearColor(0.09f, 0.09f, 0.11f, 1.0f);
    gl_.Clear(GL_COLOR_BUFFER_BIT);
    draw_viewport(fb_h);
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
    const CameraFrame frame = camera_->frame(static_cast<double>(view_w_) / view_h_);
    const ViewKey key{frame.view, frame.projection, view_w_, view_h_, input.samples, input.exposure, scene_version_};
    const int y = fb_h - view_y_ - view_h_;
    if (!view_cache_->holds(key)) {
        const auto start = std::chrono::steady_clock::now();
        try {
            renderer_->draw(input, frame, view_cache_->begin_update(key), 0, 0);
        } catch (const std::exception& e) {
            view_cache_->invalidate();
            scene_->render_input.reset();
            set_error(std::string("drawing: ") + e.what());
            return;
        }
        last_render_ms_ = ms_since(start);
    }
    view_cache_->blit(0, view_x_, y);
}

void EditorApp::handle_viewport_input() {
    const ImGuiIO& io = ImGui::GetIO();
    if (!camera_) return;
    // Mouse in viewport pixels (framebuffer units, origin at the viewport's top-left).
    const double s = framebuffer_scale_;
    const double mx = io.MousePos.x * s - view_x_, my = io.MousePos.y * s - view_y_;
    const bool inside = mx >= 0 && my >= 0 && mx < view_w_ && my < view_h_;
    const double dx = io.MouseDelta.x * s, dy = io.MouseDelta.y * s;
    const bool free = !io.WantCaptureMouse || options_.hide_ui;

    if (free && inside && io.MouseWheel != 0) camera_->zoom(std::pow(0.85, io.MouseWheel));
    // Right drag (or Alt + left) orbits and middle drag (or Shift + right) pans, whatever the tool.
    const bool alt_left = io.KeyAlt && io.MouseDown[0];
    if (free && (io.MouseDown[1] || alt_left) && !io.KeyShift && (dx != 0 || dy != 0)) {
        camera_->orbit(-dx * 0.008, dy * 0.008);
    }
    if (free && (io.MouseDown[2] || (io.MouseDown[1] && io.KeyShift))) camera_->pan(dx, dy, view_h_);
    if (alt_left) return;

    const bool stroke_tool = tool_ == Tool::Cut || tool_ == Tool::ExactCut || tool_ == Tool::Paint ||
                             tool_ == Tool::Fracture;
    if (tool_ == Tool::Orbit) {
        if (free && io.MouseDown[0] && !io.MouseClicked[0] && (dx != 0 || dy != 0))
            camera_->orbit(-dx * 0.008, dy * 0.008);
    } else if (tool_ == Tool::Light) {
        if (free && io.MouseDown[0] && !io.MouseClicked[0] && (dx != 0 || dy != 0) && !lighting_.lights.empty()) {
            drag_light(dx, dy);
        }
    } else if (stroke_tool) {
        if (free && inside && io.MouseClicked[0]) stroke_.clear(), stroke_active_ = true;
        if (stroke_active_ && io.MouseDown[0]) stroke_.push_back({static_cast<float>(mx), static_cast<float>(my)});
        if (stroke_active_ && io.MouseReleased[0]) {
            stroke_active_ = false;
            finish_stroke();
        }
    }
}

void EditorApp::drag_light(double dx, double dy) {
    selected_light_ = std::clamp(selected_light_, 0, static_cast<int>(lighting_.lights.size()) - 1);
    Light& light = lighting_.lights[selected_light_];
    if (light.type == LightType::Directional) {
        // Turn the direction of travel with the mouse, like an arcball about the view axes.
        const Eigen::Vector3d d = light.vector.normalized();
        const Eigen::Matrix3d rotation =
            (Eigen::AngleAxisd(dx * 0.01, camera_->up_axis()) * Eigen::AngleAxisd(dy * 0.01, camera_->right_axis()))
                .toRotationMatrix();
        light.vector = rotation * d;
    } else {
        // Move the point light in the view plane, a point at the target's depth following the cursor.
        const double half_fov = 0.5 * camera_->fov_y_degrees() * 3.14159265358979 / 180.0;
        const double units = 2 * camera_->distance() * std::tan(half_fov) / view_h_;
        light.vector += units * (dx * camera_->right_axis() - dy * camera_->up_axis());
    }
    request_solve();
}

// Until the document (editor/document.h) provides the edit history, only whole-object materials and
// lights change, and there is nothing to undo.
bool EditorApp::can_undo() const { return false; }
bool EditorApp::can_redo() const { return false; }
void EditorApp::undo() { status_ = "Nothing to undo"; }
void EditorApp::redo() { status_ = "Nothing to redo"; }

void EditorApp::set_whole_material(const TetMaterial& material, const std::string& name) {
    if (!scene_->mesh) return;
    scene_->materials.assign(scene_->mesh->tet_count(), material);
    scene_->material_name = name;
    request_solve();
}

void EditorApp::finish_stroke() {
    stroke_.clear();
    status_ = "This tool needs the edit document (not built yet)";
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
        stats.gl_version = reinterpret_cast<const char*>(app.gl().GetString(GL_VERSION));
        stats.gl_renderer = reinterpret_cast<const char*>(app.gl().GetString(GL_RENDERER));
        double frame_ms_sum = 0, view_ms_sum = 0;
        while (!glfwWindowShouldClose(window)) {
            if (screenshot || !app.idle() || app.animating()) glfwPollEvents();
            else glfwWaitEventsTimeout(0.5);  // nothing moves: sleep until input arrives
            const auto start = std::chrono::steady_clock::now();
            app.frame();
            if (screenshot) {
                if (!app.last_error().empty()) throw Error(app.last_error());
                if (!app.idle()) {
                    stats.frames = 0;
                    frame_ms_sum = view_ms_sum = 0;
                    // Not interactive: no point drawing hundreds of progress frames meanwhile.
                    std::this_thread::sleep_for(std::chrono::milliseconds(20));
                } else {
                    app.gl().Finish();  // count the GPU's work in the frame time
                    frame_ms_sum += ms_since(start);
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
        if (const EditorScene& scene = app.scene(); scene.mesh) {
            stats.tets = scene.mesh->tet_count();
            stats.vertices = scene.mesh->vertex_count();
            stats.solve_ms = scene.lighting_ms + scene.stats.assembly_ms + scene.stats.solve_ms + scene.radiance_ms;
        }
    }
    glfwDestroyWindow(window);
    return stats;
}

}  // namespace waxwork
