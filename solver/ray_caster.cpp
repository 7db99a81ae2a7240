#include "solver/ray_caster.h"

#include "base/error.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>

namespace waxwork {

bool ray_hits_triangle(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_min,
                       float t_max, const Eigen::Vector3f& v0, const Eigen::Vector3f& v1,
                       const Eigen::Vector3f& v2) {
    const Eigen::Vector3f e1 = v1 - v0;
    const Eigen::Vector3f e2 = v2 - v0;
    const Eigen::Vector3f p = direction.cross(e2);
    const float det = e1.dot(p);
    // Exactly parallel rays (or degenerate triangles) cannot hit in the interior; grazing hits of a
    // shadow ray are irrelevant for visibility anyway.
    if (det == 0.0f) return false;
    const float inv_det = 1.0f / det;
    const Eigen::Vector3f s = origin - v0;
    const float u = s.dot(p) * inv_det;
    if (u < 0.0f || u > 1.0f) return false;
    const Eigen::Vector3f q = s.cross(e1);
    const float v = direction.dot(q) * inv_det;
    if (v < 0.0f || u + v > 1.0f) return false;
    const float t = e2.dot(q) * inv_det;
    return t > t_min && t < t_max;
}

namespace {

constexpr int kBinCount = 16;
constexpr int kMaxLeafSize = 4;
// Below this many triangles a subtree is built on the calling thread (task overhead dominates).
constexpr size_t kParallelThreshold = 4096;
// Beyond this depth splits are by count, so the traversal stack of 64 entries can never overflow
// (a pathological SAH sequence of 1-vs-rest splits could otherwise nest arbitrarily deep).
constexpr int kMaxSahDepth = 32;

struct Box {
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
    Eigen::Vector3f hi = Eigen::Vector3f::Constant(-std::numeric_limits<float>::infinity());

    void grow(const Eigen::Vector3f& p) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    void grow(const Box& b) {
        lo = lo.cwiseMin(b.lo);
        hi = hi.cwiseMax(b.hi);
    }
    float half_area() const {
        if (!(lo.array() <= hi.array()).all()) return 0.0f;
        const Eigen::Vector3f d = hi - lo;
        return d.x() * d.y() + d.y() * d.z() + d.z() * d.x();
    }
};

}  // namespace

// Binned SAH over triangle centroids (Wald 2007): per axis, 16 bins, sweep for the cheapest split.
struct BvhBuilder {
    std::vector<Box> boxes;
    std::vector<Eigen::Vector3f> centroids;
    std::vector<int32_t> order;  // triangle ids, permuted into leaf order
    std::vector<TriangleBvh::Node>& nodes;
    std::atomic<int32_t> next_node{1};

    explicit BvhBuilder(std::vector<TriangleBvh::Node>& n) : nodes(n) {}

