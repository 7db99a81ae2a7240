#include "editor/viewport_tools.h"

#include "tetops/cut.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace waxwork {
namespace {

constexpr double kWidth = 400, kHeight = 300;

OrbitCamera test_camera() {
    CameraSettings settings;
    settings.eye_direction = Eigen::Vector3d(0, 0, 1);
    return OrbitCamera(Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)), settings,
                       kWidth / kHeight);
}

PointerEvent event(PointerAction action, double x, double y, PointerButton button = PointerButton::None,
                   Modifiers modifiers = {}) {
    PointerEvent e;
    e.action = action;
    e.position = Eigen::Vector2d(x, y);
    e.button = button;
    e.modifiers = modifiers;
    return e;
}

// Press at the first point, move through the others, release at the last; returns the release's outcome.
ToolOutcome drag(ViewportTools& tools, const ViewportContext& context, const std::vector<Eigen::Vector2d>& points,
                 PointerButton button = PointerButton::Left, Modifiers modifiers = {}) {
    tools.pointer(event(PointerAction::Press, points[0].x(), points[0].y(), button, modifiers), context);
    for (size_t i = 1; i < points.size(); ++i)
        tools.pointer(event(PointerAction::Move, points[i].x(), points[i].y(), PointerButton::None, modifiers), context);
    return tools.pointer(event(PointerAction::Release, points.back().x(), points.back().y(), button, modifiers), context);
}

ViewportContext context_for(OrbitCamera& camera) {
    ViewportContext context;
    context.camera = &camera;
    context.width = kWidth;
    context.height = kHeight;
    return context;
}

TEST(ViewportTools, RemoveCutDragYieldsAStrokeCutThroughTheDraggedPoints) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    ViewportTools tools;
    tools.set_tool(Tool::RemoveCut, context);
    const std::vector<Eigen::Vector2d> points = {{100, 50}, {150, 120}, {220, 180}, {300, 250}};
    tools.pointer(event(PointerAction::Press, 100, 50, PointerButton::Left), context);
    for (size_t i = 1; i < points.size(); ++i) {
        const ToolOutcome during = tools.pointer(event(PointerAction::Move, points[i].x(), points[i].y()), context);
        EXPECT_FALSE(during.cut);
        // The overlay shows the stroke so far while it is drawn.
        EXPECT_EQ(tools.overlay().stroke.size(), i + 1);
    }
    EXPECT_TRUE(tools.active());
    const ToolOutcome out = tools.pointer(event(PointerAction::Release, 300, 250, PointerButton::Left), context);
    ASSERT_TRUE(out.cut);
    EXPECT_FALSE(out.cut->exact);
    EXPECT_FALSE(out.cut->stroke.flip);
    ASSERT_EQ(out.cut->stroke.points.size(), points.size());
    for (size_t i = 0; i < points.size(); ++i) {
        // Each stroke point lies under its cursor position.
        const Eigen::Vector3d p = camera.project(out.cut->stroke.points[i], kWidth, kHeight);
        EXPECT_NEAR(p.x(), points[i].x(), 1e-6);
        EXPECT_NEAR(p.y(), points[i].y(), 1e-6);
    }
    EXPECT_LT((out.cut->stroke.eye - camera.eye()).norm(), 1e-12);
    EXPECT_FALSE(tools.active());
    EXPECT_TRUE(tools.overlay().stroke.empty());
}

TEST(ViewportTools, TheCutToolCutsExactlyAndShiftFlipsTheSide) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    ViewportTools tools;
    tools.set_tool(Tool::Cut, context);
    const ToolOutcome out = drag(tools, context, {{200, 20}, {200, 150}, {200, 280}}, PointerButton::Left, {true, false, false});
    ASSERT_TRUE(out.cut);
    EXPECT_TRUE(out.cut->exact);
    EXPECT_TRUE(out.cut->stroke.flip);
}

