#include "tetops/surface_check.h"

#include "base/progress.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/intersections.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <queue>
#include <tuple>
#include <unordered_set>

namespace waxwork {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point3 = Kernel::Point_3;
using Triangle = std::array<int32_t, 3>;

Point3 to_cgal(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

bool is_finite(const Eigen::Vector3d& p) { return p.allFinite(); }

bool indices_valid(const Triangle& t, size_t point_count) {
    return std::all_of(t.begin(), t.end(),
                       [&](int32_t i) { return i >= 0 && static_cast<size_t>(i) < point_count; });
}

bool repeats_index(const Triangle& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

// For every point, the smallest index of a point at exactly the same position. Files often store a
// point once per face that uses it (STL always does); the shape, not the numbering, must be checked.
// Non-finite points are never merged: NaN compares unequal and the mesher rejects them anyway.
std::vector<int32_t> canonical_points(const std::vector<Eigen::Vector3d>& points) {
    std::vector<int32_t> order(points.size());
    std::iota(order.begin(), order.end(), 0);
    auto less = [&](int32_t a, int32_t b) {
        const auto& p = points[a];
        const auto& q = points[b];
        return std::tie(p.x(), p.y(), p.z(), a) < std::tie(q.x(), q.y(), q.z(), b);
    };
    std::vector<int32_t> finite;
    finite.reserve(points.size());
    for (int32_t i : order)
        if (is_finite(points[i])) finite.push_back(i);
    std::sort(finite.begin(), finite.end(), less);
    std::vector<int32_t> canonical = order;
    for (size_t k = 1; k < finite.size(); ++k)
        if (points[finite[k]] == points[finite[k - 1]]) canonical[finite[k]] = canonical[finite[k - 1]];
    return canonical;
}

// The triangles with every index replaced by its canonical point. Triangles with invalid indices are
// left as they are (they are reported, never guessed at).
std::vector<Triangle> canonical_triangles(const TriangleSurface& surface,
                                          const std::vector<int32_t>& canonical) {
    std::vector<Triangle> result = surface.triangles;
    for (auto& t : result)
        if (indices_valid(t, surface.points.size()))
            for (auto& i : t) i = canonical[i];
    return result;
}

// Union-find over triangle corners, used to count the fans around each vertex.
class DisjointSets {
public:
    explicit DisjointSets(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
    size_t find(size_t i) {
        while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
        return i;
    }
    void unite(size_t a, size_t b) { parent_[find(a)] = find(b); }

private:
    std::vector<size_t> parent_;
};

struct EdgeUse {
    uint64_t key;       // (min vertex, max vertex)
    int32_t triangle;
    int8_t low_corner;  // corner of the triangle at the smaller vertex
    int8_t high_corner;
    bool forward;       // the triangle runs from the smaller to the larger vertex
};

uint64_t edge_key(int32_t a, int32_t b) {
    return (static_cast<uint64_t>(std::min(a, b)) << 32) | static_cast<uint32_t>(std::max(a, b));
}
std::array<int32_t, 2> edge_vertices(uint64_t key) {
    return {static_cast<int32_t>(key >> 32), static_cast<int32_t>(key & 0xffffffffu)};
}

// Every edge use of the usable triangles (valid, no repeated vertex), sorted by edge then triangle.
// Hand-written rather than CGAL's soup predicates because the messages need counts and examples,
// which is_polygon_soup_a_polygon_mesh() does not give.
std::vector<EdgeUse> sorted_edge_uses(const std::vector<Triangle>& triangles, size_t point_count) {
    std::vector<EdgeUse> uses;
    uses.reserve(3 * triangles.size());
    for (size_t t = 0; t < triangles.size(); ++t) {
        const Triangle& tri = triangles[t];
        if (!indices_valid(tri, point_count) || repeats_index(tri)) continue;
        for (int k = 0; k < 3; ++k) {
            int32_t a = tri[k], b = tri[(k + 1) % 3];
            bool forward = a < b;
            int8_t ka = static_cast<int8_t>(k), kb = static_cast<int8_t>((k + 1) % 3);
            uses.push_back({edge_key(a, b), static_cast<int32_t>(t), forward ? ka : kb, forward ? kb : ka,
                            forward});
        }
    }
    std::sort(uses.begin(), uses.end(), [](const EdgeUse& a, const EdgeUse& b) {
        return std::tie(a.key, a.triangle) < std::tie(b.key, b.triangle);
    });
    return uses;
}

template <typename F>
void for_each_edge(const std::vector<EdgeUse>& uses, F&& f) {
    for (size_t begin = 0; begin < uses.size();) {
        size_t end = begin + 1;
        while (end < uses.size() && uses[end].key == uses[begin].key) ++end;
        f(begin, end);
        begin = end;
    }
}

size_t count_boundary_edges(const std::vector<Triangle>& triangles, size_t point_count) {
    size_t count = 0;
    for_each_edge(sorted_edge_uses(triangles, point_count),
                  [&](size_t begin, size_t end) { count += (end - begin == 1); });
    return count;
}

bool is_collinear(const TriangleSurface& s, const Triangle& t) {
    return CGAL::collinear(to_cgal(s.points[t[0]]), to_cgal(s.points[t[1]]), to_cgal(s.points[t[2]]));
}

double signed_volume_of(const std::vector<Eigen::Vector3d>& points, const std::vector<Triangle>& triangles) {
    // Divergence theorem: sum of the signed volumes of the tets (origin, triangle). Centering on the
    // first point keeps the terms small for meshes far from the origin.
    if (points.empty()) return 0.0;
    const Eigen::Vector3d o = points.front();
    double six_volume = 0.0;
    for (const auto& t : triangles) {
        if (!indices_valid(t, points.size())) continue;
        six_volume += (points[t[0]] - o).dot((points[t[1]] - o).cross(points[t[2]] - o));
    }
    return six_volume / 6.0;
}

// Pairs of triangles that intersect beyond what they share, with CGAL's exact predicates. CGAL 5.5's
// PMP::self_intersections needs a halfedge mesh, which cannot hold the pinched vertices and
// non-manifold edges we must still check (the soup variant arrived in CGAL 5.6), so the candidate
// pairs come from CGAL's box intersection and the shared-vertex cases follow PMP's own rules.
std::vector<std::array<int32_t, 2>> self_intersecting_pairs(const TriangleSurface& surface,
                                                            const std::vector<Triangle>& triangles) {
    using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, int32_t>;
    std::vector<Box> boxes;
    boxes.reserve(triangles.size());
    for (size_t t = 0; t < triangles.size(); ++t) {
        const Triangle& tri = triangles[t];
        if (!indices_valid(tri, surface.points.size()) || repeats_index(tri) || is_collinear(surface, tri))
            continue;  // degenerate triangles are reported separately; CGAL's tests require non-degenerate
        CGAL::Bbox_3 box = to_cgal(surface.points[tri[0]]).bbox() + to_cgal(surface.points[tri[1]]).bbox() +
                           to_cgal(surface.points[tri[2]]).bbox();
        boxes.emplace_back(box, static_cast<int32_t>(t));
    }
    std::vector<std::array<int32_t, 2>> candidates;
    CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), [&](const Box& a, const Box& b) {
        candidates.push_back({std::min(a.info(), b.info()), std::max(a.info(), b.info())});
    });

    auto point = [&](int32_t i) { return to_cgal(surface.points[i]); };
    auto intersects = [&](const std::array<int32_t, 2>& pair) {
        const Triangle& t = triangles[pair[0]];
        const Triangle& u = triangles[pair[1]];
        int shared = 0;
        std::array<int, 3> in_u{-1, -1, -1};  // position of t's corner k in u, or -1
        for (int k = 0; k < 3; ++k)
            for (int l = 0; l < 3; ++l)
                if (t[k] == u[l]) {
                    in_u[k] = l;
                    ++shared;
                }
        if (shared == 3) return true;  // the same triangle twice
        if (shared == 2) {
            // They meet along the shared edge; they overlap only if coplanar and on the same side.
            int kt = static_cast<int>(std::find(in_u.begin(), in_u.end(), -1) - in_u.begin());
            int a = t[(kt + 1) % 3], b = t[(kt + 2) % 3];
            int p = t[kt];
            int q = u[0] != a && u[0] != b ? u[0] : (u[1] != a && u[1] != b ? u[1] : u[2]);
            return CGAL::coplanar(point(a), point(b), point(p), point(q)) &&
                   CGAL::coplanar_orientation(point(a), point(b), point(p), point(q)) == CGAL::POSITIVE;
        }
        if (shared == 1) {
            // Beyond the shared vertex, the intersection must cross an edge opposite to it.
            int kt = static_cast<int>(std::find_if(in_u.begin(), in_u.end(), [](int l) { return l >= 0; }) -
                                      in_u.begin());
            int lu = in_u[kt];
            Kernel::Segment_3 t_opposite(point(t[(kt + 1) % 3]), point(t[(kt + 2) % 3]));
            Kernel::Segment_3 u_opposite(point(u[(lu + 1) % 3]), point(u[(lu + 2) % 3]));
            Kernel::Triangle_3 tt(point(t[0]), point(t[1]), point(t[2]));
            Kernel::Triangle_3 uu(point(u[0]), point(u[1]), point(u[2]));
            return CGAL::do_intersect(t_opposite, uu) || CGAL::do_intersect(u_opposite, tt);
        }
        return CGAL::do_intersect(Kernel::Triangle_3(point(t[0]), point(t[1]), point(t[2])),
                                  Kernel::Triangle_3(point(u[0]), point(u[1]), point(u[2])));
    };
    // The exact tests dominate the cost and are independent: run them in parallel.
    std::vector<char> hit(candidates.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size()), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k) hit[k] = intersects(candidates[k]);
    });
    std::vector<std::array<int32_t, 2>> result;
    for (size_t k = 0; k < candidates.size(); ++k)
        if (hit[k]) result.push_back(candidates[k]);
    std::sort(result.begin(), result.end());
    result.erase(std::unique(result.begin(), result.end()), result.end());
    return result;
}

