#include "base/error.h"
#include "editor/orbit_camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace waxwork {
namespace {

Eigen::AlignedBox3d test_box() { return Eigen::AlignedBox3d(Eigen::Vector3d(-1, 0, -0.5), Eigen::Vector3d(2, 1.5, 0.5)); }

TEST(OrbitCamera, StartsAtTheFrameOfWaxworkRender) {
    const CameraSettings settings;
    const OrbitCamera camera(test_box(), settings, 4.0 / 3.0);
    const CameraFrame expected = frame_camera(test_box(), settings, 4.0 / 3.0);
    const CameraFrame actual = camera.frame(4.0 / 3.0);
    EXPECT_LT((actual.view - expected.view).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((actual.projection - expected.projection).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((actual.eye - expected.eye).norm(), 1e-12);
}

TEST(OrbitCamera, OrbitKeepsTheTargetAndDistance) {
    OrbitCamera camera(test_box(), CameraSettings{}, 1.0);
    const Eigen::Vector3d target = camera.target();
    const double distance = (camera.eye() - target).norm();
    camera.orbit(0.7, 0.3);
    EXPECT_LT((camera.target() - target).norm(), 1e-12);
    EXPECT_NEAR((camera.eye() - target).norm(), distance, 1e-9);
    // The frame's eye is the camera's eye, and the view maps the target onto the -z axis.
    const CameraFrame frame = camera.frame(1.0);
    EXPECT_LT((frame.eye - camera.eye()).norm(), 1e-9);
    const Eigen::Vector4d t = frame.view * target.homogeneous();
    EXPECT_NEAR(t.x(), 0, 1e-9);
    EXPECT_NEAR(t.y(), 0, 1e-9);
    EXPECT_NEAR(t.z(), -distance, 1e-9);
}

TEST(OrbitCamera, YawTurnsAboutUpAndPitchRaisesTheEye) {
    CameraSettings settings;
    settings.eye_direction = Eigen::Vector3d(0, 0, 1);
    OrbitCamera camera(test_box(), settings, 1.0);
    camera.orbit(std::numbers::pi / 2, 0);
    // A quarter turn about +y takes +z to +x.
    EXPECT_LT((camera.eye_direction() - Eigen::Vector3d(1, 0, 0)).norm(), 1e-12);
    camera.orbit(0, 0.4);
    EXPECT_NEAR(camera.eye_direction().y(), std::sin(0.4), 1e-12);
    EXPECT_GT(camera.eye_direction().x(), 0);
}

TEST(OrbitCamera, PitchStopsShortOfThePole) {
    OrbitCamera camera(test_box(), CameraSettings{}, 1.0);
    camera.orbit(0, 10.0);
    const double angle = std::acos(camera.eye_direction().dot(Eigen::Vector3d::UnitY()));
    EXPECT_NEAR(angle, OrbitCamera::kMinPoleAngle, 1e-9);
    camera.orbit(0, -10.0);
    const double below = std::acos(camera.eye_direction().dot(Eigen::Vector3d::UnitY()));
    EXPECT_NEAR(below, std::numbers::pi - OrbitCamera::kMinPoleAngle, 1e-9);
    EXPECT_TRUE(camera.frame(1.0).view.allFinite());
}

TEST(OrbitCamera, PanMovesAPointAtTheTargetDepthWithTheCursor) {
    OrbitCamera camera(test_box(), CameraSettings{}, 1.5);
    const double width = 600, height = 400;
    const Eigen::Vector3d before = camera.project(camera.target(), width, height);
    const Eigen::Vector3d world_target = camera.target();
    camera.pan(25, -10, height);
    // The old target point moved on screen by exactly the drag.
    const Eigen::Vector3d after = camera.project(world_target, width, height);
    EXPECT_NEAR(after.x() - before.x(), 25, 1e-6);
    EXPECT_NEAR(after.y() - before.y(), -10, 1e-6);
    // Panning does not turn the camera.
    EXPECT_LT((camera.eye_direction() - CameraSettings{}.eye_direction.normalized()).norm(), 1e-12);
}

TEST(OrbitCamera, ZoomScalesTheDistanceWithinBounds) {
    OrbitCamera camera(test_box(), CameraSettings{}, 1.0);
    const double d = camera.distance();
    camera.zoom(0.5);
    EXPECT_NEAR(camera.distance(), 0.5 * d, 1e-12);
    camera.zoom(1e-9);
    EXPECT_NEAR(camera.distance(), 1e-3 * camera.scene_radius(), 1e-12);
    camera.zoom(std::nan(""));
    camera.zoom(-2);
    EXPECT_NEAR(camera.distance(), 1e-3 * camera.scene_radius(), 1e-12);
    camera.zoom(1e12);
    EXPECT_NEAR(camera.distance(), 1e3 * camera.scene_radius(), 1e-6);
}

TEST(OrbitCamera, UnprojectedRayPassesThroughTheProjectedPoint) {
    OrbitCamera camera(test_box(), CameraSettings{}, 1.0);
    camera.orbit(-0.4, 0.2);
    camera.pan(13, 7, 300);
    const double width = 640, height = 360;
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.3, 0.9, 0.1), Eigen::Vector3d(-0.8, 0.2, -0.4),
                                     Eigen::Vector3d(1.7, 1.4, 0.45)}) {
        const Eigen::Vector3d pixel = camera.project(p, width, height);
        EXPECT_GT(pixel.z(), 0);
        EXPECT_LT(pixel.z(), 1);
        const Ray ray = camera.unproject(pixel.head<2>(), width, height);
        EXPECT_NEAR(ray.direction.norm(), 1, 1e-12);
        const Eigen::Vector3d to_point = p - ray.origin;
        // Distance from the point to the ray.
        EXPECT_LT((to_point - to_point.dot(ray.direction) * ray.direction).norm(), 1e-9);
        EXPECT_GT(to_point.dot(ray.direction), 0);
    }
    // The centre of the viewport looks at the target.
    const Ray centre = camera.unproject(Eigen::Vector2d(width / 2, height / 2), width, height);
    EXPECT_LT((centre.direction + camera.eye_direction()).norm(), 1e-9);
}

