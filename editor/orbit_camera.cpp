#include "editor/orbit_camera.h"

#include "base/error.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace waxwork {

OrbitCamera::OrbitCamera(const Eigen::AlignedBox3d& box, const CameraSettings& settings, double aspect) {
    // frame_camera validates the box, direction, up vector, field of view, aspect and margin.
    const CameraFrame check = frame_camera(box, settings, aspect);
    centre_ = box.center();
    target_ = centre_ + settings.target_offset;
    radius_ = bounding_radius(box);
    eye_direction_ = settings.eye_direction.stableNormalized();
    up_ = settings.up.normalized();
    fov_y_degrees_ = settings.fov_y_degrees;
    distance_ = (check.eye - target_).norm();
}

CameraFrame OrbitCamera::frame(double aspect) const {
    return look_at_frame(target_, eye_direction_, up_, distance_, radius_ + (target_ - centre_).norm(), fov_y_degrees_,
                         aspect);
}

CameraSettings OrbitCamera::settings(double aspect) const {
    CameraSettings s;
    s.eye_direction = eye_direction_;
    s.up = up_;
    s.fov_y_degrees = fov_y_degrees_;
    // framing_distance is proportional to the margin.
    s.margin = distance_ / framing_distance(radius_, fov_y_degrees_, aspect, 1.0);
    s.target_offset = target_ - centre_;
    return s;
}

CameraSettings OrbitCamera::settings(double aspect, const Eigen::AlignedBox3d& box) const {
    if (box.isEmpty()) return settings(aspect);
    CameraSettings s = settings(aspect);
    s.margin = distance_ / framing_distance(bounding_radius(box), fov_y_degrees_, aspect, 1.0);
    s.target_offset = target_ - box.center();
    return s;
}

Eigen::Vector3d OrbitCamera::right_axis() const { return (-eye_direction_).cross(up_).normalized(); }

Eigen::Vector3d OrbitCamera::up_axis() const { return right_axis().cross(-eye_direction_); }

void OrbitCamera::orbit(double yaw, double pitch) {
    if (!std::isfinite(yaw) || !std::isfinite(pitch)) return;
    eye_direction_ = (Eigen::AngleAxisd(yaw, up_) * eye_direction_).normalized();
    // Angle between the eye direction and up: pitch moves the eye towards up (smaller angle).
    const double angle = std::acos(std::clamp(eye_direction_.dot(up_), -1.0, 1.0));
    const double target_angle = std::clamp(angle - pitch, kMinPoleAngle, std::numbers::pi - kMinPoleAngle);
    // A positive rotation about the right axis (forward x up) turns the eye direction away from up.
    eye_direction_ = (Eigen::AngleAxisd(target_angle - angle, right_axis()) * eye_direction_).normalized();
}

void OrbitCamera::pan(double dx, double dy, double viewport_height) {
    if (!(viewport_height > 0) || !std::isfinite(dx) || !std::isfinite(dy)) return;
    // At the target's depth one pixel spans 2 d tan(fov/2) / height world units.
    const double half_fov = 0.5 * fov_y_degrees_ * std::numbers::pi / 180.0;
    const double units_per_pixel = 2 * distance_ * std::tan(half_fov) / viewport_height;
    target_ += units_per_pixel * (-dx * right_axis() + dy * up_axis());
}

void OrbitCamera::zoom(double factor) {
    if (!(factor > 0) || !std::isfinite(factor)) return;
    distance_ = std::clamp(distance_ * factor, 1e-3 * radius_, 1e3 * radius_);
}

Ray OrbitCamera::unproject(const Eigen::Vector2d& pixel, double viewport_width, double viewport_height) const {
    const CameraFrame f = frame(viewport_width / viewport_height);
    const Eigen::Matrix4d inverse = (f.projection * f.view).inverse();
    const double x = 2 * pixel.x() / viewport_width - 1;
    const double y = 1 - 2 * pixel.y() / viewport_height;
    const Eigen::Vector4d near_point = inverse * Eigen::Vector4d(x, y, -1, 1);
    const Eigen::Vector4d far_point = inverse * Eigen::Vector4d(x, y, 1, 1);
    const Eigen::Vector3d a = near_point.head<3>() / near_point.w();
    const Eigen::Vector3d b = far_point.head<3>() / far_point.w();
    return Ray{f.eye, (b - a).normalized()};
}

Eigen::Vector3d OrbitCamera::project(const Eigen::Vector3d& point, double viewport_width,
                                     double viewport_height) const {
    const CameraFrame f = frame(viewport_width / viewport_height);
    const Eigen::Vector4d clip = f.projection * f.view * point.homogeneous();
    const Eigen::Vector3d ndc = clip.head<3>() / clip.w();
    return {(ndc.x() + 1) * 0.5 * viewport_width, (1 - ndc.y()) * 0.5 * viewport_height, 0.5 * (ndc.z() + 1)};
}

}  // namespace waxwork
