// The editor's camera: it orbits a target point, pans in the view plane and zooms along the view
// direction. Plain math (no window), so it is unit tested; its matrices come from look_at_frame
// (render/surface_renderer.h), the function `waxwork render` frames its camera with, so the editor's
// first frame shows exactly what `waxwork render` renders.
#pragma once

#include "render/camera.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace waxwork {

struct Ray {
    Eigen::Vector3d origin;
    Eigen::Vector3d direction;  // unit length
};

class OrbitCamera {
public:
    // The pose frame_camera(box, settings, aspect) gives: centred on the box, at its framing distance.
    // Throws InvalidArgumentError for what frame_camera refuses.
    OrbitCamera(const Eigen::AlignedBox3d& box, const CameraSettings& settings, double aspect);

    // View and projection for a viewport of this aspect (width / height). The depth range encloses
    // the scene's bounding sphere wherever panning moved the target.
    CameraFrame frame(double aspect) const;
    // The settings that give this view through frame_camera (`waxwork render`, sessions) for a
    // viewport of this aspect: the zoom as the margin, the pan as the target offset.
    CameraSettings settings(double aspect) const;
    // The same for a model whose bounding box is now `box` (cut, deformed or moved since the camera
    // was made): frame_camera(box, settings(aspect, box), aspect) gives this view again.
    CameraSettings settings(double aspect, const Eigen::AlignedBox3d& box) const;

    // Turns the eye around the target: `yaw` radians about the up vector, then `pitch` radians about
    // the image's right axis (positive: the eye moves up). The pitch stops kMinPoleAngle short of the
    // up vector so the image never flips over the pole.
    void orbit(double yaw, double pitch);
    // Moves the target and eye together by a drag of (dx, dy) pixels (x right, y down) in a viewport
    // `viewport_height` pixels high: a point at the target's depth follows the cursor.
    void pan(double dx, double dy, double viewport_height);
    // Multiplies the eye's distance to the target by `factor` (< 1 zooms in), kept within
    // [1e-3, 1e3] x the scene radius.
    void zoom(double factor);

    // The ray from the eye through a point of the viewport (pixels, origin at the top-left corner,
    // y down; continuous coordinates: (0, 0) is the corner, (w/2, h/2) the centre).
    Ray unproject(const Eigen::Vector2d& pixel, double viewport_width, double viewport_height) const;
    // The viewport position (same convention) of a world point, and its depth in [0, 1] as a depth
    // buffer would hold it. The inverse of unproject.
    Eigen::Vector3d project(const Eigen::Vector3d& point, double viewport_width, double viewport_height) const;

    const Eigen::Vector3d& target() const { return target_; }
    const Eigen::Vector3d& eye_direction() const { return eye_direction_; }
    const Eigen::Vector3d& up() const { return up_; }
    double distance() const { return distance_; }
    double scene_radius() const { return radius_; }
    double fov_y_degrees() const { return fov_y_degrees_; }
    Eigen::Vector3d eye() const { return target_ + distance_ * eye_direction_; }
    // The image's right and up axes in world space.
    Eigen::Vector3d right_axis() const;
    Eigen::Vector3d up_axis() const;

    static constexpr double kMinPoleAngle = 0.02;  // radians

private:
    Eigen::Vector3d centre_;  // of the scene's box
    Eigen::Vector3d target_;
    Eigen::Vector3d eye_direction_;  // unit, target -> eye
    Eigen::Vector3d up_;             // unit
    double distance_;
    double radius_;
    double fov_y_degrees_;
};

}  // namespace waxwork
