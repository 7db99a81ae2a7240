#include "editor/stroke_tools.h"
#include "tetops/cut.h"

#include <gtest/gtest.h>

#include <cmath>

namespace waxwork {
namespace {

Eigen::AlignedBox3d unit_box() { return Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)); }

OrbitCamera front_camera() {
    CameraSettings settings;
    settings.eye_direction = Eigen::Vector3d(0, 0, 1);  // looking down -z
    return OrbitCamera(unit_box(), settings, 1.0);
}

TEST(StrokeTools, SimplifyKeepsSpacingAndTheEndPoint) {
    const ScreenStroke stroke = {{0, 0}, {1, 0}, {2, 0}, {10, 0}, {11, 0}, {20, 0}, {21, 0}};
    const ScreenStroke kept = simplify_stroke(stroke, 5);
    // 0 and 10 kept, 20 kept then replaced by the end point 21 (closer than the spacing to it).
    ASSERT_EQ(kept.size(), 3u);
    EXPECT_EQ(kept.front(), (std::array<float, 2>{0, 0}));
    EXPECT_EQ(kept[1], (std::array<float, 2>{10, 0}));
    EXPECT_EQ(kept.back(), (std::array<float, 2>{21, 0}));
    // A click without movement stays one point; a short drag two.
    EXPECT_EQ(simplify_stroke({{3, 3}, {3, 3}}, 5).size(), 1u);
    EXPECT_EQ(simplify_stroke({{3, 3}, {4, 3}}, 5).size(), 2u);
    EXPECT_TRUE(simplify_stroke({}, 5).empty());
}

TEST(StrokeTools, TargetPlanePointsProjectBackToTheStroke) {
    OrbitCamera camera = front_camera();
    camera.orbit(0.3, 0.2);
    const ScreenStroke stroke = {{100, 50}, {150, 120}, {60, 180}};
    const auto points = stroke_on_target_plane(camera, stroke, 200, 200);
    ASSERT_EQ(points.size(), stroke.size());
    for (size_t i = 0; i < points.size(); ++i) {
        const Eigen::Vector3d p = camera.project(points[i], 200, 200);
        EXPECT_NEAR(p.x(), stroke[i][0], 1e-6);
        EXPECT_NEAR(p.y(), stroke[i][1], 1e-6);
        // On the plane through the target perpendicular to the view.
        EXPECT_NEAR((points[i] - camera.target()).dot(camera.eye_direction()), 0, 1e-9);
    }
}

TEST(StrokeTools, AVerticalStrokeDownTheMiddleCutsAwayTheLeftHalfAsSeen) {
    const OrbitCamera camera = front_camera();
    // Drawn top to bottom through the centre of a 200 x 200 viewport.
    const ScreenStroke stroke = {{100, 10}, {100, 190}};
    const StrokeCut cut(camera.eye(), -camera.eye_direction(), stroke_on_target_plane(camera, stroke, 200, 200));
    // Seen from +z with y up, image right is +x. Moving down the screen, the viewer's left is image
    // right (+x)... the paper's convention, the left of the stroke direction, is decided by StrokeCut;
    // here the two halves must simply land on opposite sides, and points on the stroke on neither.
    const double left = cut.side(Eigen::Vector3d(-0.5, 0, 0));
    const double right = cut.side(Eigen::Vector3d(0.5, 0, 0));
    EXPECT_LT(left * right, 0);
    // Drawing the same stroke upwards swaps the sides.
    const ScreenStroke reversed = {{100, 190}, {100, 10}};
    const StrokeCut back(camera.eye(), -camera.eye_direction(), stroke_on_target_plane(camera, reversed, 200, 200));
    EXPECT_LT(back.side(Eigen::Vector3d(-0.5, 0, 0)) * left, 0);
}