std::string plural(size_t n, const std::string& singular, const std::string& plural_form) {
    return std::to_string(n) + " " + (n == 1 ? singular : plural_form);
}

}  // namespace

std::string triangle_count_problem(size_t triangles, size_t limit) {
    if (triangles <= limit) return {};
    return std::to_string(triangles) + " triangles, more than the meshers take (" + std::to_string(limit) +
           ": they keep or query every one, and a 2M-triangle surface ran for minutes); simplify the surface "
           "to at most " + std::to_string(limit) + " triangles first";
}

bool SurfaceDefects::has_safe_repairs() const {
    return duplicate_points || unreferenced_points || repeated_index_triangles || zero_area_triangles ||
           inconsistent_edges || signed_volume < 0.0;
}

bool SurfaceDefects::is_clean() const { return describe().empty() && !has_safe_repairs(); }

namespace {

// All checks; the self-intersection test, by far the most expensive, only when asked for.
SurfaceDefects analyze(const TriangleSurface& surface, bool with_intersections) {
    SurfaceDefects d;
    d.point_count = surface.points.size();
    d.triangle_count = surface.triangles.size();
    const size_t n = surface.points.size();

    for (size_t i = 0; i < n; ++i)
        if (!is_finite(surface.points[i]) && d.non_finite_points++ == 0)
            d.first_non_finite_point = static_cast<int32_t>(i);

    std::vector<char> referenced(n, 0);
    for (size_t t = 0; t < surface.triangles.size(); ++t) {
        const Triangle& tri = surface.triangles[t];
        if (!indices_valid(tri, n)) {
            if (d.invalid_indices++ == 0) d.first_invalid_triangle = static_cast<int32_t>(t);
            continue;
        }
        for (int32_t i : tri) referenced[i] = 1;
    }
    d.unreferenced_points = static_cast<size_t>(std::count(referenced.begin(), referenced.end(), 0));

    const std::vector<int32_t> canonical = canonical_points(surface.points);
    for (size_t i = 0; i < n; ++i)
        if (referenced[i] && canonical[i] != static_cast<int32_t>(i)) ++d.duplicate_points;
    const std::vector<Triangle> triangles = canonical_triangles(surface, canonical);

    for (size_t t = 0; t < triangles.size(); ++t) {
        const Triangle& tri = triangles[t];
        if (!indices_valid(tri, n)) continue;
        if (repeats_index(tri)) {
            ++d.repeated_index_triangles;
        } else if (d.non_finite_points == 0 && is_collinear(surface, tri)) {
            if (d.zero_area_triangles++ == 0) d.first_zero_area_triangle = static_cast<int32_t>(t);
        }
    }

    // Edges and fans. Corners of triangles sharing an edge are joined at both ends of the edge; a
    // vertex whose corners fall into more than one set is pinched.
    const std::vector<EdgeUse> uses = sorted_edge_uses(triangles, n);
    DisjointSets fans(3 * triangles.size());
    for_each_edge(uses, [&](size_t begin, size_t end) {
        const size_t count = end - begin;
        const auto vertices = edge_vertices(uses[begin].key);
        if (count == 1) {
            if (d.boundary_edges++ == 0) d.first_boundary_edge = vertices;
        } else if (count > 2) {
            if (d.non_manifold_edges++ == 0) d.first_non_manifold_edge = vertices;
        } else if (uses[begin].forward == uses[begin + 1].forward) {
            if (d.inconsistent_edges++ == 0) d.first_inconsistent_edge = vertices;
        }
        for (size_t k = begin + 1; k < end; ++k) {
            fans.unite(3 * uses[begin].triangle + uses[begin].low_corner, 3 * uses[k].triangle + uses[k].low_corner);
            fans.unite(3 * uses[begin].triangle + uses[begin].high_corner,
                       3 * uses[k].triangle + uses[k].high_corner);
        }
    });
    std::vector<std::pair<int32_t, size_t>> vertex_fans;
    for (size_t t = 0; t < triangles.size(); ++t) {
        if (!indices_valid(triangles[t], n) || repeats_index(triangles[t])) continue;
        for (int k = 0; k < 3; ++k) vertex_fans.emplace_back(triangles[t][k], fans.find(3 * t + k));
    }
    std::sort(vertex_fans.begin(), vertex_fans.end());
    vertex_fans.erase(std::unique(vertex_fans.begin(), vertex_fans.end()), vertex_fans.end());
    for (size_t k = 1; k < vertex_fans.size(); ++k)
        if (vertex_fans[k].first == vertex_fans[k - 1].first &&
            (k < 2 || vertex_fans[k - 2].first != vertex_fans[k].first))
            if (d.non_manifold_vertices++ == 0) d.first_non_manifold_vertex = vertex_fans[k].first;

    if (d.non_finite_points == 0) {
        if (with_intersections) {
            const auto pairs = self_intersecting_pairs(surface, triangles);
            d.self_intersecting_pairs = pairs.size();
            if (!pairs.empty()) d.first_self_intersecting_pair = pairs.front();
        }
        d.signed_volume = signed_volume_of(surface.points, triangles);
    }
    return d;
}

}  // namespace