TEST(ViewportTools, CutSideTicksPointAtTheSideTheCutRemoves) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    for (const bool shift : {false, true}) {
        ViewportTools tools;
        tools.set_tool(Tool::Cut, context);
        const Modifiers modifiers{shift, false, false};
        const std::vector<Eigen::Vector2d> points = {{80, 40}, {200, 150}, {330, 260}};
        tools.pointer(event(PointerAction::Press, 80, 40, PointerButton::Left, modifiers), context);
        tools.pointer(event(PointerAction::Move, 200, 150, PointerButton::None, modifiers), context);
        tools.pointer(event(PointerAction::Move, 330, 260, PointerButton::None, modifiers), context);
        const ToolOverlay overlay = tools.overlay();
        ASSERT_GE(overlay.cut_side_ticks.size(), 3u);
        const ToolOutcome out = tools.pointer(event(PointerAction::Release, 330, 260, PointerButton::Left, modifiers), context);
        ASSERT_TRUE(out.cut);
        const StrokeCut cut(out.cut->stroke.eye, out.cut->stroke.view_direction, out.cut->stroke.points, out.cut->stroke.flip);
        for (const auto& tick : overlay.cut_side_ticks) {
            // The tick's far end, at the target's depth, lies on the cut-away side; the opposite point on the kept one.
            const Eigen::Vector2d far_end = tick[1], opposite = 2 * tick[0] - tick[1];
            EXPECT_TRUE(cut.cuts_away(point_under_cursor(camera, far_end, kWidth, kHeight, camera.target()))) << shift;
            EXPECT_FALSE(cut.cuts_away(point_under_cursor(camera, opposite, kWidth, kHeight, camera.target()))) << shift;
        }
    }
}

TEST(ViewportTools, EscapeCancelsTheStroke) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    ViewportTools tools;
    tools.set_tool(Tool::Paint, context);
    tools.pointer(event(PointerAction::Press, 100, 100, PointerButton::Left), context);
    tools.pointer(event(PointerAction::Move, 180, 120), context);
    EXPECT_TRUE(tools.cancel(context));
    EXPECT_FALSE(tools.active());
    EXPECT_TRUE(tools.overlay().stroke.empty());
    // The release after a cancelled stroke does nothing.
    const ToolOutcome out = tools.pointer(event(PointerAction::Release, 200, 130, PointerButton::Left), context);
    EXPECT_FALSE(out.handled());
    EXPECT_FALSE(tools.cancel(context));  // nothing left to cancel
}

TEST(ViewportTools, PaintAndFractureStrokesComeBackInViewportPixels) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    ViewportTools tools;
    tools.set_tool(Tool::Paint, context);
    const ToolOutcome paint = drag(tools, context, {{100, 100}, {140, 110}, {190, 120}});
    ASSERT_TRUE(paint.paint);
    ASSERT_EQ(paint.paint->size(), 3u);
    EXPECT_FLOAT_EQ((*paint.paint)[1][0], 140);
    EXPECT_FLOAT_EQ((*paint.paint)[2][1], 120);
    tools.set_tool(Tool::Fracture, context);
    const ToolOutcome fracture = drag(tools, context, {{50, 60}, {250, 60}});
    ASSERT_TRUE(fracture.fracture);
    EXPECT_EQ(fracture.fracture->size(), 2u);
}

