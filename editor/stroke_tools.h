// From mouse strokes in the viewport to world-space input for the editing operations: the polyline of
// a cut stroke on the camera's near side (tetops/cut.h StrokeCut sweeps it along the view rays) and
// the surface points under a paint stroke (found by casting view rays at the boundary surface).
#pragma once

#include "editor/orbit_camera.h"
#include "scene/edit_operation.h"
#include "solver/ray_caster.h"

#include <Eigen/Core>

#include <array>
#include <optional>
#include <vector>

namespace waxwork {

using ScreenStroke = std::vector<std::array<float, 2>>;  // viewport pixels, origin top-left, y down

// Drops points closer than `min_spacing` pixels to the previously kept one (mouse events arrive far
// denser than a stroke needs); the last point is always kept when it differs from the first.
ScreenStroke simplify_stroke(const ScreenStroke& stroke, float min_spacing);

// The stroke's points in world space, on the plane through the camera's target perpendicular to the
// view direction (in front of the eye, as StrokeCut requires).
std::vector<Eigen::Vector3d> stroke_on_target_plane(const OrbitCamera& camera, const ScreenStroke& stroke,
                                                    double viewport_width, double viewport_height);

// The nearest point where `ray` meets a triangle of `bvh` within `max_distance`, nullopt when it meets
// none. Bisects the BVH's any-hit query on the segment length (24 halvings: a relative precision of
// 6e-8 of max_distance, far below an edge), so no second, first-hit traversal has to be maintained.
std::optional<Eigen::Vector3d> first_hit(const TriangleBvh& bvh, const Ray& ray, double max_distance);

// The surface points under a paint stroke (strokes points that miss the object are skipped).
std::vector<Eigen::Vector3d> stroke_on_surface(const OrbitCamera& camera, const TriangleBvh& bvh,
                                               const ScreenStroke& stroke, double viewport_width,
                                               double viewport_height);

// The cut a stroke draws: swept from the camera's eye along its view rays; the left side of the
// stroke as drawn is cut away, the right with `flip` (Shift in the editor). nullopt for a stroke of
// fewer than two distinct points.
std::optional<StrokeCutOp> stroke_cut_op(const OrbitCamera& camera, const ScreenStroke& stroke,
                                         double viewport_width, double viewport_height, bool exact, bool flip);

// A paint stroke of `material` with Gaussian width `sigma` (world units) through the surface points
// under the stroke; nullopt when the stroke misses the object.
std::optional<PaintOp> paint_op(const OrbitCamera& camera, const TriangleBvh& surface, const ScreenStroke& stroke,
                                double viewport_width, double viewport_height, const TetMaterial& material,
                                double sigma);

}  // namespace waxwork