SurfaceDefects find_surface_defects(const TriangleSurface& surface) { return analyze(surface, true); }

std::vector<std::string> SurfaceDefects::describe(const SurfaceIndexMap* origin) const {
    // Through origin when given; an element origin marks as new (-1) is "[new I]", I its own index.
    auto translated = [&](int32_t i, const std::vector<int32_t>* map) {
        if (!map || i < 0 || static_cast<size_t>(i) >= map->size()) return std::to_string(i);
        return (*map)[i] >= 0 ? std::to_string((*map)[i]) : "[new " + std::to_string(i) + "]";
    };
    auto point_id = [&](int32_t i) { return translated(i, origin ? &origin->points : nullptr); };
    auto triangle_id = [&](int32_t i) { return translated(i, origin ? &origin->triangles : nullptr); };
    auto edge = [&](const std::array<int32_t, 2>& e) { return "vertices " + point_id(e[0]) + " and " + point_id(e[1]); };

    std::vector<std::string> lines;
    if (triangle_count == 0) lines.push_back("no triangles");
    if (non_finite_points)
        lines.push_back(plural(non_finite_points, "vertex", "vertices") + " with non-finite coordinates (first: vertex " +
                        point_id(first_non_finite_point) + ")");
    if (invalid_indices)
        lines.push_back(plural(invalid_indices, "triangle", "triangles") +
                        " referring to missing vertices (first: face " + triangle_id(first_invalid_triangle) + ")");
    if (boundary_edges)
        lines.push_back(plural(boundary_edges, "boundary edge", "boundary edges") +
                        " (the surface is open; first: " + edge(first_boundary_edge) + ")");
    if (non_manifold_edges)
        lines.push_back(plural(non_manifold_edges, "non-manifold edge", "non-manifold edges") +
                        " (shared by more than two triangles; first: " + edge(first_non_manifold_edge) + ")");
    if (non_manifold_vertices)
        lines.push_back(plural(non_manifold_vertices, "non-manifold vertex", "non-manifold vertices") +
                        " (pinched; " + (non_manifold_vertices == 1 ? "" : "first: ") + "vertex " +
                        point_id(first_non_manifold_vertex) + ")");
    if (inconsistent_edges)
        lines.push_back(plural(inconsistent_edges, "inconsistently oriented edge", "inconsistently oriented edges") +
                        " (first: " + edge(first_inconsistent_edge) + ")");
    if (self_intersecting_pairs)
        lines.push_back(plural(self_intersecting_pairs, "self-intersecting triangle pair",
                               "self-intersecting triangle pairs") +
                        " (first: faces " + triangle_id(first_self_intersecting_pair[0]) + " and " +
                        triangle_id(first_self_intersecting_pair[1]) + ")");
    if (zero_area_triangles)
        lines.push_back(plural(zero_area_triangles, "zero-area triangle", "zero-area triangles") + " (first: face " +
                        triangle_id(first_zero_area_triangle) + ")");
    // The volume means something only for a closed, consistently oriented surface.
    const bool volume_meaningful = lines.empty() && !inconsistent_edges;
    if (volume_meaningful && triangle_count > 0 && !(signed_volume > 0.0))
        lines.push_back(signed_volume == 0.0 ? "encloses no volume" : "oriented inward (negative volume)");
    return lines;
}

