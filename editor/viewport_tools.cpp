#include "editor/viewport_tools.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace waxwork {

const std::vector<ToolInfo>& tool_infos() {
    static const std::vector<ToolInfo> tools = {
        {Tool::Orbit, "Orbit", "Esc", "orbit"},
        {Tool::Cut, "Cut", "C", "cut"},
        {Tool::RemoveCut, "Remove cut", "X", "remove_cut"},
        {Tool::Relax, "Relax", "R", "relax"},
        {Tool::Fracture, "Fracture", "F", "fracture"},
        {Tool::MovePiece, "Move piece", "M", "move_piece"},
        {Tool::Paint, "Paint", "P", "paint"},
        {Tool::Light, "Light", "L", "light"},
        {Tool::Grab, "Grab", "G", "grab"},
        {Tool::Bend, "Bend", "B", "bend"},
        {Tool::Twist, "Twist", "T", "twist"},
        {Tool::Pin, "Pin", "N", "pin"},
    };
    return tools;
}

bool is_deform_tool(Tool tool) { return tool == Tool::Grab || tool == Tool::Bend || tool == Tool::Twist; }

const char* tool_hint(Tool tool) {
    switch (tool) {
    case Tool::Orbit: return "Drag: orbit. Right drag: orbit, middle drag: pan, wheel: zoom.";
    case Tool::Cut:
        return "Draw a stroke across the object: it cuts exactly along it (tets split at the surface) and the "
               "ticked (left) side goes; Shift: the right.";
    case Tool::RemoveCut:
        return "The paper's cut, for comparison: the tets on the ticked side go whole and the jagged "
               "cross-section is relaxed (R relaxes more); Shift: the right side.";
    case Tool::Relax: return "Relax the cross-sections of the last cut.";
    case Tool::Fracture: return "Draw a stroke: the object breaks into pieces along it; a click: random pieces.";
    case Tool::MovePiece: return "Drag a piece to move it (after Fracture); Esc while dragging puts it back.";
    case Tool::Paint: return "Paint the Brush panel's material into the volume under the stroke; the rings show its reach.";
    case Tool::Light: return "Drag: turn the selected directional light like a trackball, or move the point light.";
    case Tool::Grab: return "Drag the surface: the body follows as rigidly as it can; pins (N) hold it elsewhere.";
    case Tool::Bend: return "Drag around the pins: the grabbed end turns about the view axis through their centre.";
    case Tool::Twist: return "Drag sideways: the grabbed end turns about the line from the pins' centre to it.";
    case Tool::Pin: return "Click or drag on the surface to pin the volume there (Deform panel: clear pins).";
    }
    return "";
}

const std::vector<std::string>& control_lines() {
    static const std::vector<std::string> lines = {
        "Left drag: the current tool (C cut, X exact cut, F fracture, M move piece, P paint, L light,",
        "           G grab, B bend, T twist, N pin)",
        "Right drag or Alt+left drag: orbit",
        "Middle drag or Shift+right drag: pan",
        "Wheel: zoom          Home: reset the view",
        "Esc: cancel the stroke or drag, else back to Orbit",
        "Shift while cutting: cut away the right side instead",
        "Ctrl+Z / Ctrl+Shift+Z: undo / redo   Tab: hide the panels",
        "D: remove the fragments under a size set in the Edit menu (0.1% of the volume at first)",
    };
    return lines;
}

Eigen::Vector3d point_under_cursor(const OrbitCamera& camera, const Eigen::Vector2d& pixel, double width,
                                   double height, const Eigen::Vector3d& anchor) {
    const Ray ray = camera.unproject(pixel, width, height);
    const Eigen::Vector3d forward = -camera.eye_direction();
    const double along = ray.direction.dot(forward);
    // A ray parallel to the plane (impossible inside a field of view under 180 degrees): stay put.
    if (!(along > 1e-9)) return anchor;
    return ray.origin + ((anchor - ray.origin).dot(forward) / along) * ray.direction;
}

namespace {

// The arcball sphere point under a pixel, in view coordinates (x right, y up, z towards the eye).
Eigen::Vector3d sphere_point(const Eigen::Vector2d& pixel, double width, double height) {
    const double radius = 0.5 * std::min(width, height);
    Eigen::Vector3d p((pixel.x() - 0.5 * width) / radius, (0.5 * height - pixel.y()) / radius, 0);
    const double r2 = p.head<2>().squaredNorm();
    if (r2 <= 1) p.z() = std::sqrt(1 - r2);
    else p.head<2>() /= std::sqrt(r2);
    return p;
}

}  // namespace

