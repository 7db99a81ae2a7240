#include "render/turntable.h"

#include "base/error.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

namespace waxwork {

CameraSettings orbit_camera(const CameraSettings& start, int index, int frames, std::optional<double> elevation_degrees) {
    if (frames < 1) throw InvalidArgumentError("turntable: the number of frames must be at least 1");
    if (index < 0 || index >= frames)
        throw InvalidArgumentError("turntable: frame " + std::to_string(index) + " of " + std::to_string(frames));
    if (elevation_degrees && !(std::abs(*elevation_degrees) < 90))
        throw InvalidArgumentError("turntable: the elevation must be between -90 and 90 degrees");
    if (!up_orients_view(start.eye_direction, start.up) && !elevation_degrees)
        throw InvalidArgumentError("turntable: the camera looks along its up vector; give an elevation");
    const Eigen::Vector3d up = start.up.normalized();
    // The start's direction split into its height along the axis and its horizontal part.
    const Eigen::Vector3d eye = start.eye_direction.normalized();
    Eigen::Vector3d horizontal = eye - eye.dot(up) * up;
    if (horizontal.norm() < 1e-9) horizontal = up.unitOrthogonal();  // straight above: any heading
    horizontal.normalize();
    const double elevation = elevation_degrees ? *elevation_degrees * std::numbers::pi / 180
                                               : std::asin(std::clamp(eye.dot(up), -1.0, 1.0));
    const double turn = 2 * std::numbers::pi * index / frames;
    const Eigen::Vector3d heading = Eigen::AngleAxisd(turn, up) * horizontal;
    CameraSettings camera = start;
    camera.eye_direction = std::cos(elevation) * heading + std::sin(elevation) * up;
    return camera;
}

std::string turntable_frame_name(int index) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.png", index);
    return name;
}

}  // namespace waxwork