std::vector<std::string> repair_safe_defects(TriangleSurface& surface, SurfaceIndexMap* origin) {
    std::vector<std::string> repairs;
    const size_t n = surface.points.size();
    SurfaceIndexMap map;
    map.triangles.resize(surface.triangles.size());
    std::iota(map.triangles.begin(), map.triangles.end(), 0);

    // 1. Merge points at identical positions.
    std::vector<char> referenced(n, 0);
    for (const auto& t : surface.triangles)
        if (indices_valid(t, n))
            for (int32_t i : t) referenced[i] = 1;
    const std::vector<int32_t> canonical = canonical_points(surface.points);
    size_t merged = 0;
    for (size_t i = 0; i < n; ++i) merged += referenced[i] && canonical[i] != static_cast<int32_t>(i);
    surface.triangles = canonical_triangles(surface, canonical);
    if (merged) repairs.push_back("merged " + plural(merged, "duplicate vertex", "duplicate vertices"));

    // 2. Triangles that repeat a vertex have no area and no edge of their own: dropping them
    //    changes neither shape nor topology. Triangles with invalid indices stay to be reported.
    auto drop_triangles = [&](const std::vector<char>& drop) {
        size_t kept = 0;
        for (size_t t = 0; t < surface.triangles.size(); ++t)
            if (!drop[t]) {
                surface.triangles[kept] = surface.triangles[t];
                map.triangles[kept] = map.triangles[t];
                ++kept;
            }
        surface.triangles.resize(kept);
        map.triangles.resize(kept);
    };
    {
        std::vector<char> drop(surface.triangles.size(), 0);
        size_t count = 0;
        for (size_t t = 0; t < surface.triangles.size(); ++t)
            if (indices_valid(surface.triangles[t], n) && repeats_index(surface.triangles[t])) drop[t] = 1, ++count;
        if (count) {
            drop_triangles(drop);
            repairs.push_back("dropped " + plural(count, "triangle", "triangles") + " repeating a vertex");
        }
    }

    // 3. Zero-area triangles with three distinct vertices: dropping them is safe only when every edge
    //    they use stays covered by other triangles; otherwise they are left for the report.
    const bool all_finite = std::all_of(surface.points.begin(), surface.points.end(), is_finite);
    if (all_finite) {
        std::vector<char> drop(surface.triangles.size(), 0);
        size_t count = 0;
        for (size_t t = 0; t < surface.triangles.size(); ++t)
            if (indices_valid(surface.triangles[t], n) && is_collinear(surface, surface.triangles[t]))
                drop[t] = 1, ++count;
        if (count) {
            std::vector<Triangle> remaining;
            for (size_t t = 0; t < surface.triangles.size(); ++t)
                if (!drop[t]) remaining.push_back(surface.triangles[t]);
            if (count_boundary_edges(remaining, n) <= count_boundary_edges(surface.triangles, n)) {
                drop_triangles(drop);
                repairs.push_back("dropped " + plural(count, "zero-area triangle", "zero-area triangles"));
            }
        }
    }

    // 4. Drop vertices no triangle uses (those merged away in step 1 are not counted again).
    {
        std::vector<int32_t> new_index(n, -1);
        for (const auto& t : surface.triangles)
            if (indices_valid(t, n))
                for (int32_t i : t) new_index[i] = 0;
        std::vector<Eigen::Vector3d> points;
        for (size_t i = 0; i < n; ++i)
            if (new_index[i] == 0) {
                new_index[i] = static_cast<int32_t>(points.size());
                points.push_back(surface.points[i]);
                map.points.push_back(static_cast<int32_t>(i));
            }
        const size_t removed = n - points.size();
        // Invalid triangles keep their (invalid) indices so the report still shows them as invalid.
        for (auto& t : surface.triangles)
            if (indices_valid(t, n))
                for (auto& i : t) i = new_index[i];
        surface.points = std::move(points);
        if (removed > merged)
            repairs.push_back("removed " + plural(removed - merged, "unreferenced vertex", "unreferenced vertices"));
    }

    // 5. Orientation. On a closed edge-manifold surface the orientation of one triangle determines its
    //    whole component, so making neighbours agree is unambiguous (BFS across shared edges). Then
    //    the whole surface is flipped if it encloses negative volume.
    const SurfaceDefects d = analyze(surface, false);
    if (d.invalid_indices == 0 && d.boundary_edges == 0 && d.non_manifold_edges == 0 && d.non_finite_points == 0) {
        if (d.inconsistent_edges > 0) {
            const auto uses = sorted_edge_uses(surface.triangles, surface.points.size());
            std::vector<std::vector<std::pair<int32_t, bool>>> neighbours(surface.triangles.size());
            for_each_edge(uses, [&](size_t begin, size_t end) {
                if (end - begin != 2) return;
                const auto& a = uses[begin];
                const auto& b = uses[begin + 1];
                const bool same_direction = a.forward == b.forward;  // one of them must flip
                neighbours[a.triangle].emplace_back(b.triangle, same_direction);
                neighbours[b.triangle].emplace_back(a.triangle, same_direction);
            });
            std::vector<int8_t> flip(surface.triangles.size(), -1);
            bool orientable = true;
            for (size_t seed = 0; seed < surface.triangles.size() && orientable; ++seed) {
                if (flip[seed] >= 0) continue;
                flip[seed] = 0;
                std::queue<int32_t> queue;
                queue.push(static_cast<int32_t>(seed));
                while (!queue.empty() && orientable) {
                    const int32_t t = queue.front();
                    queue.pop();
                    for (const auto& [u, differ] : neighbours[t]) {
                        const int8_t wanted = static_cast<int8_t>(flip[t] ^ differ);
                        if (flip[u] < 0) {
                            flip[u] = wanted;
                            queue.push(u);
                        } else if (flip[u] != wanted) {
                            orientable = false;  // a Moebius-like surface: leave it for the report
                        }
                    }
                }
            }
            if (orientable) {
                // Flip the minority of each component, so that most of the file's orientation survives.
                std::vector<int32_t> component(surface.triangles.size(), -1);
                std::vector<std::array<size_t, 2>> votes;  // per component: triangles kept, flipped
                for (size_t seed = 0; seed < surface.triangles.size(); ++seed) {
                    if (component[seed] >= 0) continue;
                    const auto c = static_cast<int32_t>(votes.size());
                    votes.push_back({0, 0});
                    std::vector<int32_t> stack{static_cast<int32_t>(seed)};
                    component[seed] = c;
                    while (!stack.empty()) {
                        const int32_t t = stack.back();
                        stack.pop_back();
                        ++votes[c][flip[t]];
                        for (const auto& neighbour : neighbours[t])
                            if (component[neighbour.first] < 0) {
                                component[neighbour.first] = c;
                                stack.push_back(neighbour.first);
                            }
                    }
                }
                for (size_t t = 0; t < surface.triangles.size(); ++t)
                    if (votes[component[t]][1] > votes[component[t]][0]) flip[t] = static_cast<int8_t>(1 - flip[t]);
                size_t flipped = 0;
                for (size_t t = 0; t < surface.triangles.size(); ++t)
                    if (flip[t] == 1) {
                        std::swap(surface.triangles[t][1], surface.triangles[t][2]);
                        ++flipped;
                    }
                repairs.push_back("reoriented " + plural(flipped, "triangle", "triangles") +
                                  " to agree with their neighbours");
            }
        }
        if (signed_volume_of(surface.points, surface.triangles) < 0.0 &&
            analyze(surface, false).inconsistent_edges == 0) {
            for (auto& t : surface.triangles) std::swap(t[1], t[2]);
            repairs.push_back("flipped all " + plural(surface.triangles.size(), "triangle", "triangles") +
                              " to face outward (the enclosed volume was negative)");
        }
    }
    if (origin) *origin = std::move(map);
    return repairs;
}

