#include "tetops/delaunay_check.h"

#include "base/error.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <functional>
#include <utility>

namespace waxwork {

namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;

Point point(const TetMesh& mesh, int32_t v) {
    const Eigen::Vector3d& p = mesh.positions[v];
    return {p.x(), p.y(), p.z()};
}
}  // namespace

DelaunayCheck check_local_delaunay(const TetMesh& mesh, const TetConnectivity& connectivity) {
    if (connectivity.tet_neighbors.size() != mesh.tet_count())
        throw InvalidArgumentError("local Delaunay check: the connectivity does not belong to the mesh");
    using Counts = std::pair<size_t, size_t>;
    const Counts counts = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, mesh.tet_count()), Counts{0, 0},
        [&](const tbb::blocked_range<size_t>& range, Counts c) {
            for (size_t t = range.begin(); t != range.end(); ++t) {
                const Tet& tet = mesh.tets[t];
                for (int f = 0; f < 4; ++f) {
                    const int32_t n = connectivity.tet_neighbors[t][f];
                    if (n < 0 || static_cast<size_t>(n) < t) continue;  // each interior face once
                    // The neighbour's vertex that is not on the shared face.
                    int32_t opposite = -1;
                    for (int32_t v : mesh.tets[n])
                        if (v != tet[0] && v != tet[1] && v != tet[2] && v != tet[3]) opposite = v;
                    if (opposite < 0) continue;  // a duplicated tet: no test to make
                    ++c.first;
                    // With (p0, p1, p2, p3) positively oriented, CGAL reports ON_POSITIVE_SIDE for a point
                    // strictly inside the circumsphere (the same orientation convention as TetMesh).
                    if (CGAL::side_of_oriented_sphere(point(mesh, tet[0]), point(mesh, tet[1]), point(mesh, tet[2]),
                                                      point(mesh, tet[3]), point(mesh, opposite)) == CGAL::ON_POSITIVE_SIDE)
                        ++c.second;
                }
            }
            return c;
        },
        [](Counts a, Counts b) { return Counts{a.first + b.first, a.second + b.second}; });
    return {counts.first, counts.second};
}

}  // namespace waxwork
