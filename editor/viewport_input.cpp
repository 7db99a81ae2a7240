// EditorApp's pointer input: GLFW's cursor, button and scroll callbacks (or an input script calling
// the same callbacks) become PointerEvents for ViewportTools, and its outcome becomes camera changes,
// light changes and queued edits. The tool logic itself lives in viewport_tools.cpp.
#include "editor/editor_app.h"

#include "editor/stroke_tools.h"
#include "solver/material.h"

#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <csignal>
#include <cmath>
#include <limits>
#include <sstream>

namespace waxwork {

ViewportContext EditorApp::viewport_context() {
    ViewportContext context;
    context.camera = camera_ ? &*camera_ : nullptr;
    context.width = view_w_;
    context.height = view_h_;
    context.pick_piece = [this](const Eigen::Vector2d& pixel) { return piece_under(pixel); };
    context.piece_transforms = &scene_->piece_transforms;
    context.lights = &lighting_.lights;
    context.selected_light = selected_light_;
    context.deform_radius = camera_ ? deform_radius_ * camera_->scene_radius() : 0.0;
    context.pins = &pins_;
    return context;
}

bool EditorApp::ui_has_pointer() const {
    if (options_.hide_ui) return false;
    if (file_dialog_.is_open()) return true;
    // ImGui decides capture for where the window's pointer is (it polls it every frame). An event
    // somewhere else came from an input script: ImGui's decision is about another position then.
    double x = 0, y = 0;
    glfwGetCursorPos(window_, &x, &y);
    const bool at_pointer = std::abs(x - cursor_.x()) < 0.5 && std::abs(y - cursor_.y()) < 0.5;
    return ImGui::GetIO().WantCaptureMouse && at_pointer;
}

void EditorApp::on_cursor(double x, double y) {
    cursor_ = Eigen::Vector2d(x, y);
    int mods = mods_;
    if (glfwGetKey(window_, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS || glfwGetKey(window_, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS)
        mods |= GLFW_MOD_SHIFT;
    pointer_event(PointerAction::Move, PointerButton::None, mods);
}

void EditorApp::on_mouse_button(int button, int action, int mods) {
    mods_ = mods;
    const PointerButton b = button == GLFW_MOUSE_BUTTON_LEFT     ? PointerButton::Left
                            : button == GLFW_MOUSE_BUTTON_RIGHT  ? PointerButton::Right
                            : button == GLFW_MOUSE_BUTTON_MIDDLE ? PointerButton::Middle
                                                                 : PointerButton::None;
    if (b == PointerButton::None || (action != GLFW_PRESS && action != GLFW_RELEASE)) return;
    pointer_event(action == GLFW_PRESS ? PointerAction::Press : PointerAction::Release, b, mods);
}

void EditorApp::on_scroll(double steps) { pointer_event(PointerAction::Scroll, PointerButton::None, mods_, steps); }

void EditorApp::pointer_event(PointerAction action, PointerButton button, int mods, double scroll) {
    PointerEvent event;
    event.action = action;
    event.button = button;
    event.scroll = scroll;
    event.modifiers.shift = (mods & GLFW_MOD_SHIFT) != 0;
    event.modifiers.ctrl = (mods & GLFW_MOD_CONTROL) != 0;
    event.modifiers.alt = (mods & GLFW_MOD_ALT) != 0;
    // Viewport pixels: framebuffer units from the viewport's top-left corner.
    event.position = cursor_ * framebuffer_scale_ - Eigen::Vector2d(view_x_, view_y_);
    if (action == PointerAction::Press || action == PointerAction::Scroll) {
        // Drags and the wheel start only in the 3D view, not over a panel or menu.
        const bool inside = event.position.x() >= 0 && event.position.y() >= 0 && event.position.x() < view_w_ &&
                            event.position.y() < view_h_;
        if (!inside || ui_has_pointer()) return;
    }
    const ToolOutcome outcome = tools_.pointer(event, viewport_context());
    apply_tool_outcome(outcome);
}

void EditorApp::apply_tool_outcome(const ToolOutcome& outcome) {
    if (outcome.light_changed) request_solve();
    if (!outcome.message.empty()) status_ = outcome.message;
    if (!camera_ || !scene_->core) return;
    if (outcome.pin) pins_.push_back(*outcome.pin);
    queue_deform(outcome);
    try {
        if (outcome.cut) {
            last_cut_ = outcome.cut->stroke;
            queue_edit(*outcome.cut);
        }
        if (outcome.paint) {
            if (!scene_->surface_bvh) return;
            const auto op = paint_op(*camera_, *scene_->surface_bvh, *outcome.paint, view_w_, view_h_,
                                     brush_material_, brush_radius_ * camera_->scene_radius());
            if (op) queue_edit(*op);
            else status_ = "Paint: the stroke missed the object";
        }
        if (outcome.fracture) {
            FractureOp op;
            if (scene_->surface_bvh && outcome.fracture->size() >= 2) {
                // Seeds along the stroke, on the surface under it: the object breaks where drawn.
                const auto points = stroke_on_surface(*camera_, *scene_->surface_bvh, *outcome.fracture, view_w_, view_h_);
                const size_t step = std::max<size_t>(1, points.size() / static_cast<size_t>(fracture_pieces_));
                for (size_t i = 0; i < points.size(); i += step) op.seeds.push_back(points[i]);
            }
            if (op.seeds.size() < 2) {  // a click, or a stroke that missed: random pieces
                op.seeds.clear();
                op.pieces = fracture_pieces_;
                op.seed = fracture_seed_++;
            }
            queue_edit(op);
        }
        if (outcome.move) queue_edit(*outcome.move);
    } catch (const std::exception& e) {
        set_error(e.what());
    }
}

void EditorApp::select_tool(Tool tool) {
    // Relax is an action on the last cut, not a mode.
    if (tool == Tool::Relax) return relax_last_cut();
    const bool deforming = tools_.active() && is_deform_tool(tools_.tool());
    tools_.set_tool(tool, viewport_context());
    if (deforming) queue_cancel_deform();
    if (tool == Tool::Paint) open_brush_panel_ = true;
}

void EditorApp::queue_deform(const ToolOutcome& outcome) {
    if (outcome.deform_cancelled) return queue_cancel_deform();
    if (!outcome.deform) return;
    const DeformOp op = *outcome.deform;
    if (outcome.deform_finished) {
        mark_modified();
        queue_job("deform", [op](SceneCore& core) {
            const ChangeReport report = core.commit_deform(op);
            std::ostringstream line;
            line << "deform: " << report.details << " (" << std::lround(report.milliseconds) << " ms)";
            return line.str();
        });
        return;
    }
    // Only the latest preview matters: it replaces one still waiting for the worker.
    static constexpr const char* kPreviewLabel = "deform preview";
    if (!pending_jobs_.empty() && pending_jobs_.back().first == kPreviewLabel) pending_jobs_.pop_back();
    const int iterations = deform_preview_iterations_;
    queue_job(kPreviewLabel, [op, iterations](SceneCore& core) {
        const ChangeReport report = core.preview_deform(op, iterations);
        const DragReport& drag = std::get<DragReport>(report.result);
        std::ostringstream line;
        line << "deforming: " << report.moved_vertices.size() << " vertices moved ("
             << std::lround(report.milliseconds) << " ms)";
        if (drag.shortened_steps > 0) line << "; held back by the angle guard";
        return line.str();
    });
}

void EditorApp::queue_cancel_deform() {
    queue_job("cancel deform", [](SceneCore& core) {
        return core.cancel_deform() ? std::string("deform cancelled") : std::string();
    });
}

void EditorApp::select_brush_material(const std::string& name) {
    const std::vector<std::string> names = material_preset_names();
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) throw InvalidArgumentError("no material preset named '" + name + "'");
    brush_preset_ = static_cast<int>(it - names.begin());
    brush_material_ = material_preset(name);
}

std::optional<PieceHit> EditorApp::piece_under(const Eigen::Vector2d& pixel) const {
    if (!camera_ || !scene_->surface_bvh || !scene_->render_input) return std::nullopt;
    const auto hit = first_hit(*scene_->surface_bvh, camera_->unproject(pixel, view_w_, view_h_),
                               camera_->distance() + 4 * camera_->scene_radius());
    if (!hit) return std::nullopt;
    const auto& positions = scene_->render_input->positions;
    if (positions.size() != scene_->surface_piece.size()) return std::nullopt;
    size_t nearest = 0;
    double best = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < positions.size(); ++i) {
        const double d = (positions[i].cast<double>() - *hit).squaredNorm();
        if (d < best) best = d, nearest = i;
    }
    return PieceHit{scene_->surface_piece[nearest], *hit};
}

void EditorApp::handle_viewport_input() { update_piece_preview(); }

void EditorApp::update_piece_preview() {
    const std::optional<PiecePreview>& preview = tools_.piece_preview();
    std::optional<Eigen::Vector3d> shown;
    if (preview) {
        const auto& transforms = scene_->piece_transforms;
        const bool landed = !tools_.active() && preview->piece < static_cast<int>(transforms.size()) &&
                            (transforms[preview->piece].translation - preview->transform.translation -
                             preview->translation).norm() <= 1e-9 * (1 + preview->translation.norm());
        // The document applied the move, or nothing queued or running is left that could (it
        // failed): show the document's mesh instead.
        const bool settled = !tools_.active() && pending_jobs_.empty() && !tick_task_.busy();
        if (landed || settled) tools_.clear_preview();
        else
            shown = preview->translation;
    }
    if (shown != shown_preview_) {
        shown_preview_ = shown;
        ++scene_version_;  // the view cache must draw again
    }
}

SurfaceRenderInput EditorApp::with_piece_preview(const SurfaceRenderInput& input) const {
    SurfaceRenderInput moved = input;
    const std::optional<PiecePreview>& preview = tools_.piece_preview();
    if (!preview || !shown_preview_ || scene_->surface_piece.size() != moved.positions.size()) return moved;
    const Eigen::Vector3f delta = shown_preview_->cast<float>();
    for (size_t i = 0; i < moved.positions.size(); ++i)
        if (scene_->surface_piece[i] == preview->piece) moved.positions[i] += delta;
    return moved;
}

void EditorApp::draw_tool_overlay() {
    ImDrawList* draw = ImGui::GetForegroundDrawList();
    const double s = framebuffer_scale_;
    auto to_screen = [&](double x, double y) {
        return ImVec2(static_cast<float>((x + view_x_) / s), static_cast<float>((y + view_y_) / s));
    };
    // The pins, as circles of their radius, while a tool that uses them is selected.
    if (camera_ && (is_deform_tool(tools_.tool()) || tools_.tool() == Tool::Pin)) {
        for (const PinSphere& pin : pins_) {
            const Eigen::Vector3d c = camera_->project(pin.center, view_w_, view_h_);
            const Eigen::Vector3d r = camera_->project(pin.center + pin.radius * camera_->right_axis(), view_w_, view_h_);
            const float radius = static_cast<float>((r.head<2>() - c.head<2>()).norm() / s);
            if (std::isfinite(radius))
                draw->AddCircle(to_screen(c.x(), c.y()), radius, IM_COL32(90, 220, 140, 220), 0, 1.5f * ui_scale_);
        }
    }
    draw_brush_cursor();
    const ToolOverlay overlay = tools_.overlay();
    if (overlay.stroke.size() < 2) return;
    const ImU32 colour = tools_.tool() == Tool::Paint ? IM_COL32(120, 200, 255, 230) : IM_COL32(255, 190, 90, 230);
    const auto& p = overlay.stroke;
    for (size_t i = 1; i < p.size(); ++i)
        draw->AddLine(to_screen(p[i - 1][0], p[i - 1][1]), to_screen(p[i][0], p[i][1]), colour, 2.0f * ui_scale_);
    for (const auto& tick : overlay.cut_side_ticks)
        draw->AddLine(to_screen(tick[0].x(), tick[0].y()), to_screen(tick[1].x(), tick[1].y()),
                      IM_COL32(255, 110, 80, 230), 1.5f * ui_scale_);
}

namespace {

// The brush rings' colour: the stroke overlay's paint blue, opaque (and a fainter copy for the outer ring).
constexpr ImU32 kBrushRingColour = IM_COL32(80, 200, 255, 255);
constexpr ImU32 kFaintBrushRingColour = IM_COL32(80, 200, 255, 150);

}  // namespace

void EditorApp::draw_brush_cursor() {
    if (tools_.tool() != Tool::Paint || !camera_ || !scene_->surface_bvh || ui_has_pointer()) return;
    const Eigen::Vector2d pixel = cursor_ * framebuffer_scale_ - Eigen::Vector2d(view_x_, view_y_);
    if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() >= view_w_ || pixel.y() >= view_h_) return;
    const std::optional<BrushCursor> brush = brush_cursor(*camera_, *scene_->surface_bvh, pixel, view_w_, view_h_,
                                                          brush_radius_ * camera_->scene_radius());
    if (!brush) return;
    ImDrawList* draw = ImGui::GetForegroundDrawList();
    const double s = framebuffer_scale_;
    const auto outline = [&](const std::vector<Eigen::Vector2d>& ring, ImU32 colour, float thickness) {
        std::vector<ImVec2> points;
        for (const Eigen::Vector2d& p : ring)
            points.emplace_back(static_cast<float>((p.x() + view_x_) / s), static_cast<float>((p.y() + view_y_) / s));
        draw->AddPolyline(points.data(), static_cast<int>(points.size()), colour, ImDrawFlags_Closed, thickness);
    };
    // Dark under light, so the rings read on a bright surface and on a dark one alike.
    outline(brush->tenth_strength, IM_COL32(0, 0, 0, 110), 2.5f * ui_scale_);
    outline(brush->tenth_strength, kFaintBrushRingColour, 1.0f * ui_scale_);
    outline(brush->half_strength, IM_COL32(0, 0, 0, 160), 3.5f * ui_scale_);
    outline(brush->half_strength, kBrushRingColour, 1.8f * ui_scale_);
    const ImVec2 centre(static_cast<float>(cursor_.x()), static_cast<float>(cursor_.y()));
    draw->AddCircleFilled(centre, 2.0f * ui_scale_, kBrushRingColour);
}

