// Shadow rays against a triangle surface: a bounding volume hierarchy answering "does this segment
// hit anything?" (any-hit), the query behind the visibility term V_i of the incident light q.
//
// Why hand-written instead of CGAL's AABB_tree (DEVELOPERS.md: write by hand only what no library does
// well): the lighting recomputes q every time a light moves or a piece is dragged, for 30K-60K
// boundary vertices, within a frame. CGAL's tree is built for exact, general queries (double boxes,
// kernel predicates, a visitor per primitive, first-hit semantics by default); a float, binned-SAH,
// flattened BVH with an early-exit any-hit traversal does this one query several times faster
// (bench/lighting_bench.cpp measures both on spot's surface: BM_ShadowRays_HandBvh vs
// BM_ShadowRays_CgalAabbTree). Float is enough: rays start a fraction of an edge off the surface.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

// Möller-Trumbore: true when origin + t * direction hits triangle (v0, v1, v2) for some t in
// (t_min, t_max). Both sides of the triangle count. The reference the BVH is tested against.
bool ray_hits_triangle(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_min,
                       float t_max, const Eigen::Vector3f& v0, const Eigen::Vector3f& v1,
                       const Eigen::Vector3f& v2);

// An immutable BVH over a triangle set. Build once per geometry change; queries are thread-safe.
class TriangleBvh {
public:
    TriangleBvh() = default;
    // Builds with binned SAH (parallel over subtrees with TBB). Degenerate triangles are kept (they
    // are never hit). Throws InvalidArgumentError for out-of-range indices or non-finite points.
    TriangleBvh(std::span<const Eigen::Vector3f> points, std::span<const std::array<int32_t, 3>> triangles);

    // True when the open segment origin + t * direction, t in (t_min, t_max), hits any triangle.
    // direction need not be normalised (t is in units of |direction|).
    bool occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_min,
                  float t_max) const;

    // The same triangles at moved `points` (a deformation): the tree keeps its structure and takes the
    // new triangles and bounds, which is several times cheaper than building it again and answers
    // occluded() exactly as a new tree would (bounds stay exact; only traversal cost can grow as the
    // shape moves away from the one the tree was built for). InvalidArgumentError for a point set the
    // triangles do not fit or a non-finite point.
    void refit(std::span<const Eigen::Vector3f> points);

    size_t triangle_count() const { return triangles_.size(); }
    size_t node_count() const { return nodes_.size(); }
    bool empty() const { return triangles_.empty(); }

private:
    // 32 bytes, two per cache line. Interior nodes have count == 0 and their children at index and
    // index + 1 (allocated as a pair so subtrees can be built in parallel); leaves hold the triangles
    // [index, index + count) of triangles_.
    struct Node {
        float lo[3];
        int32_t index;
        float hi[3];
        int32_t count;
    };
    // Pre-computed for Möller-Trumbore: one vertex and two edges, in BVH leaf order.
    struct PackedTriangle {
        Eigen::Vector3f v0, e1, e2;
    };

    std::vector<Node> nodes_;
    std::vector<PackedTriangle> triangles_;
    std::vector<std::array<int32_t, 3>> leaf_triangles_;  // the input triangles in leaf order, for refit

    friend struct BvhBuilder;
};

}  // namespace waxwork