TEST(OrbitCamera, SettingsReproduceThePannedZoomedView) {
    // What a saved session records: frame_camera on those settings must give the editor's current view.
    OrbitCamera camera(test_box(), CameraSettings{}, 1.5);
    camera.orbit(0.6, -0.2);
    camera.pan(40, -25, 400);
    camera.zoom(0.7);
    for (const double aspect : {1.5, 0.8}) {
        const CameraSettings settings = camera.settings(aspect);
        EXPECT_GT(settings.target_offset.norm(), 0);
        const CameraFrame expected = camera.frame(aspect);
        const CameraFrame actual = frame_camera(test_box(), settings, aspect);
        EXPECT_LT((actual.view - expected.view).cwiseAbs().maxCoeff(), 1e-9) << aspect;
        EXPECT_LT((actual.projection - expected.projection).cwiseAbs().maxCoeff(), 1e-9) << aspect;
        // And a camera built from them starts there.
        const OrbitCamera rebuilt(test_box(), settings, aspect);
        EXPECT_LT((rebuilt.eye() - camera.eye()).norm(), 1e-9);
        EXPECT_LT((rebuilt.target() - camera.target()).norm(), 1e-9);
    }
    // For a model whose box changed since (a cut took half): the same eye, target and field of view
    // (the depth range follows the new box, which changes no pixel).
    const Eigen::AlignedBox3d half(test_box().min(), Eigen::Vector3d(test_box().center().x(), test_box().max().y(),
                                                                       test_box().max().z()));
    const CameraFrame expected = camera.frame(1.5);
    const CameraFrame reframed = frame_camera(half, camera.settings(1.5, half), 1.5);
    EXPECT_LT((reframed.view - expected.view).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_NEAR(reframed.projection(0, 0), expected.projection(0, 0), 1e-12);
    EXPECT_NEAR(reframed.projection(1, 1), expected.projection(1, 1), 1e-12);
    // Unpanned and unzoomed: the default settings come back.
    const OrbitCamera fresh(test_box(), CameraSettings{}, 1.5);
    EXPECT_NEAR(fresh.settings(1.5).margin, CameraSettings{}.margin, 1e-12);
    EXPECT_EQ(fresh.settings(1.5).target_offset, Eigen::Vector3d::Zero());
}

TEST(OrbitCamera, DepthRangeKeepsTheSceneAfterPanning) {
    // Panned far to the side, every corner of the box must still lie between the near and far planes.
    OrbitCamera camera(test_box(), CameraSettings{}, 1.0);
    camera.pan(-900, 0, 300);  // three viewport heights: the target far outside the box
    camera.orbit(1.2, 0);      // now the box lies behind or in front of the target along the view
    const Eigen::Vector3d lo = test_box().min(), hi = test_box().max();
    for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d p((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(), (corner & 4) ? hi.z() : lo.z());
        const CameraFrame frame = camera.frame(1.0);
        const Eigen::Vector4d clip = frame.projection * frame.view * p.homogeneous();
        const double depth = clip.z() / clip.w();
        EXPECT_GT(clip.w(), 0) << corner;  // in front of the eye
        EXPECT_GT(depth, -1) << corner;
        EXPECT_LT(depth, 1) << corner;
    }
}

TEST(OrbitCamera, RefusesWhatFrameCameraRefuses) {
    CameraSettings bad;
    bad.eye_direction = Eigen::Vector3d::Zero();
    EXPECT_THROW(OrbitCamera(test_box(), bad, 1.0), InvalidArgumentError);
    EXPECT_THROW(OrbitCamera(Eigen::AlignedBox3d(), CameraSettings{}, 1.0), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
