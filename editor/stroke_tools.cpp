#include "editor/stroke_tools.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace waxwork {

ScreenStroke simplify_stroke(const ScreenStroke& stroke, float min_spacing) {
    ScreenStroke kept;
    for (const auto& p : stroke) {
        if (!std::isfinite(p[0]) || !std::isfinite(p[1])) continue;
        if (!kept.empty() && std::hypot(p[0] - kept.back()[0], p[1] - kept.back()[1]) < min_spacing) continue;
        kept.push_back(p);
    }
    // The end point was dropped for being near the last kept one: let it replace that one (or follow
    // the first point), so the stroke ends where the mouse was released.
    const auto& last = stroke.empty() ? std::array<float, 2>{} : stroke.back();
    if (!kept.empty() && std::isfinite(last[0]) && std::isfinite(last[1]) && last != kept.back()) {
        if (kept.size() > 1) kept.back() = last;
        else kept.push_back(last);
    }
    return kept;
}

std::vector<Eigen::Vector3d> stroke_on_target_plane(const OrbitCamera& camera, const ScreenStroke& stroke,
                                                    double viewport_width, double viewport_height) {
    std::vector<Eigen::Vector3d> points;
    points.reserve(stroke.size());
    const Eigen::Vector3d forward = -camera.eye_direction();
    for (const auto& p : stroke) {
        const Ray ray = camera.unproject(Eigen::Vector2d(p[0], p[1]), viewport_width, viewport_height);
        // The plane forward . x = forward . target, which the ray meets at distance / cos(angle).
        const double cos_angle = ray.direction.dot(forward);
        if (!(cos_angle > 1e-9)) continue;
        points.push_back(ray.origin + (camera.distance() / cos_angle) * ray.direction);
    }
    return points;
}

std::optional<Eigen::Vector3d> first_hit(const TriangleBvh& bvh, const Ray& ray, double max_distance) {
    const Eigen::Vector3f origin = ray.origin.cast<float>();
    const Eigen::Vector3f direction = ray.direction.cast<float>();
    float hi = static_cast<float>(max_distance);
    if (bvh.empty() || !(hi > 0) || !bvh.occluded(origin, direction, 0.0f, hi)) return std::nullopt;
    float lo = 0.0f;  // invariant: (0, lo) misses, (0, hi) hits
    for (int i = 0; i < 24; ++i) {
        const float mid = 0.5f * (lo + hi);
        if (bvh.occluded(origin, direction, 0.0f, mid)) hi = mid;
        else lo = mid;
    }
    return ray.origin + static_cast<double>(0.5f * (lo + hi)) * ray.direction;
}

std::vector<Eigen::Vector3d> stroke_on_surface(const OrbitCamera& camera, const TriangleBvh& bvh,
                                               const ScreenStroke& stroke, double viewport_width,
                                               double viewport_height) {
    std::vector<Eigen::Vector3d> points;
    const double reach = camera.distance() + 4 * camera.scene_radius();
    for (const auto& p : stroke) {
        const Ray ray = camera.unproject(Eigen::Vector2d(p[0], p[1]), viewport_width, viewport_height);
        if (const auto hit = first_hit(bvh, ray, reach)) points.push_back(*hit);
    }
    return points;
}

std::optional<BrushCursor> brush_cursor(const OrbitCamera& camera, const TriangleBvh& bvh, const Eigen::Vector2d& pixel,
                                        double viewport_width, double viewport_height, double sigma) {
    const double reach = camera.distance() + 4 * camera.scene_radius();
    const auto hit_at = [&](const Eigen::Vector2d& p) {
        return first_hit(bvh, camera.unproject(p, viewport_width, viewport_height), reach);
    };
    const std::optional<Eigen::Vector3d> center = hit_at(pixel);
    if (!center) return std::nullopt;
    BrushCursor cursor;
    cursor.center = *center;
    // Three pixels aside: far enough that float hits give a stable plane, near enough to stay on the
    // facet under the cursor at the brush sizes one paints with.
    constexpr double kNormalOffsetPixels = 3;
    const auto right = hit_at(pixel + Eigen::Vector2d(kNormalOffsetPixels, 0));
    const auto down = hit_at(pixel + Eigen::Vector2d(0, kNormalOffsetPixels));
    const Eigen::Vector3d towards_eye = (camera.eye() - *center).normalized();
    Eigen::Vector3d normal = towards_eye;
    if (right && down) {
        const Eigen::Vector3d n = (*right - *center).cross(*down - *center);
        if (n.norm() > 0) normal = n.dot(towards_eye) >= 0 ? n.normalized() : Eigen::Vector3d(-n.normalized());
    }
    cursor.normal = normal;
    const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
    // exp(-r^2 / (2 sigma^2)) = w at r = sigma sqrt(-2 ln w).
    const double half = sigma * std::sqrt(2 * std::log(2.0)), tenth = sigma * std::sqrt(2 * std::log(10.0));
    for (int i = 0; i < kBrushCursorSegments; ++i) {
        const double angle = 2 * std::numbers::pi * i / kBrushCursorSegments;
        const Eigen::Vector3d direction = std::cos(angle) * u + std::sin(angle) * v;
        cursor.half_strength.push_back(camera.project(*center + half * direction, viewport_width, viewport_height).head<2>());
        cursor.tenth_strength.push_back(camera.project(*center + tenth * direction, viewport_width, viewport_height).head<2>());
    }
    return cursor;
}

std::optional<StrokeCutOp> stroke_cut_op(const OrbitCamera& camera, const ScreenStroke& stroke,
                                         double viewport_width, double viewport_height, bool exact, bool flip) {
    StrokeCutOp op;
    op.stroke.eye = camera.eye();
    op.stroke.view_direction = -camera.eye_direction();
    op.stroke.points = stroke_on_target_plane(camera, stroke, viewport_width, viewport_height);
    op.stroke.flip = flip;
    op.exact = exact;
    const auto& p = op.stroke.points;
    const bool distinct = p.size() >= 2 && std::any_of(p.begin() + 1, p.end(), [&](const Eigen::Vector3d& q) {
        return (q - p.front()).norm() > 1e-9 * camera.scene_radius();
    });
    if (!distinct) return std::nullopt;
    return op;
}

std::optional<PaintOp> paint_op(const OrbitCamera& camera, const TriangleBvh& surface, const ScreenStroke& stroke,
                                double viewport_width, double viewport_height, const TetMaterial& material,
                                double sigma) {
    PaintOp op;
    op.points = stroke_on_surface(camera, surface, stroke, viewport_width, viewport_height);
    if (op.points.empty()) return std::nullopt;
    op.material = material;
    op.sigma = sigma;
    return op;
}

}  // namespace waxwork
