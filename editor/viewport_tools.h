// The editor's mouse tools as a state machine, independent of GLFW and ImGui so that it is unit
// tested and so that scripted input (editor/input_script.h) and real input drive the same code.
// EditorApp turns window events into PointerEvents in viewport pixels and acts on the ToolOutcome:
//
//   left drag            the current tool (Orbit orbits; Cut, Exact cut, Fracture and Paint draw a
//                        stroke; Move piece drags the piece under the cursor; Light drags the selected
//                        light: a directional one turns like a trackball, a point light follows the cursor;
//                        Grab, Bend and Twist deform the body under the cursor, Pin places pins)
//   right drag, Alt+left orbit          middle drag, Shift+right  pan          wheel  zoom
//   Esc                  cancels the stroke or drag in progress (the editor selects Orbit otherwise)
//   Home                 resets the view (the editor rebuilds the camera)
#pragma once

#include "editor/orbit_camera.h"
#include "editor/stroke_tools.h"
#include "scene/edit_operation.h"
#include "solver/lighting.h"

#include <Eigen/Core>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace waxwork {

enum class Tool { Orbit, Cut, RemoveCut, Relax, Fracture, MovePiece, Paint, Light, Grab, Bend, Twist, Pin };

// Grab, Bend and Twist: the tools that deform the volume while dragging.
bool is_deform_tool(Tool tool);

struct ToolInfo {
    Tool tool;
    const char* name;
    const char* shortcut;  // shown in the menus; empty: none
    const char* id;        // the name input scripts use ("remove_cut")
};
const std::vector<ToolInfo>& tool_infos();
// One line on what a left drag does with the tool and the camera controls (tooltips, the overlay).
const char* tool_hint(Tool tool);
// The camera and tool controls, one per line, for the Help menu.
const std::vector<std::string>& control_lines();

enum class PointerAction { Press, Move, Release, Scroll };
enum class PointerButton { None, Left, Right, Middle };

struct Modifiers {
    bool shift = false;
    bool ctrl = false;
    bool alt = false;
};

struct PointerEvent {
    PointerAction action = PointerAction::Move;
    Eigen::Vector2d position = Eigen::Vector2d::Zero();  // viewport pixels, origin top-left, y down
    PointerButton button = PointerButton::None;          // Press and Release: which button
    Modifiers modifiers;
    double scroll = 0;  // Scroll: wheel steps, positive away from the user (zooms in)
};

// Where a ray from the cursor first meets a piece.
struct PieceHit {
    int piece = -1;
    Eigen::Vector3d point = Eigen::Vector3d::Zero();  // world space
};

// What the tools may look at and change for one event.
struct ViewportContext {
    OrbitCamera* camera = nullptr;  // nullptr: nothing shown yet, events are ignored
    double width = 1, height = 1;   // viewport pixels
    // The piece under a viewport pixel; unset or nullopt: none.
    std::function<std::optional<PieceHit>(const Eigen::Vector2d&)> pick_piece;
    const std::vector<RigidTransform>* piece_transforms = nullptr;
    std::vector<Light>* lights = nullptr;  // the Light tool changes lights[selected_light] in place
    int selected_light = 0;
    // Grab, Bend, Twist and Pin: the handle's falloff radius (world units; a pin's radius is half of
    // it) and the pins placed so far (Bend and Twist turn about their centre).
    double deform_radius = 0;
    const std::vector<PinSphere>* pins = nullptr;
};

// A piece shown moved while it is dragged (the document moves it when the drag ends).
struct PiecePreview {
    int piece = -1;
    RigidTransform transform;                                // the piece's whole transform
    Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // added by the drag so far
};

struct ToolOutcome {
    bool camera_changed = false;
    bool light_changed = false;             // lights[selected_light] was changed
    std::optional<StrokeCutOp> cut;         // a finished Cut or Exact cut stroke
    std::optional<ScreenStroke> paint;      // a finished Paint stroke (the editor casts it at the surface)
    std::optional<ScreenStroke> fracture;   // a finished Fracture stroke
    std::optional<MovePieceOp> move;        // a finished piece drag
    // Grab, Bend and Twist: the drag's deformation so far (shown as a preview), and whether the drag
    // ended (commit it) or ended without a motion (drop the preview).
    std::optional<DeformOp> deform;
    bool deform_finished = false;
    bool deform_cancelled = false;
    std::optional<PinSphere> pin;           // Pin: a pin placed on the surface
    std::string message;                    // why a press did nothing, for the status line
    bool handled() const {
        return camera_changed || light_changed || cut || paint || fracture || move || deform || deform_cancelled || pin;
    }
};