std::vector<std::string> repair_hard_defects(TriangleSurface& surface, const SurfaceRepairOptions& options,
                                             Progress* progress) {
    std::vector<std::string> repairs;
    if (!options.fill_holes && !options.autorefine) return repairs;
    repair_safe_defects(surface);  // the halfedge mesh below needs merged points and no degenerate faces

    const SurfaceDefects before = find_surface_defects(surface);
    if (before.non_finite_points || before.invalid_indices || before.non_manifold_edges ||
        before.non_manifold_vertices || before.inconsistent_edges) {
        repairs.push_back("hard repairs not attempted: the surface must first be "
                          "edge- and vertex-manifold and consistently oriented");
        return repairs;
    }

    using Mesh = CGAL::Surface_mesh<Point3>;
    namespace PMP = CGAL::Polygon_mesh_processing;
    std::vector<Point3> points;
    points.reserve(surface.points.size());
    for (const auto& p : surface.points) points.push_back(to_cgal(p));
    std::vector<std::vector<size_t>> polygons;
    polygons.reserve(surface.triangles.size());
    for (const auto& t : surface.triangles) polygons.push_back({size_t(t[0]), size_t(t[1]), size_t(t[2])});
    if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
        repairs.push_back("hard repairs not attempted: the surface is not a "
                          "manifold polygon mesh");
        return repairs;
    }
    Mesh mesh;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);

    if (options.fill_holes && before.boundary_edges > 0) {
        // Collect one halfedge per hole first: filling changes the border.
        std::vector<Mesh::Halfedge_index> holes;
        std::unordered_set<Mesh::Halfedge_index> seen;
        for (auto h : mesh.halfedges()) {
            if (!mesh.is_border(h) || seen.count(h)) continue;
            holes.push_back(h);
            for (auto g : CGAL::halfedges_around_face(h, mesh)) seen.insert(g);
        }
        size_t new_faces = 0, new_vertices = 0, unfaired = 0;
        report_stage(progress, "repairing (filling holes)");
        for (auto h : holes) {
            check_cancelled(progress);
            std::vector<Mesh::Face_index> faces;
            std::vector<Mesh::Vertex_index> vertices;
            const bool faired = std::get<0>(PMP::triangulate_refine_and_fair_hole(
                mesh, h, std::back_inserter(faces), std::back_inserter(vertices)));
            unfaired += !faired;
            new_faces += faces.size();
            new_vertices += vertices.size();
        }
        repairs.push_back("filled " + plural(holes.size(), "hole", "holes") + " (" +
                          plural(before.boundary_edges, "boundary edge", "boundary edges") + ") with " +
                          plural(new_faces, "triangle", "triangles") + " and " +
                          plural(new_vertices, "new vertex", "new vertices") +
                          (unfaired ? " (" + plural(unfaired, "patch", "patches") + " could not be faired)" : ""));
    }

    if (options.autorefine && before.self_intersecting_pairs > 0) {
        // CGAL 5.5 has no autorefine(); its experimental local remeshing is the available tool. It may
        // fail on some intersections, so the caller re-validates and rejects what remains.
        report_stage(progress, "repairing (removing self-intersections)");
        const bool complete = PMP::experimental::remove_self_intersections(mesh);
        repairs.push_back(std::string("remeshed around ") +
                          plural(before.self_intersecting_pairs, "self-intersecting triangle pair",
                                 "self-intersecting triangle pairs") +
                          (complete ? "" : " (not all could be removed)"));
    }

    mesh.collect_garbage();
    TriangleSurface result;
    result.points.reserve(mesh.number_of_vertices());
    for (auto v : mesh.vertices()) {
        const Point3& p = mesh.point(v);
        result.points.emplace_back(p.x(), p.y(), p.z());
    }
    for (auto f : mesh.faces()) {
        Triangle t{};
        int k = 0;
        for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            if (k < 3) t[k] = static_cast<int32_t>(v.idx());
            ++k;
        }
        if (k == 3) result.triangles.push_back(t);
    }
    surface = std::move(result);
    for (auto& line : repair_safe_defects(surface)) repairs.push_back(std::move(line));
    return repairs;
}

}  // namespace waxwork
