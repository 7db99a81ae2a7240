#include "tetops/cut.h"

#include "base/error.h"
#include "tetops/vertex_map.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace waxwork {

double CuttingSurface::step_to_surface(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const {
    if (side(to) >= 0) return 1.0;
    if (side(from) < 0) return 0.0;
    // Bisection keeps the invariant side(from + lo d) >= 0, so the answer is never on the kept side;
    // 60 halvings reach the resolution of a double on [0, 1].
    double lo = 0.0, hi = 1.0;
    const Eigen::Vector3d d = to - from;
    for (int i = 0; i < 60 && hi - lo > 0; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (side(from + mid * d) >= 0) lo = mid; else hi = mid;
    }
    return lo;
}

std::string plane_problem(const Eigen::Vector3d& normal, double offset) {
    if (!normal.allFinite() || !std::isfinite(offset)) return "normal and offset must be finite numbers";
    const double length = normal.stableNorm();  // no overflow for huge components (1e300)
    if (!(length > 0) || !std::isfinite(length)) return "the normal must not be the zero vector";
    return "";
}

PlaneCut::PlaneCut(const Eigen::Vector3d& normal, double offset) {
    const std::string problem = plane_problem(normal, offset);
    if (!problem.empty()) throw InvalidArgumentError("cutting plane: " + problem);
    const double length = normal.stableNorm();
    normal_ = normal / length;
    offset_ = offset / length;
}

double PlaneCut::side(const Eigen::Vector3d& p) const { return normal_.dot(p) - offset_; }

double PlaneCut::step_to_surface(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const {
    const double s_from = side(from);
    const double s_to = side(to);
    if (s_to >= 0) return 1.0;
    if (s_from <= 0) return 0.0;
    double t = s_from / (s_from - s_to);
    // The closed form may land a rounding error on the kept side; step back by ulps until it does
    // not (by a relative amount that doubles each time), so relaxation can promise that no vertex
    // ever crosses the plane.
    const Eigen::Vector3d d = to - from;
    for (int i = 0; i < 50 && t > 0 && side(from + t * d) < 0; ++i) t *= 1.0 - std::ldexp(1.0, i - 52);
    return side(from + t * d) < 0 ? 0.0 : t;
}

StrokeCut::StrokeCut(const Eigen::Vector3d& eye, const Eigen::Vector3d& view_direction,
                     std::vector<Eigen::Vector3d> stroke_points, bool flip)
    : eye_(eye), sign_(flip ? -1.0 : 1.0) {
    if (!eye.allFinite() || !view_direction.allFinite())
        throw InvalidArgumentError("stroke cut: eye and view direction must be finite");
    if (!(view_direction.norm() > 0)) throw InvalidArgumentError("stroke cut: zero view direction");
    view_ = view_direction.normalized();
    if (stroke_points.empty()) throw InvalidArgumentError("stroke cut: the stroke has no points");
    for (const Eigen::Vector3d& p : stroke_points) {
        if (!p.allFinite()) throw InvalidArgumentError("stroke cut: non-finite stroke point");
        if (!((p - eye_).dot(view_) > 0))
            throw InvalidArgumentError("stroke cut: a stroke point is not in front of the eye");
    }
    screen_depth_ = (stroke_points.front() - eye_).dot(view_);
    for (const Eigen::Vector3d& p : stroke_points) {
        const Eigen::Vector3d w = p - eye_;
        const Eigen::Vector3d projected = eye_ + w * (screen_depth_ / w.dot(view_));
        // Repeated points (a mouse that did not move) would make zero-length segments.
        if (points_.empty() || (projected - points_.back()).norm() > 1e-12 * screen_depth_)
            points_.push_back(projected);
    }
    if (points_.size() < 2) throw InvalidArgumentError("stroke cut: the stroke needs two distinct points");
}

double StrokeCut::side(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d w = x - eye_;
    const double depth = w.dot(view_);
    if (!(depth > 0)) return -std::numeric_limits<double>::max();
    const Eigen::Vector3d p = eye_ + w * (screen_depth_ / depth);
    const size_t segments = points_.size() - 1;
    auto left_normal = [&](size_t i) {
        // On screen, left of the direction s is s x view (right x up = towards the viewer = -view).
        return Eigen::Vector3d((points_[i + 1] - points_[i]).cross(view_).normalized());
    };
    double best_distance = std::numeric_limits<double>::infinity();
    double best_value = 0;
    for (size_t i = 0; i < segments; ++i) {
        const Eigen::Vector3d& a = points_[i];
        const Eigen::Vector3d d = points_[i + 1] - a;
        double t = (p - a).dot(d) / d.squaredNorm();
        // The end segments extend to infinity so the surface splits the whole screen.
        const double lo = i == 0 ? -std::numeric_limits<double>::infinity() : 0.0;
        const double hi = i + 1 == segments ? std::numeric_limits<double>::infinity() : 1.0;
        t = std::clamp(t, lo, hi);
        const Eigen::Vector3d q = a + t * d;
        const double distance = (p - q).squaredNorm();
        if (distance >= best_distance) continue;
        best_distance = distance;
        // At a shared corner the pseudo-normal (sum of both segments' normals) gives the right side
        // for points in the corner's wedge, where either segment's normal alone could be wrong.
        Eigen::Vector3d normal = left_normal(i);
        if (t == 0.0 && i > 0) normal += left_normal(i - 1);
        if (t == 1.0 && i + 1 < segments) normal += left_normal(i + 1);
        best_value = normal.normalized().dot(p - q);
        if (t != 0.0 && t != 1.0) best_value = left_normal(i).dot(p - a);
    }
    // Scale the screen-plane distance back to the point's depth: close to a world distance.
    return sign_ * best_value * (depth / screen_depth_);
}

std::vector<Eigen::Vector3d> world_positions(const TetMesh& mesh) {
    std::vector<Eigen::Vector3d> world = mesh.positions;
    if (mesh.piece_ids.empty() || mesh.piece_transforms.empty()) return world;
    const std::vector<int32_t> vertex_piece = vertex_pieces(mesh);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, world.size(), 4096), [&](const auto& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) {
            const int32_t piece = vertex_piece[v];
            if (piece < 0 || static_cast<size_t>(piece) >= mesh.piece_transforms.size()) continue;
            const RigidTransform& motion = mesh.piece_transforms[piece];
            world[v] = motion.rotation * mesh.positions[v] + motion.translation;
        }
    });
    return world;
}