// What to draw over the viewport while a stroke is drawn: its polyline and short ticks on the side
// that a cut takes away.
struct ToolOverlay {
    ScreenStroke stroke;
    std::vector<std::array<Eigen::Vector2d, 2>> cut_side_ticks;  // from a stroke point towards the removed side
};

class ViewportTools {
public:
    static constexpr double kOrbitRadiansPerPixel = 0.008;
    static constexpr double kZoomPerStep = 0.85;     // distance factor per wheel step
    static constexpr float kStrokeSpacing = 3.0f;    // pixels between kept stroke points
    static constexpr double kTickSpacing = 24.0;     // pixels between cut-side ticks
    static constexpr double kTickLength = 9.0;
    static constexpr double kTwistRadiansPerPixel = 0.01;  // horizontal drag: the turn at the handle
    static constexpr double kPinRadiusFraction = 0.5;      // of the deform radius
    // The committed deform: steps and iterations from the rest shape (Document::commit_deform).
    static constexpr int kCommitSteps = 2;
    static constexpr int kCommitIterations = 8;
    Tool tool() const { return tool_; }
    // Cancels a drag in progress (as Esc does) and switches.
    void set_tool(Tool tool, const ViewportContext& context);

    ToolOutcome pointer(const PointerEvent& event, const ViewportContext& context);
    // Esc: drops the stroke or drag in progress (a dragged light returns to where it was). Returns
    // whether there was one.
    bool cancel(const ViewportContext& context);

    // A stroke or a drag is in progress (the window redraws continuously meanwhile).
    bool active() const { return drag_ != Drag::None; }
    ToolOverlay overlay() const;
    const std::optional<PiecePreview>& piece_preview() const { return preview_; }
    // The editor shows the document's moved piece now: stop previewing it.
    void clear_preview() {
        if (drag_ != Drag::Piece) preview_.reset();
    }

private:
    enum class Drag { None, Orbit, Pan, Stroke, Piece, Light, Deform, Pin };

    void begin(const PointerEvent& event, const ViewportContext& context, ToolOutcome& out);
    void drag_to(const PointerEvent& event, const ViewportContext& context, ToolOutcome& out);
    void finish(const PointerEvent& event, const ViewportContext& context, ToolOutcome& out);
    Light* dragged_light(const ViewportContext& context) const;
    void begin_deform(const PointerEvent& event, const ViewportContext& context, ToolOutcome& out);
    void deform_to(const PointerEvent& event, const ViewportContext& context);
    void place_pin(const PointerEvent& event, const ViewportContext& context, ToolOutcome& out);

    Tool tool_ = Tool::Orbit;
    Drag drag_ = Drag::None;
    PointerButton drag_button_ = PointerButton::None;
    Eigen::Vector2d last_ = Eigen::Vector2d::Zero();
    Eigen::Vector2d start_ = Eigen::Vector2d::Zero();
    bool flip_ = false;  // Shift held: the cut keeps the left side instead
    ScreenStroke stroke_;
    std::optional<PiecePreview> preview_;
    Eigen::Vector3d grab_point_ = Eigen::Vector3d::Zero();  // piece or light point under the cursor at the press
    int light_index_ = -1;
    Light light_at_press_;
    std::optional<DeformOp> deform_;                   // the deform drag in progress
    bool deform_moved_ = false;                        // ... and the cursor has left the press pixel
    Eigen::Vector3d pivot_ = Eigen::Vector3d::Zero();  // Bend, Twist: the pins' centre
    std::optional<Eigen::Vector3d> last_pin_;          // Pin drag: where the last pin went
};

// The point on the plane through `anchor` facing the camera that the cursor at `pixel` is over: what
// a dragged point follows so that it stays under the cursor.
Eigen::Vector3d point_under_cursor(const OrbitCamera& camera, const Eigen::Vector2d& pixel, double width,
                                   double height, const Eigen::Vector3d& anchor);

// Shoemake's arcball: the rotation that takes the sphere point under `from` to the one under `to`, the
// sphere filling the viewport's smaller side (cursor outside it: rotation about the view axis).
Eigen::Matrix3d trackball_rotation(const OrbitCamera& camera, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
                                   double width, double height);

}  // namespace waxwork