TEST(ViewportTools, RightDragOrbitsMiddleDragPansWheelZooms) {
    const OrbitCamera start = test_camera();
    ViewportTools tools;
    tools.set_tool(Tool::Cut, ViewportContext{});  // camera controls work whatever the tool

    OrbitCamera orbiting = start;
    ViewportContext context = context_for(orbiting);
    ToolOutcome out = drag(tools, context, {{200, 150}, {250, 150}}, PointerButton::Right);
    // Dragging 50 px right turns the eye by -50 * 0.008 rad about up: from +z towards -x.
    const double angle = -50 * ViewportTools::kOrbitRadiansPerPixel;
    EXPECT_NEAR(orbiting.eye_direction().x(), std::sin(angle), 1e-9);
    EXPECT_NEAR(orbiting.eye_direction().z(), std::cos(angle), 1e-9);
    EXPECT_LT((orbiting.target() - start.target()).norm(), 1e-12);
    EXPECT_FALSE(out.cut);  // no stroke from an orbit

    // Alt + left orbits too.
    OrbitCamera alt = start;
    context = context_for(alt);
    drag(tools, context, {{200, 150}, {250, 150}}, PointerButton::Left, {false, false, true});
    EXPECT_LT((alt.eye_direction() - orbiting.eye_direction()).norm(), 1e-12);

    // Middle drag and Shift + right pan: the target point follows the cursor.
    for (const auto& [button, modifiers] : {std::pair{PointerButton::Middle, Modifiers{}},
                                            std::pair{PointerButton::Right, Modifiers{true, false, false}}}) {
        OrbitCamera panning = start;
        context = context_for(panning);
        const Eigen::Vector3d point = start.target();
        const Eigen::Vector3d before = panning.project(point, kWidth, kHeight);
        drag(tools, context, {{200, 150}, {230, 170}}, button, modifiers);
        const Eigen::Vector3d after = panning.project(point, kWidth, kHeight);
        EXPECT_NEAR(after.x() - before.x(), 30, 1e-6);
        EXPECT_NEAR(after.y() - before.y(), 20, 1e-6);
        EXPECT_LT((panning.eye_direction() - start.eye_direction()).norm(), 1e-12);
    }

    OrbitCamera zooming = start;
    context = context_for(zooming);
    PointerEvent wheel = event(PointerAction::Scroll, 200, 150);
    wheel.scroll = 2;
    out = tools.pointer(wheel, context);
    EXPECT_TRUE(out.camera_changed);
    EXPECT_NEAR(zooming.distance(), start.distance() * ViewportTools::kZoomPerStep * ViewportTools::kZoomPerStep, 1e-9);
}

TEST(ViewportTools, LeftDragOrbitsWithTheOrbitTool) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    ViewportTools tools;
    tools.pointer(event(PointerAction::Press, 200, 150, PointerButton::Left), context);
    EXPECT_TRUE(tools.pointer(event(PointerAction::Move, 200, 100), context).camera_changed);
    // Dragging up lowers the eye (pitch is +dy).
    EXPECT_LT(camera.eye_direction().y(), 0);
}

TEST(ViewportTools, PieceDragPreviewsThenMovesThePiece) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    std::vector<RigidTransform> transforms(3);
    transforms[2].translation = Eigen::Vector3d(0.5, 0, 0);
    context.piece_transforms = &transforms;
    const Eigen::Vector3d grabbed(0.2, 0.1, 0.4);
    context.pick_piece = [&](const Eigen::Vector2d&) { return std::optional<PieceHit>(PieceHit{2, grabbed}); };
    ViewportTools tools;
    tools.set_tool(Tool::MovePiece, context);
    const Eigen::Vector3d at = camera.project(grabbed, kWidth, kHeight);
    tools.pointer(event(PointerAction::Press, at.x(), at.y(), PointerButton::Left), context);
    ASSERT_TRUE(tools.piece_preview());
    EXPECT_EQ(tools.piece_preview()->piece, 2);
    const ToolOutcome during = tools.pointer(event(PointerAction::Move, at.x() + 40, at.y() - 25), context);
    EXPECT_FALSE(during.move);
    // The preview moves the grabbed point under the cursor, at its depth.
    const Eigen::Vector3d preview_point = grabbed + tools.piece_preview()->translation;
    const Eigen::Vector3d seen = camera.project(preview_point, kWidth, kHeight);
    EXPECT_NEAR(seen.x(), at.x() + 40, 1e-6);
    EXPECT_NEAR(seen.y(), at.y() - 25, 1e-6);
    EXPECT_NEAR((preview_point - camera.eye()).dot(-camera.eye_direction()),
                (grabbed - camera.eye()).dot(-camera.eye_direction()), 1e-9);
    const ToolOutcome out = tools.pointer(event(PointerAction::Release, at.x() + 40, at.y() - 25, PointerButton::Left), context);
    ASSERT_TRUE(out.move);
    EXPECT_EQ(out.move->piece, 2);
    EXPECT_LT((out.move->transform.translation - (transforms[2].translation + tools.piece_preview()->translation)).norm(), 1e-12);
    EXPECT_GT(out.move->transform.translation.x(), 0.5);  // moved right
    // The preview stays until the editor shows the moved piece.
    EXPECT_TRUE(tools.piece_preview());
    tools.clear_preview();
    EXPECT_FALSE(tools.piece_preview());
}