namespace {

// Calls the callbacks GLFW would call for real input, so scripted events take the same path:
// ImGui's backend callbacks first (installed after ours), which chain to EditorApp's.
class WindowScriptTarget final : public ScriptTarget {
public:
    WindowScriptTarget(GLFWwindow* window, EditorApp& app) : window_(window), app_(app) {}
    bool ready() const override { return app_.viewport_ready() || app_.start_screen_shown(); }
    bool idle() const override { return app_.idle(); }
    void cursor(double x, double y) override {
        const GLFWcursorposfun f = glfwSetCursorPosCallback(window_, nullptr);
        glfwSetCursorPosCallback(window_, f);
        if (f) f(window_, x, y);
    }
    void button(int button, bool press, int mods) override {
        const GLFWmousebuttonfun f = glfwSetMouseButtonCallback(window_, nullptr);
        glfwSetMouseButtonCallback(window_, f);
        if (f) f(window_, button, press ? GLFW_PRESS : GLFW_RELEASE, mods);
    }
    void scroll(double steps) override {
        const GLFWscrollfun f = glfwSetScrollCallback(window_, nullptr);
        glfwSetScrollCallback(window_, f);
        if (f) f(window_, 0.0, steps);
    }
    void key(int key, int mods) override {
        const GLFWkeyfun f = glfwSetKeyCallback(window_, nullptr);
        glfwSetKeyCallback(window_, f);
        if (!f) return;
        const int scancode = glfwGetKeyScancode(key);
        f(window_, key, scancode, GLFW_PRESS, mods);
        f(window_, key, scancode, GLFW_RELEASE, mods);
    }
    void select_tool(Tool tool) override { app_.select_tool(tool); }
    void select_material(const std::string& preset) override { app_.select_brush_material(preset); }
    void set_crease_angle(double degrees) override { app_.set_crease_angle(degrees); }
    void save_session(const std::filesystem::path& file) override { app_.save_session(file); }
    void save_volume(const std::filesystem::path& file) override { app_.save_volume(file); }
    void export_surface(const std::filesystem::path& file) override { app_.export_surface(file); }
    void open_file(const std::filesystem::path& file) override { app_.request_open(file); }
    void cancel_task() override { app_.cancel_loading(); }
    void choose_repair(const std::string& id) override { app_.choose_repair(id); }
    void render_reference(std::optional<double> seconds, std::optional<double> noise_percent,
                          std::optional<int> size_divisor) override {
        app_.render_reference_with(seconds, noise_percent, size_divisor);
    }
    void cancel_reference() override { app_.cancel_reference(); }
    void save_reference(const std::filesystem::path& file) override { app_.save_reference(file); }
    void snapshot() override { app_.snapshot(); }
    void quit() override { app_.request_quit(); }
    void close_window() override {
        const GLFWwindowclosefun f = glfwSetWindowCloseCallback(window_, nullptr);
        glfwSetWindowCloseCallback(window_, f);
        // What GLFW does for the close button: flag the window, then tell the callback.
        glfwSetWindowShouldClose(window_, GLFW_TRUE);
        if (f) f(window_);
    }
    void answer_dialog(const std::string& button, const std::filesystem::path& file) override {
        app_.answer_unsaved_dialog(button, file);
    }
    void open_example(const std::string& name) override { app_.open_example(name); }
    void recover(bool accept) override { accept ? app_.recover() : app_.discard_recovery(); }
    void autosave() override { app_.autosave(); }
    void kill() override { std::raise(SIGKILL); }
    void save_image(const std::filesystem::path& file) override { app_.save_image(file); }
    void export_turntable(const std::filesystem::path& video, int frames) override { app_.export_turntable(video, frames); }
    void set_background(const std::string& background) override { app_.set_background(background); }

private:
    GLFWwindow* window_;
    EditorApp& app_;
};

}  // namespace

std::unique_ptr<ScriptTarget> make_window_script_target(GLFWwindow* window, EditorApp& app) {
    return std::make_unique<WindowScriptTarget>(window, app);
}

}  // namespace waxwork