Eigen::Matrix3d trackball_rotation(const OrbitCamera& camera, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
                                   double width, double height) {
    const Eigen::Vector3d a = sphere_point(from, width, height), b = sphere_point(to, width, height);
    Eigen::Matrix3d view_to_world;
    view_to_world.col(0) = camera.right_axis();
    view_to_world.col(1) = camera.up_axis();
    view_to_world.col(2) = camera.eye_direction();
    const Eigen::Quaterniond rotation = Eigen::Quaterniond::FromTwoVectors(view_to_world * a, view_to_world * b);
    return rotation.toRotationMatrix();
}

void ViewportTools::set_tool(Tool tool, const ViewportContext& context) {
    cancel(context);
    tool_ = tool;
}

Light* ViewportTools::dragged_light(const ViewportContext& context) const {
    if (!context.lights || light_index_ < 0 || light_index_ >= static_cast<int>(context.lights->size())) return nullptr;
    return &(*context.lights)[light_index_];
}

bool ViewportTools::cancel(const ViewportContext& context) {
    if (drag_ == Drag::None) return false;
    if (drag_ == Drag::Light) {
        if (Light* light = dragged_light(context)) *light = light_at_press_;
    }
    drag_ = Drag::None;
    drag_button_ = PointerButton::None;
    stroke_.clear();
    preview_.reset();
    light_index_ = -1;
    deform_.reset();
    last_pin_.reset();
    return true;
}

ToolOutcome ViewportTools::pointer(const PointerEvent& event, const ViewportContext& context) {
    ToolOutcome out;
    if (!context.camera || !(context.width > 0) || !(context.height > 0) || !event.position.allFinite()) return out;
    switch (event.action) {
    case PointerAction::Scroll:
        if (std::isfinite(event.scroll) && event.scroll != 0) {
            context.camera->zoom(std::pow(kZoomPerStep, event.scroll));
            out.camera_changed = true;
        }
        break;
    case PointerAction::Press:
        if (drag_ == Drag::None) begin(event, context, out);
        break;
    case PointerAction::Move:
        if (drag_ != Drag::None) drag_to(event, context, out);
        break;
    case PointerAction::Release:
        if (drag_ != Drag::None && event.button == drag_button_) {
            drag_to(event, context, out);
            finish(event, context, out);
        }
        break;
    }
    last_ = event.position;
    return out;
}

void ViewportTools::begin(const PointerEvent& event, const ViewportContext& context, ToolOutcome& out) {
    (void)out;
    const Modifiers& m = event.modifiers;
    const bool left = event.button == PointerButton::Left, right = event.button == PointerButton::Right;
    drag_button_ = event.button;
    start_ = event.position;
    if (event.button == PointerButton::Middle || (right && m.shift)) {
        drag_ = Drag::Pan;
    } else if (right || (left && m.alt)) {
        drag_ = Drag::Orbit;
    } else if (!left) {
        drag_button_ = PointerButton::None;
    } else {
        switch (tool_) {
        case Tool::Orbit:
        case Tool::Relax: drag_ = Drag::Orbit; break;
        case Tool::Cut:
        case Tool::RemoveCut:
        case Tool::Fracture:
        case Tool::Paint:
            drag_ = Drag::Stroke;
            stroke_.assign(1, {static_cast<float>(event.position.x()), static_cast<float>(event.position.y())});
            flip_ = m.shift;
            break;
        case Tool::MovePiece: {
            const std::optional<PieceHit> hit = context.pick_piece ? context.pick_piece(event.position) : std::nullopt;
            const auto* transforms = context.piece_transforms;
            if (!hit || !transforms || hit->piece < 0 || hit->piece >= static_cast<int>(transforms->size())) break;
            drag_ = Drag::Piece;
            grab_point_ = hit->point;
            preview_ = PiecePreview{hit->piece, (*transforms)[hit->piece], Eigen::Vector3d::Zero()};
            break;
        }
        case Tool::Grab:
        case Tool::Bend:
        case Tool::Twist: begin_deform(event, context, out); break;
        case Tool::Pin:
            drag_ = Drag::Pin;
            last_pin_.reset();
            place_pin(event, context, out);
            break;
        case Tool::Light:
            if (!context.lights || context.selected_light < 0 ||
                context.selected_light >= static_cast<int>(context.lights->size()))
                break;
            drag_ = Drag::Light;
            light_index_ = context.selected_light;
            light_at_press_ = (*context.lights)[light_index_];
            grab_point_ = light_at_press_.vector;
            break;
        }
    }
    if (drag_ == Drag::None) drag_button_ = PointerButton::None;
}