TEST(StrokeTools, FirstHitFindsTheNearestSurface) {
    // Two parallel squares at z = 0.5 and z = -0.5; the ray from +z meets the front one first.
    const std::vector<Eigen::Vector3f> points = {{-1, -1, 0.5f}, {1, -1, 0.5f},  {1, 1, 0.5f},  {-1, 1, 0.5f},
                                                 {-1, -1, -0.5f}, {1, -1, -0.5f}, {1, 1, -0.5f}, {-1, 1, -0.5f}};
    const std::vector<std::array<int32_t, 3>> triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
    const TriangleBvh bvh(points, triangles);
    const Ray ray{Eigen::Vector3d(0.2, 0.1, 3), Eigen::Vector3d(0, 0, -1)};
    const auto hit = first_hit(bvh, ray, 10);
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(hit->z(), 0.5, 1e-5);
    EXPECT_NEAR(hit->x(), 0.2, 1e-9);
    EXPECT_FALSE(first_hit(bvh, ray, 2).has_value());  // stops short of the front square
    EXPECT_FALSE(first_hit(bvh, Ray{Eigen::Vector3d(3, 0, 3), Eigen::Vector3d(0, 0, -1)}, 10).has_value());
}

TEST(StrokeTools, PaintStrokeLandsOnTheVisibleSurface) {
    const std::vector<Eigen::Vector3f> points = {{-1, -1, 0.25f}, {1, -1, 0.25f}, {1, 1, 0.25f}, {-1, 1, 0.25f}};
    const std::vector<std::array<int32_t, 3>> triangles = {{0, 1, 2}, {0, 2, 3}};
    const TriangleBvh bvh(points, triangles);
    const OrbitCamera camera = front_camera();
    // The middle of the viewport hits the square, the corner misses it.
    const auto on_surface = stroke_on_surface(camera, bvh, {{100, 100}, {110, 95}, {0, 0}}, 200, 200);
    ASSERT_EQ(on_surface.size(), 2u);
    for (const Eigen::Vector3d& p : on_surface) EXPECT_NEAR(p.z(), 0.25, 1e-5);
    EXPECT_NEAR(on_surface[0].x(), 0, 1e-5);
    EXPECT_NEAR(on_surface[0].y(), 0, 1e-5);
}

// The brush cursor lies on the surface under the cursor: on a square facing the camera its rings are
// circles around the cursor of the radii where the Gaussian falls to 1/2 and 1/10; on a tilted square
// they are ellipses squeezed along the tilt, with the square's normal; off the object there is none.
TEST(StrokeTools, BrushCursorRingsLieOnTheSurfaceUnderTheCursor) {
    const std::vector<std::array<int32_t, 3>> triangles = {{0, 1, 2}, {0, 2, 3}};
    const OrbitCamera camera = front_camera();
    const double sigma = 0.1;
    {
        const std::vector<Eigen::Vector3f> facing = {{-1, -1, 0.25f}, {1, -1, 0.25f}, {1, 1, 0.25f}, {-1, 1, 0.25f}};
        const TriangleBvh bvh(facing, triangles);
        const auto cursor = brush_cursor(camera, bvh, Eigen::Vector2d(100, 100), 200, 200, sigma);
        ASSERT_TRUE(cursor.has_value());
        EXPECT_NEAR(cursor->center.z(), 0.25, 1e-5);
        EXPECT_NEAR(cursor->normal.z(), 1.0, 1e-6);
        ASSERT_EQ(cursor->half_strength.size(), static_cast<size_t>(kBrushCursorSegments));
        // The rings' world radii, through the projection of a point that far from the centre.
        const auto pixels_for = [&](double world) {
            return (camera.project(cursor->center + Eigen::Vector3d(world, 0, 0), 200, 200) -
                    camera.project(cursor->center, 200, 200)).head<2>().norm();
        };
        const double half = pixels_for(sigma * std::sqrt(2 * std::log(2.0)));
        const double tenth = pixels_for(sigma * std::sqrt(2 * std::log(10.0)));
        for (int i = 0; i < kBrushCursorSegments; ++i) {
            EXPECT_NEAR((cursor->half_strength[i] - Eigen::Vector2d(100, 100)).norm(), half, 0.02 * half) << i;
            EXPECT_NEAR((cursor->tenth_strength[i] - Eigen::Vector2d(100, 100)).norm(), tenth, 0.02 * tenth) << i;
        }
        EXPECT_FALSE(brush_cursor(camera, bvh, Eigen::Vector2d(1, 1), 200, 200, sigma).has_value());  // misses
    }
    {
        // Tilted 60 degrees about the x axis: seen along z the ring is half as tall as it is wide.
        const float c = 0.5f, s = std::sqrt(3.0f) / 2;
        const std::vector<Eigen::Vector3f> tilted = {{-1, -c, -s}, {1, -c, -s}, {1, c, s}, {-1, c, s}};
        const TriangleBvh bvh(tilted, triangles);
        const auto cursor = brush_cursor(camera, bvh, Eigen::Vector2d(100, 100), 200, 200, sigma);
        ASSERT_TRUE(cursor.has_value());
        EXPECT_NEAR(std::abs(cursor->normal.dot(Eigen::Vector3d(0, -s, c).normalized())), 1.0, 1e-4);
        EXPECT_GT(cursor->normal.z(), 0);  // towards the camera
        double width = 0, height = 0;
        for (const Eigen::Vector2d& p : cursor->tenth_strength) {
            width = std::max(width, std::abs(p.x() - 100));
            height = std::max(height, std::abs(p.y() - 100));
        }
        EXPECT_NEAR(height / width, 0.5, 0.05);
    }
}