void require_tets_left_by_cut(const TetMesh& after, size_t tets_before) {
    if (after.tet_count() == 0 && tets_before > 0)
        throw InvalidArgumentError("the cut removes all " + std::to_string(tets_before) +
                                   " tets: nothing would be left (a plane cuts away the side its normal points "
                                   "to, a stroke the side on its left; flip it to keep that side)");
}

CutResult remove_cut_away_tets(TetMesh& mesh, const CuttingSurface& surface) {
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    std::vector<uint8_t> cut_away(mesh.vertex_count());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, world.size(), 4096), [&](const auto& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) cut_away[v] = surface.cuts_away(world[v]);
    });

    std::vector<uint8_t> remove(mesh.tet_count());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.tet_count(), 4096), [&](const auto& range) {
        for (size_t t = range.begin(); t != range.end(); ++t) {
            const Tet& tet = mesh.tets[t];
            remove[t] = cut_away[tet[0]] && cut_away[tet[1]] && cut_away[tet[2]] && cut_away[tet[3]];
        }
    });
    return remove_tets(mesh, remove);
}

CutResult remove_tets(TetMesh& mesh, const std::vector<uint8_t>& remove) {
    CutResult result;
    const size_t tet_count = mesh.tet_count();
    if (remove.size() != tet_count)
        throw InvalidArgumentError("remove_tets: one flag per tet expected, got " + std::to_string(remove.size()) +
                                   " for " + std::to_string(tet_count) + " tets");
    // Compaction is a single ordered pass: at 500K tets it costs a few milliseconds, less than
    // the bookkeeping a parallel prefix sum would need on two cores.
    std::vector<uint8_t> vertex_used(mesh.vertex_count(), 0);
    result.new_to_old_tet.reserve(tet_count);
    for (size_t t = 0; t < tet_count; ++t) {
        const Tet& tet = mesh.tets[t];
        if (remove[t]) continue;
        result.new_to_old_tet.push_back(static_cast<int32_t>(t));
        for (int32_t v : tet) vertex_used[v] = 1;
    }
    result.tets_removed = tet_count - result.new_to_old_tet.size();

    result.old_to_new_vertex.assign(mesh.vertex_count(), -1);
    int32_t next_vertex = 0;
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        if (!vertex_used[v]) continue;
        result.old_to_new_vertex[v] = next_vertex;
        mesh.positions[next_vertex] = mesh.positions[v];
        ++next_vertex;
    }
    result.vertices_removed = mesh.vertex_count() - static_cast<size_t>(next_vertex);
    mesh.positions.resize(next_vertex);

    // Old index >= new index throughout, so every per-tet array compacts in place.
    const bool has_materials = mesh.materials.size() == tet_count;
    const bool has_original_ids = mesh.original_ids.size() == tet_count;
    const bool has_piece_ids = mesh.piece_ids.size() == tet_count;
    for (size_t n = 0; n < result.new_to_old_tet.size(); ++n) {
        const size_t old = result.new_to_old_tet[n];
        Tet tet = mesh.tets[old];
        for (int32_t& v : tet) v = result.old_to_new_vertex[v];
        mesh.tets[n] = tet;
        if (has_materials) mesh.materials[n] = mesh.materials[old];
        if (has_original_ids) mesh.original_ids[n] = mesh.original_ids[old];
        if (has_piece_ids) mesh.piece_ids[n] = mesh.piece_ids[old];
    }
    const size_t kept = result.new_to_old_tet.size();
    mesh.tets.resize(kept);
    if (has_materials) mesh.materials.resize(kept);
    if (has_original_ids) mesh.original_ids.resize(kept);
    if (has_piece_ids) mesh.piece_ids.resize(kept);
    return result;
}

}  // namespace waxwork
