#include "tetops/sharp_tips.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <unordered_map>
#include <vector>

namespace waxwork {

// Written here rather than taken from CGAL: PMP::detect_sharp_edges marks the same edges (this uses
// its test, on the angle between the face normals) but says nothing of the angles between them, and
// it needs the surface as a CGAL mesh where this needs one pass over the triangles.
std::vector<SharpTip> sharp_tips(const TriangleSurface& surface, double sharp_edge_angle_deg) {
    const auto& points = surface.points;
    std::vector<Eigen::Vector3d> normals(surface.triangles.size());
    for (size_t t = 0; t < surface.triangles.size(); ++t) {
        const auto& tri = surface.triangles[t];
        normals[t] = (points[tri[1]] - points[tri[0]]).cross(points[tri[2]] - points[tri[0]]);
    }
    // The two triangles of each undirected edge, keyed by (low, high) vertex.
    auto key = [](int32_t a, int32_t b) {
        return (static_cast<uint64_t>(std::min(a, b)) << 32) | static_cast<uint32_t>(std::max(a, b));
    };
    std::unordered_map<uint64_t, std::array<int32_t, 2>> edge_faces;
    edge_faces.reserve(surface.triangles.size() * 3 / 2);
    for (size_t t = 0; t < surface.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) {
            auto [it, inserted] = edge_faces.try_emplace(key(surface.triangles[t][k], surface.triangles[t][(k + 1) % 3]),
                                                         std::array<int32_t, 2>{static_cast<int32_t>(t), -1});
            if (!inserted) it->second[1] = static_cast<int32_t>(t);
        }
    const double cos_bound = std::cos(sharp_edge_angle_deg * std::numbers::pi / 180);
    std::vector<std::vector<int32_t>> sharp_neighbours(points.size());
    for (const auto& [edge, faces] : edge_faces) {
        if (faces[1] < 0) continue;
        const Eigen::Vector3d& n1 = normals[faces[0]];
        const Eigen::Vector3d& n2 = normals[faces[1]];
        const double norms = n1.norm() * n2.norm();
        if (!(norms > 0) || n1.dot(n2) > cos_bound * norms) continue;
        const auto a = static_cast<int32_t>(edge >> 32), b = static_cast<int32_t>(edge & 0xffffffffu);
        sharp_neighbours[a].push_back(b);
        sharp_neighbours[b].push_back(a);
    }
    std::vector<SharpTip> tips;
    for (size_t v = 0; v < points.size(); ++v) {
        const auto& ends = sharp_neighbours[v];
        if (ends.size() < 2) continue;
        SharpTip tip{static_cast<int32_t>(v), 180.0, 0.0};
        for (size_t i = 0; i < ends.size(); ++i)
            for (size_t j = i + 1; j < ends.size(); ++j) {
                const Eigen::Vector3d a = points[ends[i]] - points[v], b = points[ends[j]] - points[v];
                // atan2 of |a x b| and a.b keeps small angles accurate (acos of the cosine does not).
                const double angle = std::atan2(a.cross(b).norm(), a.dot(b)) * 180 / std::numbers::pi;
                if (angle < tip.angle_deg) tip.angle_deg = angle, tip.shorter_edge = std::min(a.norm(), b.norm());
            }
        tips.push_back(tip);
    }
    return tips;
}

double sharp_tip_work(const SharpTip& tip, double edge) {
    return std::log1p(tip.shorter_edge / edge) / (tip.angle_deg * std::numbers::pi / 180);
}

}  // namespace waxwork