TEST(ViewportTools, PieceDragOnNothingOrCancelledMovesNothing) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    std::vector<RigidTransform> transforms(2);
    context.piece_transforms = &transforms;
    context.pick_piece = [](const Eigen::Vector2d&) { return std::optional<PieceHit>(); };
    ViewportTools tools;
    tools.set_tool(Tool::MovePiece, context);
    EXPECT_FALSE(drag(tools, context, {{100, 100}, {200, 100}}).move);
    context.pick_piece = [](const Eigen::Vector2d&) { return std::optional<PieceHit>(PieceHit{1, Eigen::Vector3d::Zero()}); };
    tools.pointer(event(PointerAction::Press, 200, 150, PointerButton::Left), context);
    tools.pointer(event(PointerAction::Move, 260, 150), context);
    EXPECT_TRUE(tools.cancel(context));
    EXPECT_FALSE(tools.piece_preview());
    EXPECT_FALSE(tools.pointer(event(PointerAction::Release, 260, 150, PointerButton::Left), context).move);
}

// Grab: every move previews the translation that keeps the grabbed point under the cursor; the
// release commits it with the pins and radius of the press.
TEST(ViewportTools, GrabPreviewsEveryMoveAndCommitsOnRelease) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    const Eigen::Vector3d grabbed(0.2, 0.1, 0.4);
    context.pick_piece = [&](const Eigen::Vector2d&) { return std::optional<PieceHit>(PieceHit{0, grabbed}); };
    const std::vector<PinSphere> pins = {PinSphere{Eigen::Vector3d(-0.5, 0, 0), 0.1}};
    context.pins = &pins;
    context.deform_radius = 0.3;
    ViewportTools tools;
    tools.set_tool(Tool::Grab, context);
    const Eigen::Vector3d at = camera.project(grabbed, kWidth, kHeight);
    EXPECT_FALSE(tools.pointer(event(PointerAction::Press, at.x(), at.y(), PointerButton::Left), context).deform);
    const ToolOutcome during = tools.pointer(event(PointerAction::Move, at.x() + 30, at.y() + 10), context);
    ASSERT_TRUE(during.deform);
    EXPECT_FALSE(during.deform_finished);
    EXPECT_EQ(during.deform->grab, grabbed);
    EXPECT_EQ(during.deform->radius, 0.3);
    EXPECT_EQ(during.deform->pins, pins);
    EXPECT_EQ(during.deform->motion.kind, HandleMotion::Kind::Translate);
    const Eigen::Vector3d seen = camera.project(grabbed + during.deform->motion.move, kWidth, kHeight);
    EXPECT_NEAR(seen.x(), at.x() + 30, 1e-6);
    EXPECT_NEAR(seen.y(), at.y() + 10, 1e-6);
    const ToolOutcome out = tools.pointer(event(PointerAction::Release, at.x() + 30, at.y() + 10, PointerButton::Left), context);
    ASSERT_TRUE(out.deform);
    EXPECT_TRUE(out.deform_finished);
    EXPECT_TRUE(*out.deform == *during.deform);
    EXPECT_FALSE(tools.active());
    // A click without a motion ends the preview instead of committing an empty edit.
    tools.pointer(event(PointerAction::Press, at.x(), at.y(), PointerButton::Left), context);
    const ToolOutcome click = tools.pointer(event(PointerAction::Release, at.x(), at.y(), PointerButton::Left), context);
    EXPECT_FALSE(click.deform);
    EXPECT_TRUE(click.deform_cancelled);
}

