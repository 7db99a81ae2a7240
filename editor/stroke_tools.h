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

// The paint brush's footprint under the cursor, for drawing it: where the view ray through `pixel`
// meets the surface (cross-sections included: they are surface too), the surface's normal there
// (from the hits of two rays a few pixels aside; facing the camera where those miss), and two rings
// in that tangent plane, in viewport pixels: where the Gaussian brush (tetops/paint.h) blends at half
// strength and at a tenth. nullopt when the ray misses the object.
struct BrushCursor {
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    std::vector<Eigen::Vector2d> half_strength, tenth_strength;  // closed outlines (first point not repeated)
};
inline constexpr int kBrushCursorSegments = 48;
std::optional<BrushCursor> brush_cursor(const OrbitCamera& camera, const TriangleBvh& bvh, const Eigen::Vector2d& pixel,
                                        double viewport_width, double viewport_height, double sigma);

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
