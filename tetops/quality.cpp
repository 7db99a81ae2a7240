#include "tetops/quality.h"

#include "tetops/connectivity.h"

#include <tbb/parallel_reduce.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace waxwork {

// Cosine of the smallest interior dihedral angle of a tet (the largest cosine over its six edges):
// the same geometry as dihedral_angles_deg without the six arc cosines, so a whole-mesh minimum costs
// one acos instead of six per tet. A degenerate face gives 1 (a zero angle).
double max_dihedral_cosine(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                           const Eigen::Vector3d& p3) {
    const std::array<const Eigen::Vector3d*, 4> p = {&p0, &p1, &p2, &p3};
    std::array<Eigen::Vector3d, 4> normal;
    std::array<double, 4> length;
    for (int k = 0; k < 4; ++k) {
        const auto& f = kTetFaces[k];
        normal[k] = (*p[f[1]] - *p[f[0]]).cross(*p[f[2]] - *p[f[0]]);
        length[k] = normal[k].norm();
        if (!(length[k] > 0)) return 1.0;
    }
    double worst = -1.0;
    // Edge (i, j) is between the faces opposite the other two vertices; interior cosine = -n_k.n_l.
    for (int k = 0; k < 4; ++k)
        for (int l = k + 1; l < 4; ++l) worst = std::max(worst, -normal[k].dot(normal[l]) / (length[k] * length[l]));
    return std::min(worst, 1.0);
}

std::array<double, 6> dihedral_angles_deg(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                          const Eigen::Vector3d& p2, const Eigen::Vector3d& p3) {
    const std::array<const Eigen::Vector3d*, 4> p = {&p0, &p1, &p2, &p3};
    // Outward (for positive orientation) normal of the face opposite each vertex.
    std::array<Eigen::Vector3d, 4> normal;
    for (int k = 0; k < 4; ++k) {
        const auto& f = kTetFaces[k];
        normal[k] = (*p[f[1]] - *p[f[0]]).cross(*p[f[2]] - *p[f[0]]);
    }
    std::array<double, 6> angles{};
    for (int e = 0; e < 6; ++e) {
        // The two faces meeting at edge (i, j) are the ones opposite the other two vertices k, l; the
        // interior dihedral angle is pi minus the angle between their outward normals.
        const int i = kTetEdges[e][0], j = kTetEdges[e][1];
        int k = -1, l = -1;
        for (int m = 0; m < 4; ++m)
            if (m != i && m != j) (k < 0 ? k : l) = m;
        const double denom = normal[k].norm() * normal[l].norm();
        if (!(denom > 0)) {
            angles[e] = 0;  // degenerate face: report a zero angle, the worst possible
            continue;
        }
        const double cosine = std::clamp(normal[k].dot(normal[l]) / denom, -1.0, 1.0);
        angles[e] = 180.0 - std::acos(cosine) * 180.0 / std::numbers::pi;
    }
    return angles;
}

double min_dihedral_angle_deg(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                              const Eigen::Vector3d& p3) {
    // The angle grows with the cosine between the outward normals, so the largest interior cosine
    // gives the smallest angle: one acos instead of dihedral_angles_deg's six (the quality passes of
    // the exact split and of the fracture call this for every candidate move). Same arithmetic as
    // dihedral_angles_deg's smallest angle: 180 degrees minus the angle between outward normals.
    return 180.0 - std::acos(-max_dihedral_cosine(p0, p1, p2, p3)) * 180.0 / std::numbers::pi;
}

double min_dihedral_angle_deg(const TetMesh& mesh, const Tet& tet) {
    return min_dihedral_angle_deg(mesh.positions[tet[0]], mesh.positions[tet[1]], mesh.positions[tet[2]],
                                  mesh.positions[tet[3]]);
}

double radius_edge_ratio(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                         const Eigen::Vector3d& p3) {
    const Eigen::Vector3d a = p1 - p0, b = p2 - p0, c = p3 - p0;
    const double det = 2.0 * a.dot(b.cross(c));
    if (det == 0.0) return std::numeric_limits<double>::infinity();
    const Eigen::Vector3d offset = (a.squaredNorm() * b.cross(c) + b.squaredNorm() * c.cross(a) +
                                    c.squaredNorm() * a.cross(b)) / det;
    const double shortest = std::sqrt(std::min({a.squaredNorm(), b.squaredNorm(), c.squaredNorm(),
                                                (p2 - p1).squaredNorm(), (p3 - p1).squaredNorm(),
                                                (p3 - p2).squaredNorm()}));
    return shortest > 0 ? offset.norm() / shortest : std::numeric_limits<double>::infinity();
}