// Bend turns about the view axis through the pins' centre by the angle swept around it; Twist turns
// about the line from the pins' centre to the grab point, the turn at the grab point growing with the
// horizontal drag. Without pins both refuse with a message.
TEST(ViewportTools, BendAndTwistTurnAboutThePins) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    const Eigen::Vector3d grabbed(0.5, 0, 0);
    context.pick_piece = [&](const Eigen::Vector2d&) { return std::optional<PieceHit>(PieceHit{0, grabbed}); };
    context.deform_radius = 0.3;
    std::vector<PinSphere> pins;
    context.pins = &pins;
    ViewportTools tools;
    tools.set_tool(Tool::Bend, context);
    const Eigen::Vector3d at = camera.project(grabbed, kWidth, kHeight);
    const ToolOutcome refused = tools.pointer(event(PointerAction::Press, at.x(), at.y(), PointerButton::Left), context);
    EXPECT_NE(refused.message.find("place pins first"), std::string::npos);
    EXPECT_FALSE(tools.active());
    EXPECT_FALSE(tools.pointer(event(PointerAction::Release, at.x(), at.y() - 40, PointerButton::Left), context).deform);

    pins = {PinSphere{Eigen::Vector3d(-0.5, 0.1, 0), 0.1}, PinSphere{Eigen::Vector3d(-0.5, -0.1, 0), 0.1}};
    const Eigen::Vector3d pivot(-0.5, 0, 0);
    // The cursor goes a quarter turn counter-clockwise on screen around the pivot (up is -y on screen).
    const Eigen::Vector3d p = camera.project(pivot, kWidth, kHeight);
    const double r = at.x() - p.x();
    const ToolOutcome bent = drag(tools, context, {at.head<2>(), Eigen::Vector2d(p.x(), p.y() - r)});
    ASSERT_TRUE(bent.deform);
    EXPECT_TRUE(bent.deform_finished);
    EXPECT_EQ(bent.deform->motion.kind, HandleMotion::Kind::Bend);
    EXPECT_LT((bent.deform->motion.axis_point - pivot).norm(), 1e-12);
    EXPECT_NEAR(bent.deform->motion.angle, std::numbers::pi / 2, 1e-6);
    // The grab point goes to the cursor: (0.5, 0) about (-0.5, 0) by a quarter turn is (-0.5, 1).
    EXPECT_LT((bent.deform->motion.apply(grabbed, 1) - Eigen::Vector3d(-0.5, 1, 0)).norm(), 1e-6);

    tools.set_tool(Tool::Twist, context);
    const ToolOutcome twisted = drag(tools, context, {at.head<2>(), at.head<2>() + Eigen::Vector2d(50, 7)});
    ASSERT_TRUE(twisted.deform);
    EXPECT_EQ(twisted.deform->motion.kind, HandleMotion::Kind::Twist);
    // The turn at the grab point (distance 1 from the pivot along the axis) is 50 px of drag.
    EXPECT_NEAR(twisted.deform->motion.angle * (grabbed - pivot).norm(), 50 * ViewportTools::kTwistRadiansPerPixel, 1e-12);
    EXPECT_LT((twisted.deform->motion.apply(grabbed, 1) - grabbed).norm(), 1e-12);  // on the axis
}

TEST(ViewportTools, PinPlacesPinsAlongADragHalfARadiusApart) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    context.deform_radius = 0.4;
    context.pick_piece = [&](const Eigen::Vector2d& pixel) {
        return std::optional<PieceHit>(PieceHit{0, Eigen::Vector3d(pixel.x() / 100, 0, 0)});
    };
    ViewportTools tools;
    tools.set_tool(Tool::Pin, context);
    std::vector<PinSphere> placed;
    const ToolOutcome first = tools.pointer(event(PointerAction::Press, 0, 150, PointerButton::Left), context);
    ASSERT_TRUE(first.pin);
    EXPECT_EQ(first.pin->radius, 0.2);
    placed.push_back(*first.pin);
    for (int x = 1; x <= 40; ++x)
        if (const auto out = tools.pointer(event(PointerAction::Move, x, 150), context); out.pin) placed.push_back(*out.pin);
    tools.pointer(event(PointerAction::Release, 40, 150, PointerButton::Left), context);
    // Points 0 .. 0.4 apart by 0.01: a pin at the first point at least 0.1 (half the pin radius) from
    // the previous one.
    ASSERT_GE(placed.size(), 4u);
    for (size_t i = 1; i < placed.size(); ++i) {
        const double gap = (placed[i].center - placed[i - 1].center).norm();
        EXPECT_GE(gap, 0.1 - 1e-12);
        EXPECT_LT(gap, 0.11 + 1e-12);
    }
}

