// The view: where the eye stands and the matrices it gives. Shared by `waxwork render`, sessions and
// the editor's orbit camera, so every front end frames a volume the same way.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace waxwork {

// Where the camera stands: it looks at the centre of the bounding box from `eye_direction` and backs
// off until the bounding sphere fits the narrower field of view with `margin` to spare.
struct CameraSettings {
    // From the centre towards the eye. The default is a 3/4 view of a y-up model whose front faces +z:
    // from the front right, somewhat above.
    Eigen::Vector3d eye_direction = Eigen::Vector3d(0.7, 0.5, 1.0);
    Eigen::Vector3d up = Eigen::Vector3d(0, 1, 0);
    double fov_y_degrees = 30;
    double margin = 1.1;
    // The point looked at, relative to the box's centre (the editor's pan); world units. The depth
    // range grows by its length so the whole box stays between the near and far planes.
    Eigen::Vector3d target_offset = Eigen::Vector3d::Zero();
};

// Whether `up` can orient a view along `eye_direction`: both finite and non-zero (of any magnitude)
// and not parallel. What look_at_frame requires, for readers to check where the values enter.
bool up_orients_view(const Eigen::Vector3d& eye_direction, const Eigen::Vector3d& up);

struct CameraFrame {
    Eigen::Vector3d eye;
    Eigen::Matrix4d view;
    Eigen::Matrix4d projection;  // OpenGL clip space
};

// Throws InvalidArgumentError for a zero or non-finite direction, an up vector parallel to it, a field
// of view outside (0, 180) degrees, or an empty box.
CameraFrame frame_camera(const Eigen::AlignedBox3d& box, const CameraSettings& camera, double aspect);

// The eye at target + distance * eye_direction (normalised) looking at `target`, `up_hint` giving the
// image's up; near and far planes enclose a sphere of `radius` around the target. frame_camera is this
// with the box's centre and framing distance, and the editor's orbit camera calls it too, so both give
// identical matrices for the same pose (the editor's first frame equals `waxwork render`'s image).
// Throws InvalidArgumentError like frame_camera, and for a non-positive distance or radius.
CameraFrame look_at_frame(const Eigen::Vector3d& target, const Eigen::Vector3d& eye_direction,
                          const Eigen::Vector3d& up_hint, double distance, double radius, double fov_y_degrees,
                          double aspect);

// How far from the centre of a sphere of `radius` the eye stands so the sphere fits the narrower field
// of view with `margin` to spare; and the radius frame_camera uses for a box (half its diagonal).
double framing_distance(double radius, double fov_y_degrees, double aspect, double margin);
double bounding_radius(const Eigen::AlignedBox3d& box);

}  // namespace waxwork