    void build(int32_t node_index, size_t begin, size_t end, int depth) {
        Box bounds, centroid_bounds;
        for (size_t i = begin; i < end; ++i) {
            bounds.grow(boxes[order[i]]);
            centroid_bounds.grow(centroids[order[i]]);
        }
        TriangleBvh::Node& node = nodes[node_index];
        for (int k = 0; k < 3; ++k) {
            node.lo[k] = bounds.lo[k];
            node.hi[k] = bounds.hi[k];
        }
        const size_t count = end - begin;
        auto make_leaf = [&] {
            node.index = static_cast<int32_t>(begin);
            node.count = static_cast<int32_t>(count);
        };
        if (count <= static_cast<size_t>(kMaxLeafSize)) return make_leaf();

        // Best split over the three axes.
        float best_cost = std::numeric_limits<float>::infinity();
        int best_axis = -1, best_bin = -1;
        const Eigen::Vector3f extent = centroid_bounds.hi - centroid_bounds.lo;
        for (int axis = 0; axis < 3 && depth < kMaxSahDepth; ++axis) {
            if (!(extent[axis] > 0.0f)) continue;
            const float scale = kBinCount / extent[axis];
            std::array<Box, kBinCount> bin_boxes;
            std::array<int, kBinCount> bin_counts{};
            for (size_t i = begin; i < end; ++i) {
                const int b = std::min(kBinCount - 1,
                                       static_cast<int>((centroids[order[i]][axis] - centroid_bounds.lo[axis]) * scale));
                bin_boxes[b].grow(boxes[order[i]]);
                ++bin_counts[b];
            }
            // Right-to-left sweep stores the cost share of everything right of each split plane.
            std::array<float, kBinCount> right_cost{};
            Box right;
            int right_count = 0;
            for (int b = kBinCount - 1; b > 0; --b) {
                right.grow(bin_boxes[b]);
                right_count += bin_counts[b];
                right_cost[b] = right.half_area() * right_count;
            }
            Box left;
            int left_count = 0;
            for (int b = 0; b < kBinCount - 1; ++b) {
                left.grow(bin_boxes[b]);
                left_count += bin_counts[b];
                if (left_count == 0 || left_count == static_cast<int>(count)) continue;
                const float cost = left.half_area() * left_count + right_cost[b + 1];
                if (cost < best_cost) {
                    best_cost = cost;
                    best_axis = axis;
                    best_bin = b;
                }
            }
        }

        size_t middle;
        if (best_axis < 0) {
            // All centroids coincide (SAH cannot separate them), or the tree is already deep: split by
            // count, which halves the size and bounds the depth by kMaxSahDepth + log2(n) < 64.
            int axis = 0;
            for (int k = 1; k < 3; ++k) axis = extent[k] > extent[axis] ? k : axis;
            middle = begin + count / 2;
            std::nth_element(order.begin() + begin, order.begin() + middle, order.begin() + end,
                             [&](int32_t a, int32_t b) { return centroids[a][axis] < centroids[b][axis]; });
        } else {
            // Traversal cost ~1 node visit per 1 triangle test: a leaf is better when splitting does
            // not reduce the expected number of tests.
            const float leaf_cost = bounds.half_area() * count;
            if (best_cost >= leaf_cost && count <= 16) return make_leaf();
            const float scale = kBinCount / extent[best_axis];
            const float lo = centroid_bounds.lo[best_axis];
            auto it = std::partition(order.begin() + begin, order.begin() + end, [&](int32_t t) {
                const int b = std::min(kBinCount - 1, static_cast<int>((centroids[t][best_axis] - lo) * scale));
                return b <= best_bin;
            });
            middle = static_cast<size_t>(it - order.begin());
        }

        const int32_t left_index = next_node.fetch_add(2);
        node.index = left_index;
        node.count = 0;
        if (count >= kParallelThreshold) {
            tbb::parallel_invoke([&] { build(left_index, begin, middle, depth + 1); },
                                 [&] { build(left_index + 1, middle, end, depth + 1); });
        } else {
            build(left_index, begin, middle, depth + 1);
            build(left_index + 1, middle, end, depth + 1);
        }
    }
};

TriangleBvh::TriangleBvh(std::span<const Eigen::Vector3f> points,
                         std::span<const std::array<int32_t, 3>> triangles) {
    for (const Eigen::Vector3f& p : points) {
        if (!p.allFinite()) throw InvalidArgumentError("TriangleBvh: non-finite point coordinate");
    }
    const auto point_count = static_cast<int64_t>(points.size());
    for (size_t t = 0; t < triangles.size(); ++t) {
        for (int32_t v : triangles[t]) {
            if (v < 0 || v >= point_count) {
                throw InvalidArgumentError("TriangleBvh: triangle " + std::to_string(t) + " has vertex index " +
                                           std::to_string(v) + " outside 0.." + std::to_string(point_count - 1));
            }
        }
    }
    if (triangles.empty()) return;

    // A binary tree with leaves of >= 1 triangle has at most 2n - 1 nodes.
    nodes_.resize(2 * triangles.size() - 1);
    BvhBuilder builder(nodes_);
    builder.boxes.resize(triangles.size());
    builder.centroids.resize(triangles.size());
    builder.order.resize(triangles.size());
    tbb::parallel_for(size_t{0}, triangles.size(), [&](size_t t) {
        Box box;
        for (int32_t v : triangles[t]) box.grow(points[v]);
        builder.boxes[t] = box;
        builder.centroids[t] = 0.5f * (box.lo + box.hi);
        builder.order[t] = static_cast<int32_t>(t);
    });
    builder.build(0, 0, triangles.size(), 0);
    nodes_.resize(builder.next_node.load());
    nodes_.shrink_to_fit();

    leaf_triangles_.resize(triangles.size());
    for (size_t i = 0; i < triangles.size(); ++i) leaf_triangles_[i] = triangles[builder.order[i]];
    triangles_.resize(triangles.size());
    tbb::parallel_for(size_t{0}, triangles.size(), [&](size_t i) {
        const auto& tri = leaf_triangles_[i];
        const Eigen::Vector3f& v0 = points[tri[0]];
        triangles_[i] = {v0, points[tri[1]] - v0, points[tri[2]] - v0};
    });
}

void TriangleBvh::refit(std::span<const Eigen::Vector3f> points) {
    for (const Eigen::Vector3f& p : points)
        if (!p.allFinite()) throw InvalidArgumentError("TriangleBvh::refit: non-finite point coordinate");
    const auto point_count = static_cast<int64_t>(points.size());
    for (const auto& tri : leaf_triangles_)
        for (const int32_t v : tri)
            if (v >= point_count)
                throw InvalidArgumentError("TriangleBvh::refit: a triangle has vertex index " + std::to_string(v) +
                                           " outside the " + std::to_string(point_count) + " points");
    tbb::parallel_for(size_t{0}, leaf_triangles_.size(), [&](size_t i) {
        const auto& tri = leaf_triangles_[i];
        const Eigen::Vector3f& v0 = points[tri[0]];
        triangles_[i] = {v0, points[tri[1]] - v0, points[tri[2]] - v0};
    });
    // Children are allocated after their parent (BvhBuilder::next_node), so a backward sweep sees
    // both children of a node before the node.
    for (size_t k = nodes_.size(); k-- > 0;) {
        Node& node = nodes_[k];
        Box box;
        if (node.count > 0) {
            for (int32_t i = node.index; i < node.index + node.count; ++i)
                for (const int32_t v : leaf_triangles_[i]) box.grow(points[v]);
        } else {
            for (const Node* child : {&nodes_[node.index], &nodes_[node.index + 1]})
                box.grow(Box{Eigen::Vector3f(child->lo[0], child->lo[1], child->lo[2]),
                             Eigen::Vector3f(child->hi[0], child->hi[1], child->hi[2])});
        }
        for (int a = 0; a < 3; ++a) {
            node.lo[a] = box.lo[a];
            node.hi[a] = box.hi[a];
        }
    }
}

bool TriangleBvh::occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_min,
                           float t_max) const {
    if (nodes_.empty()) return false;
    // Division by a zero component gives +-inf, which the slab test handles (IEEE): the ray is then
    // parallel to that slab pair and inside or outside it for every t.
    const Eigen::Vector3f inv = direction.cwiseInverse();
    const bool negative[3] = {inv.x() < 0, inv.y() < 0, inv.z() < 0};

    // Slab test; returns the entry distance or +inf when the segment misses the box.
    auto enter = [&](const Node& n) {
        float t0 = t_min, t1 = t_max;
        for (int k = 0; k < 3; ++k) {
            float a = (n.lo[k] - origin[k]) * inv[k];
            float b = (n.hi[k] - origin[k]) * inv[k];
            if (negative[k]) std::swap(a, b);
            // Written so that NaN (0 * inf on a slab plane) leaves the interval unchanged.
            t0 = a > t0 ? a : t0;
            t1 = b < t1 ? b : t1;
        }
        return t0 <= t1 ? t0 : std::numeric_limits<float>::infinity();
    };

    if (enter(nodes_[0]) == std::numeric_limits<float>::infinity()) return false;
    int32_t stack[64];
    int depth = 0;
    int32_t current = 0;
    while (true) {
        const Node& n = nodes_[current];
        if (n.count > 0) {
            for (int32_t i = n.index; i < n.index + n.count; ++i) {
                const PackedTriangle& tri = triangles_[i];
                const Eigen::Vector3f p = direction.cross(tri.e2);
                const float det = tri.e1.dot(p);
                if (det == 0.0f) continue;
                const float inv_det = 1.0f / det;
                const Eigen::Vector3f s = origin - tri.v0;
                const float u = s.dot(p) * inv_det;
                if (u < 0.0f || u > 1.0f) continue;
                const Eigen::Vector3f q = s.cross(tri.e1);
                const float v = direction.dot(q) * inv_det;
                if (v < 0.0f || u + v > 1.0f) continue;
                const float t = tri.e2.dot(q) * inv_det;
                if (t > t_min && t < t_max) return true;
            }
        } else {
            // Nearer child first: occluders close to the receiver are found sooner on average.
            const float t_left = enter(nodes_[n.index]);
            const float t_right = enter(nodes_[n.index + 1]);
            const bool hit_left = t_left != std::numeric_limits<float>::infinity();
            const bool hit_right = t_right != std::numeric_limits<float>::infinity();
            if (hit_left && hit_right) {
                const bool left_first = t_left <= t_right;
                stack[depth++] = left_first ? n.index + 1 : n.index;
                current = left_first ? n.index : n.index + 1;
                continue;
            }
            if (hit_left || hit_right) {
                current = hit_left ? n.index : n.index + 1;
                continue;
            }
        }
        if (depth == 0) return false;
        current = stack[--depth];
    }
}

}  // namespace waxwork