TEST(StrokeTools, CutStrokeBecomesAStrokeCutOpFromTheEye) {
    OrbitCamera camera = front_camera();
    camera.orbit(0.2, -0.1);
    const ScreenStroke stroke = {{50, 20}, {120, 180}};
    const auto op = stroke_cut_op(camera, stroke, 200, 200, true, true);
    ASSERT_TRUE(op.has_value());
    EXPECT_TRUE(op->exact);
    EXPECT_TRUE(op->stroke.flip);
    EXPECT_LT((op->stroke.eye - camera.eye()).norm(), 1e-12);
    EXPECT_LT((op->stroke.view_direction + camera.eye_direction()).norm(), 1e-12);
    ASSERT_EQ(op->stroke.points.size(), 2u);
    // The op's surface, built the way Document builds it, splits the object along the stroke: points
    // projecting to either side of it land on opposite sides.
    const StrokeCut cut(op->stroke.eye, op->stroke.view_direction, op->stroke.points, op->stroke.flip);
    const Ray left = camera.unproject(Eigen::Vector2d(40, 150), 200, 200);
    const Ray right = camera.unproject(Eigen::Vector2d(160, 50), 200, 200);
    const double depth = camera.distance();
    EXPECT_LT(cut.side(left.origin + depth * left.direction) * cut.side(right.origin + depth * right.direction), 0);
    // A click is no cut.
    EXPECT_FALSE(stroke_cut_op(camera, {{50, 20}, {50, 20}}, 200, 200, false, false).has_value());
}

TEST(StrokeTools, PaintStrokeBecomesAPaintOpOnTheSurface) {
    const std::vector<Eigen::Vector3f> points = {{-1, -1, 0.25f}, {1, -1, 0.25f}, {1, 1, 0.25f}, {-1, 1, 0.25f}};
    const std::vector<std::array<int32_t, 3>> triangles = {{0, 1, 2}, {0, 2, 3}};
    const TriangleBvh bvh(points, triangles);
    TetMaterial material;
    material.mua = {0.1, 0.2, 0.3};
    material.musp = {1, 1, 1};
    material.eta = 1.4;
    const auto op = paint_op(front_camera(), bvh, {{100, 100}, {105, 100}}, 200, 200, material, 0.07);
    ASSERT_TRUE(op.has_value());
    EXPECT_EQ(op->material, material);
    EXPECT_EQ(op->sigma, 0.07);
    ASSERT_EQ(op->points.size(), 2u);
    EXPECT_NEAR(op->points[0].z(), 0.25, 1e-5);
    EXPECT_FALSE(paint_op(front_camera(), bvh, {{0, 0}}, 200, 200, material, 0.07).has_value());
}

}  // namespace
}  // namespace waxwork