TEST(ViewportTools, LightDragTurnsADirectionalLightLikeATrackball) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    std::vector<Light> lights(2);
    lights[1].type = LightType::Directional;
    lights[1].vector = -camera.eye_direction();  // comes from the viewer
    context.lights = &lights;
    context.selected_light = 1;
    ViewportTools tools;
    tools.set_tool(Tool::Light, context);
    const Light untouched = lights[0];
    // Drag from the centre 60 px right: the light's source (opposite to its travel) follows the
    // trackball point under the cursor towards the right.
    tools.pointer(event(PointerAction::Press, 200, 150, PointerButton::Left), context);
    const ToolOutcome out = tools.pointer(event(PointerAction::Move, 260, 150), context);
    EXPECT_TRUE(out.light_changed);
    const Eigen::Vector3d source = -lights[1].vector;
    const double radius = 0.5 * std::min(kWidth, kHeight);
    const double expected_angle = std::asin(60 / radius);
    EXPECT_NEAR(std::atan2(source.dot(camera.right_axis()), source.dot(camera.eye_direction())), expected_angle, 1e-9);
    EXPECT_NEAR(source.dot(camera.up_axis()), 0, 1e-9);
    EXPECT_NEAR(lights[1].vector.norm(), 1, 1e-12);
    // Dragging up instead raises the source.
    tools.pointer(event(PointerAction::Move, 200, 100), context);
    EXPECT_GT((-lights[1].vector).dot(camera.up_axis()), 0.1);
    EXPECT_NEAR((-lights[1].vector).dot(camera.right_axis()), 0, 1e-9);
    tools.pointer(event(PointerAction::Release, 200, 100, PointerButton::Left), context);
    EXPECT_EQ(lights[0].vector, untouched.vector);  // only the selected light moves
}

TEST(ViewportTools, LightDragMovesAPointLightUnderTheCursorAndEscapePutsItBack) {
    OrbitCamera camera = test_camera();
    ViewportContext context = context_for(camera);
    std::vector<Light> lights(1);
    lights[0].type = LightType::Point;
    lights[0].vector = Eigen::Vector3d(0.5, 1.5, 0.8);
    const Eigen::Vector3d start = lights[0].vector;
    context.lights = &lights;
    ViewportTools tools;
    tools.set_tool(Tool::Light, context);
    const Eigen::Vector3d at = camera.project(start, kWidth, kHeight);
    tools.pointer(event(PointerAction::Press, at.x(), at.y(), PointerButton::Left), context);
    tools.pointer(event(PointerAction::Move, at.x() - 30, at.y() + 45), context);
    const Eigen::Vector3d seen = camera.project(lights[0].vector, kWidth, kHeight);
    EXPECT_NEAR(seen.x(), at.x() - 30, 1e-6);
    EXPECT_NEAR(seen.y(), at.y() + 45, 1e-6);
    EXPECT_NEAR(seen.z(), at.z(), 1e-9);  // same depth
    EXPECT_TRUE(tools.cancel(context));
    EXPECT_EQ(lights[0].vector, start);
}

TEST(ViewportTools, WithoutACameraEventsAreIgnored) {
    ViewportTools tools;
    ViewportContext context;
    tools.set_tool(Tool::Cut, context);
    EXPECT_FALSE(tools.pointer(event(PointerAction::Press, 10, 10, PointerButton::Left), context).handled());
    EXPECT_FALSE(tools.active());
}

TEST(ViewportTools, EveryToolHasAScriptIdAndAHint) {
    for (const ToolInfo& info : tool_infos()) {
        EXPECT_NE(std::string(info.id), "");
        EXPECT_NE(std::string(tool_hint(info.tool)), "");
    }
    EXPECT_FALSE(control_lines().empty());
}

}  // namespace
}  // namespace waxwork