std::vector<double> min_dihedral_angles_deg(const TetMesh& mesh) {
    std::vector<double> result(mesh.tets.size());
    tbb::parallel_for(size_t{0}, mesh.tets.size(), [&](size_t t) {
        const Tet& tet = mesh.tets[t];
        result[t] = min_dihedral_angle_deg(mesh, tet);
    });
    return result;
}


double mesh_min_dihedral_deg(const TetMesh& mesh) {
    if (mesh.tets.empty()) return 0;
    // Find the worst tet by cosine, then measure it with min_dihedral_angle_deg so the value is the
    // one every other report of the same tet gives.
    using Worst = std::pair<double, size_t>;  // (largest cosine, its tet)
    const Worst worst = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, mesh.tets.size(), 2048), Worst{-2.0, 0},
        [&](const tbb::blocked_range<size_t>& range, Worst w) {
            for (size_t t = range.begin(); t != range.end(); ++t) {
                const Tet& tet = mesh.tets[t];
                const double c = max_dihedral_cosine(mesh.positions[tet[0]], mesh.positions[tet[1]],
                                                     mesh.positions[tet[2]], mesh.positions[tet[3]]);
                if (c > w.first) w = {c, t};
            }
            return w;
        },
        [](const Worst& a, const Worst& b) { return b.first > a.first || (b.first == a.first && b.second < a.second) ? b : a; });
    const Tet& tet = mesh.tets[worst.second];
    return min_dihedral_angle_deg(mesh, tet);
}

namespace {

struct QualityAccumulator {
    double min_dihedral = std::numeric_limits<double>::infinity();
    double max_dihedral = 0;
    double max_ratio = 0;
    double sum_ratio = 0;
    size_t below_5 = 0;
    double min_edge = std::numeric_limits<double>::infinity();
    double max_edge = 0;
    double sum_edge = 0;

    void join(const QualityAccumulator& o) {
        min_dihedral = std::min(min_dihedral, o.min_dihedral);
        max_dihedral = std::max(max_dihedral, o.max_dihedral);
        max_ratio = std::max(max_ratio, o.max_ratio);
        sum_ratio += o.sum_ratio;
        below_5 += o.below_5;
        min_edge = std::min(min_edge, o.min_edge);
        max_edge = std::max(max_edge, o.max_edge);
        sum_edge += o.sum_edge;
    }
};

}  // namespace

QualityReport measure_quality(const TetMesh& mesh) {
    QualityReport report;
    if (mesh.tets.empty()) return report;
    // Deterministic: the means are sums, which must not depend on how the threads split the tets.
    const QualityAccumulator total = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<size_t>(0, mesh.tets.size(), 2048), QualityAccumulator{},
        [&](const tbb::blocked_range<size_t>& r, QualityAccumulator acc) {
            for (size_t t = r.begin(); t != r.end(); ++t) {
                const Tet& tet = mesh.tets[t];
                const auto& p0 = mesh.positions[tet[0]];
                const auto& p1 = mesh.positions[tet[1]];
                const auto& p2 = mesh.positions[tet[2]];
                const auto& p3 = mesh.positions[tet[3]];
                const auto angles = dihedral_angles_deg(p0, p1, p2, p3);
                const auto [lo, hi] = std::minmax_element(angles.begin(), angles.end());
                acc.min_dihedral = std::min(acc.min_dihedral, *lo);
                acc.max_dihedral = std::max(acc.max_dihedral, *hi);
                if (*lo < 5.0) ++acc.below_5;
                const double ratio = radius_edge_ratio(p0, p1, p2, p3);
                acc.max_ratio = std::max(acc.max_ratio, ratio);
                acc.sum_ratio += ratio;
                // Each interior edge is shared by several tets; the mean is over tet-edge incidences,
                // which is what matters for the sizing statistics.
                for (const auto& e : kTetEdges) {
                    const double length = (mesh.positions[tet[e[1]]] - mesh.positions[tet[e[0]]]).norm();
                    acc.min_edge = std::min(acc.min_edge, length);
                    acc.max_edge = std::max(acc.max_edge, length);
                    acc.sum_edge += length;
                }
            }
            return acc;
        },
        [](QualityAccumulator a, const QualityAccumulator& b) {
            a.join(b);
            return a;
        });
    const double n = static_cast<double>(mesh.tets.size());
    report.min_dihedral_deg = total.min_dihedral;
    report.max_dihedral_deg = total.max_dihedral;
    report.max_radius_edge_ratio = total.max_ratio;
    report.mean_radius_edge_ratio = total.sum_ratio / n;
    report.tets_below_5_deg = total.below_5;
    report.min_edge_length = total.min_edge;
    report.max_edge_length = total.max_edge;
    report.mean_edge_length = total.sum_edge / (6.0 * n);
    return report;
}

}  // namespace waxwork