void ViewportTools::drag_to(const PointerEvent& event, const ViewportContext& context, ToolOutcome& out) {
    OrbitCamera& camera = *context.camera;
    const Eigen::Vector2d delta = event.position - last_;
    switch (drag_) {
    case Drag::None: break;
    case Drag::Orbit:
        if (delta.squaredNorm() > 0) {
            // Dragging right turns the object right (the eye left); dragging down raises the eye.
            camera.orbit(-delta.x() * kOrbitRadiansPerPixel, delta.y() * kOrbitRadiansPerPixel);
            out.camera_changed = true;
        }
        break;
    case Drag::Pan:
        if (delta.squaredNorm() > 0) {
            camera.pan(delta.x(), delta.y(), context.height);
            out.camera_changed = true;
        }
        break;
    case Drag::Stroke: {
        const std::array<float, 2> p = {static_cast<float>(event.position.x()), static_cast<float>(event.position.y())};
        if (p != stroke_.back()) stroke_.push_back(p);
        flip_ = event.modifiers.shift;
        break;
    }
    case Drag::Piece:
        // The grabbed point stays under the cursor, at its depth.
        preview_->translation = point_under_cursor(camera, event.position, context.width, context.height, grab_point_) -
                                grab_point_;
        break;
    case Drag::Deform:
        // A press and release on one pixel is a click, not a drag (the round trip through the
        // camera's projection would still make a tiny motion of it).
        deform_moved_ = deform_moved_ || (event.position - start_).norm() >= 1;
        deform_to(event, context);
        out.deform = deform_;
        break;
    case Drag::Pin: place_pin(event, context, out); break;
    case Drag::Light: {
        Light* light = dragged_light(context);
        if (!light) break;
        if (light_at_press_.type == LightType::Directional) {
            // The light's source on a trackball: the rotation from the press to the cursor turns the
            // direction it had at the press (not incrementally, so a drag back returns it exactly).
            const Eigen::Matrix3d r = trackball_rotation(camera, start_, event.position, context.width, context.height);
            light->vector = r * light_at_press_.vector;
        } else {
            light->vector = point_under_cursor(camera, event.position, context.width, context.height, grab_point_);
        }
        out.light_changed = true;
        break;
    }
    }
}

void ViewportTools::finish(const PointerEvent& event, const ViewportContext& context, ToolOutcome& out) {
    const OrbitCamera& camera = *context.camera;
    if (drag_ == Drag::Stroke) {
        const ScreenStroke stroke = simplify_stroke(stroke_, kStrokeSpacing);
        if (tool_ == Tool::Cut || tool_ == Tool::RemoveCut) {
            out.cut = stroke_cut_op(camera, stroke, context.width, context.height, tool_ == Tool::Cut,
                                    event.modifiers.shift);
        } else if (tool_ == Tool::Paint) {
            if (!stroke.empty()) out.paint = stroke;
        } else if (tool_ == Tool::Fracture) {
            out.fracture = stroke;
        }
    } else if (drag_ == Drag::Piece && preview_ && preview_->translation.squaredNorm() > 0) {
        MovePieceOp op;
        op.piece = preview_->piece;
        op.transform = preview_->transform;
        op.transform.translation += preview_->translation;
        out.move = op;
    }
    if (drag_ == Drag::Deform) {
        if (deform_moved_) {
            out.deform = deform_;
            out.deform_finished = true;
        } else {
            out.deform.reset();
            out.deform_cancelled = true;
        }
    }
    // After a move the preview stays until the editor shows the moved piece (clear_preview), so the
    // piece does not jump back for the frames the document takes to apply it.
    const bool keep_preview = out.move.has_value();
    drag_ = Drag::None;
    drag_button_ = PointerButton::None;
    stroke_.clear();
    light_index_ = -1;
    deform_.reset();
    last_pin_.reset();
    if (!keep_preview) preview_.reset();
}

