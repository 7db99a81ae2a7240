#include "render/camera.h"

#include "base/error.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace waxwork {

bool up_orients_view(const Eigen::Vector3d& eye_direction, const Eigen::Vector3d& up) {
    if (!eye_direction.allFinite() || !up.allFinite()) return false;
    if (eye_direction.cwiseAbs().maxCoeff() == 0 || up.cwiseAbs().maxCoeff() == 0) return false;
    // Only the directions count: stableNormalized scales before squaring, so a vector of 1e308 (or
    // 1e-300) is a direction like any other instead of overflowing (or underflowing) its norm.
    return eye_direction.stableNormalized().cross(up.stableNormalized()).norm() >= 1e-9;
}

CameraFrame look_at_frame(const Eigen::Vector3d& target, const Eigen::Vector3d& eye_direction,
                          const Eigen::Vector3d& up_hint, double distance, double radius, double fov_y_degrees,
                          double aspect) {
    if (!target.allFinite() || !std::isfinite(distance) || !(distance > 0) || !std::isfinite(radius) || !(radius > 0)) {
        throw InvalidArgumentError("camera: target, distance and radius must be finite, distance and radius positive");
    }
    if (!eye_direction.allFinite() || eye_direction.cwiseAbs().maxCoeff() == 0) {
        throw InvalidArgumentError("camera: eye direction must be finite and non-zero");
    }
    if (!(fov_y_degrees > 0 && fov_y_degrees < 180)) {
        throw InvalidArgumentError("camera: vertical field of view must be in (0, 180) degrees");
    }
    if (!(aspect > 0) || !std::isfinite(aspect)) throw InvalidArgumentError("camera: aspect ratio must be positive");
    if (!up_orients_view(eye_direction, up_hint))
        throw InvalidArgumentError("camera: up vector is zero or parallel to the view direction");
    const Eigen::Vector3d forward = -eye_direction.stableNormalized();  // eye -> target
    const Eigen::Vector3d right = forward.cross(up_hint.stableNormalized()).normalized();
    const Eigen::Vector3d up = right.cross(forward);

    CameraFrame frame;
    frame.eye = target - distance * forward;
    frame.view.setIdentity();
    frame.view.block<1, 3>(0, 0) = right.transpose();
    frame.view.block<1, 3>(1, 0) = up.transpose();
    frame.view.block<1, 3>(2, 0) = -forward.transpose();
    frame.view.block<3, 1>(0, 3) = -frame.view.block<3, 3>(0, 0) * frame.eye;

    // The sphere lies within [distance - radius, distance + radius] in front of the eye.
    const double half_fov_y = 0.5 * fov_y_degrees * std::numbers::pi / 180.0;
    const double near_plane = std::max(distance - 1.5 * radius, 1e-3 * distance);
    const double far_plane = distance + 1.5 * radius;
    const double f = 1.0 / std::tan(half_fov_y);
    frame.projection.setZero();
    frame.projection(0, 0) = f / aspect;
    frame.projection(1, 1) = f;
    frame.projection(2, 2) = (far_plane + near_plane) / (near_plane - far_plane);
    frame.projection(2, 3) = 2 * far_plane * near_plane / (near_plane - far_plane);
    frame.projection(3, 2) = -1;
    return frame;
}

double framing_distance(double radius, double fov_y_degrees, double aspect, double margin) {
    const double half_fov_y = 0.5 * fov_y_degrees * std::numbers::pi / 180.0;
    const double half_fov_x = std::atan(std::tan(half_fov_y) * aspect);
    return margin * radius / std::sin(std::min(half_fov_x, half_fov_y));
}

double bounding_radius(const Eigen::AlignedBox3d& box) { return std::max(0.5 * box.diagonal().norm(), 1e-12); }

CameraFrame frame_camera(const Eigen::AlignedBox3d& box, const CameraSettings& camera, double aspect) {
    if (box.isEmpty() || !box.min().allFinite() || !box.max().allFinite()) {
        throw InvalidArgumentError("camera: empty or non-finite bounding box");
    }
    if (!(camera.fov_y_degrees > 0 && camera.fov_y_degrees < 180)) {
        throw InvalidArgumentError("camera: vertical field of view must be in (0, 180) degrees");
    }
    if (!(aspect > 0) || !std::isfinite(aspect) || !(camera.margin > 0)) {
        throw InvalidArgumentError("camera: aspect ratio and margin must be positive");
    }
    const double radius = bounding_radius(box);
    if (!camera.target_offset.allFinite()) throw InvalidArgumentError("camera: target offset must be finite");
    return look_at_frame(box.center() + camera.target_offset, camera.eye_direction, camera.up,
                         framing_distance(radius, camera.fov_y_degrees, aspect, camera.margin),
                         radius + camera.target_offset.norm(), camera.fov_y_degrees, aspect);
}

}  // namespace waxwork
