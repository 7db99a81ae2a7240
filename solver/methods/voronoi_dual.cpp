#include "solver/methods/voronoi_dual.h"

#include "base/error.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <string>

namespace waxwork {

namespace {

// Unit vector along the part of v perpendicular to the unit vector d.
Eigen::Vector3d perpendicular_unit(const Eigen::Vector3d& v, const Eigen::Vector3d& d) {
    return (v - v.dot(d) * d).normalized();
}

// Signed area of the right triangle (m_e, c_f, c_t) of edge e = (a, b) in face f = (a, b, k) of a tet
// whose fourth vertex is l (the right angle is at c_f: c_f - m_e lies in f and is perpendicular to e,
// c_t - c_f is normal to f).
double signed_elementary_area(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& k,
                              const Eigen::Vector3d& l, const Eigen::Vector3d& c_t) {
    const Eigen::Vector3d m = 0.5 * (a + b);
    const Eigen::Vector3d d = (b - a).normalized();
    const Eigen::Vector3d c_f = triangle_circumcentre(a, b, k);
    // Positive when c_f lies on k's side of e within the face...
    const double along_face = (c_f - m).dot(perpendicular_unit(k - m, d));
    // ...times positive when c_t lies on l's side of the face.
    Eigen::Vector3d normal = (b - a).cross(k - a).normalized();
    if (normal.dot(l - a) < 0) normal = -normal;
    const double off_face = (c_t - c_f).dot(normal);
    return 0.5 * along_face * off_face;
}

}  // namespace

Eigen::Vector3d triangle_circumcentre(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const Eigen::Vector3d u = b - a, v = c - a;
    const Eigen::Vector3d n = u.cross(v);
    return a + (u.squaredNorm() * v - v.squaredNorm() * u).cross(n) / (2 * n.squaredNorm());
}

Eigen::Vector3d tet_circumcentre(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                                 const Eigen::Vector3d& p3) {
    const Eigen::Vector3d a = p1 - p0, b = p2 - p0, c = p3 - p0;
    const double det = a.dot(b.cross(c));
    return p0 + (a.squaredNorm() * b.cross(c) + b.squaredNorm() * c.cross(a) + c.squaredNorm() * a.cross(b)) / (2 * det);
}

TetDual tet_voronoi_dual(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                         const Eigen::Vector3d& p3) {
    const std::array<const Eigen::Vector3d*, 4> p = {&p0, &p1, &p2, &p3};
    const Eigen::Vector3d c_t = tet_circumcentre(p0, p1, p2, p3);
    TetDual dual{};
    for (int e = 0; e < 6; ++e) {
        const int a = kTetEdges[e][0], b = kTetEdges[e][1];
        const int k = kTetEdges[5 - e][0], l = kTetEdges[5 - e][1];  // the opposite edge
        const double area = signed_elementary_area(*p[a], *p[b], *p[k], *p[l], c_t) +
                            signed_elementary_area(*p[a], *p[b], *p[l], *p[k], c_t);
        const double length = (*p[b] - *p[a]).norm();
        dual.edge_coefficient[e] = area / length;
        // Pyramid with apex at either end over the dual piece, height |e| / 2.
        const double pyramid = area * length / 6.0;
        dual.cell_volume[a] += pyramid;
        dual.cell_volume[b] += pyramid;
    }
    return dual;
}

VoronoiDual build_voronoi_dual(const TetMesh& mesh, const TetConnectivity& connectivity, double mm_per_unit) {
    if (connectivity.tet_neighbors.size() != mesh.tet_count())
        throw InvalidArgumentError("Voronoi dual: the connectivity does not belong to the mesh");
    VoronoiDual dual;
    dual.edge_coefficient.resize(mesh.tet_count());
    dual.cell_volume.resize(mesh.tet_count());
    dual.boundary_area.resize(connectivity.boundary_faces.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.tet_count()), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t t = range.begin(); t != range.end(); ++t) {
            const Tet& tet = mesh.tets[t];
            // Relative to the first vertex, so the circumcentre formulas see small coordinates.
            const Eigen::Vector3d& origin = mesh.positions[tet[0]];
            const Eigen::Vector3d p1 = (mesh.positions[tet[1]] - origin) * mm_per_unit;
            const Eigen::Vector3d p2 = (mesh.positions[tet[2]] - origin) * mm_per_unit;
            const Eigen::Vector3d p3 = (mesh.positions[tet[3]] - origin) * mm_per_unit;
            if (!(p1.dot(p2.cross(p3)) > 0))
                throw InvalidArgumentError("Voronoi dual: tet " + std::to_string(t) +
                                           " has non-positive volume (no circumcentre)");
            const TetDual piece = tet_voronoi_dual(Eigen::Vector3d::Zero(), p1, p2, p3);
            dual.edge_coefficient[t] = piece.edge_coefficient;
            dual.cell_volume[t] = piece.cell_volume;
        }
    });
    tbb::parallel_for(size_t{0}, connectivity.boundary_faces.size(), [&](size_t f) {
        const auto& v = connectivity.boundary_faces[f].vertices;
        const Eigen::Vector3d& origin = mesh.positions[v[0]];
        const std::array<Eigen::Vector3d, 3> p = {Eigen::Vector3d::Zero(), (mesh.positions[v[1]] - origin) * mm_per_unit,
                                                  (mesh.positions[v[2]] - origin) * mm_per_unit};
        const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
        int obtuse = -1;
        for (int i = 0; i < 3; ++i)
            if ((p[(i + 1) % 3] - p[i]).dot(p[(i + 2) % 3] - p[i]) < 0) obtuse = i;
        std::array<double, 3> share{};
        if (obtuse >= 0) {
            for (int i = 0; i < 3; ++i) share[i] = i == obtuse ? area / 2 : area / 4;
        } else {
            // The Voronoi region of corner i: two right triangles (p_i, m_ij, c) over the edges at i.
            const Eigen::Vector3d c = triangle_circumcentre(p[0], p[1], p[2]);
            for (int i = 0; i < 3; ++i)
                for (int j : {(i + 1) % 3, (i + 2) % 3}) {
                    const Eigen::Vector3d m = 0.5 * (p[i] + p[j]);
                    share[i] += 0.25 * (p[j] - p[i]).norm() * (c - m).norm();
                }
        }
        dual.boundary_area[f] = share;
    });
    return dual;
}

}  // namespace waxwork