void ViewportTools::begin_deform(const PointerEvent& event, const ViewportContext& context, ToolOutcome& out) {
    const std::optional<PieceHit> hit = context.pick_piece ? context.pick_piece(event.position) : std::nullopt;
    if (!hit) return;
    if (!(context.deform_radius > 0)) {
        out.message = "Grab, Bend and Twist need a positive radius";
        return;
    }
    const std::vector<PinSphere> pins = context.pins ? *context.pins : std::vector<PinSphere>{};
    if (tool_ != Tool::Grab) {
        if (pins.empty()) {
            out.message = "Bend and Twist turn about the pins: place pins first (Pin tool, N)";
            return;
        }
        pivot_ = Eigen::Vector3d::Zero();
        for (const PinSphere& pin : pins) pivot_ += pin.center;
        pivot_ /= static_cast<double>(pins.size());
        if ((hit->point - pivot_).norm() <= 1e-9 * context.deform_radius) {
            out.message = "Grab farther from the pins: Bend and Twist turn about their centre";
            return;
        }
    }
    DeformOp op;
    op.grab = hit->point;
    op.radius = context.deform_radius;
    op.pins = pins;
    op.steps = kCommitSteps;
    op.iterations = kCommitIterations;
    deform_ = op;
    deform_moved_ = false;
    grab_point_ = hit->point;
    drag_ = Drag::Deform;
}

void ViewportTools::deform_to(const PointerEvent& event, const ViewportContext& context) {
    const OrbitCamera& camera = *context.camera;
    const Eigen::Vector3d cursor = point_under_cursor(camera, event.position, context.width, context.height, grab_point_);
    switch (tool_) {
    case Tool::Bend: {
        // About the view axis through the pins' centre, by the angle the cursor swept around it (the
        // axis points at the eye, so a counter-clockwise sweep on screen turns the body the same way).
        const Eigen::Vector3d axis = camera.eye_direction();
        Eigen::Vector3d a = grab_point_ - pivot_, b = cursor - pivot_;
        a -= a.dot(axis) * axis;
        b -= b.dot(axis) * axis;
        const double angle = std::atan2(axis.dot(a.cross(b)), a.dot(b));
        deform_->motion = HandleMotion::bend(pivot_, axis, std::isfinite(angle) ? angle : 0.0);
        break;
    }
    case Tool::Twist: {
        // About the line from the pins' centre to the grab point; the turn grows along it from zero at
        // the pins to the dragged angle at the grab point.
        const Eigen::Vector3d axis = grab_point_ - pivot_;
        const double angle = (event.position.x() - start_.x()) * kTwistRadiansPerPixel;
        deform_->motion = HandleMotion::twist(pivot_, axis, angle / axis.norm());
        break;
    }
    default: deform_->motion = HandleMotion::translation(cursor - grab_point_); break;
    }
}

void ViewportTools::place_pin(const PointerEvent& event, const ViewportContext& context, ToolOutcome& out) {
    const std::optional<PieceHit> hit = context.pick_piece ? context.pick_piece(event.position) : std::nullopt;
    const double radius = kPinRadiusFraction * context.deform_radius;
    if (!hit || !(radius > 0)) return;
    // A drag lays pins half a radius apart along the surface.
    if (last_pin_ && (hit->point - *last_pin_).norm() < 0.5 * radius) return;
    last_pin_ = hit->point;
    out.pin = PinSphere{hit->point, radius};
}

ToolOverlay ViewportTools::overlay() const {
    ToolOverlay overlay;
    if (drag_ != Drag::Stroke) return overlay;
    overlay.stroke = stroke_;
    if (tool_ != Tool::Cut && tool_ != Tool::RemoveCut) return overlay;
    // Ticks every kTickSpacing pixels of arc length, on the side that goes: the left of the stroke as
    // drawn (y down, so the left of direction (dx, dy) is (dy, -dx)), the right with Shift.
    double next_tick = 0.5 * kTickSpacing, travelled = 0;
    for (size_t i = 1; i < stroke_.size(); ++i) {
        const Eigen::Vector2d a(stroke_[i - 1][0], stroke_[i - 1][1]), b(stroke_[i][0], stroke_[i][1]);
        const double length = (b - a).norm();
        if (length == 0) continue;
        const Eigen::Vector2d d = (b - a) / length;
        Eigen::Vector2d side(d.y(), -d.x());
        if (flip_) side = -side;
        while (next_tick <= travelled + length) {
            const Eigen::Vector2d at = a + (next_tick - travelled) * d;
            overlay.cut_side_ticks.push_back({at, at + kTickLength * side});
            next_tick += kTickSpacing;
        }
        travelled += length;
    }
    return overlay;
}

}  // namespace waxwork
