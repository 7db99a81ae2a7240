// A kd-tree over 3D points (nanoflann, Debian libnanoflann-dev) for radius and nearest-neighbour
// queries: the adaptor through which nanoflann reads the points in place, and the tree type over it.
// The points must outlive the cloud and the tree.
#pragma once

#include <Eigen/Core>
#include <nanoflann.hpp>

#include <cstddef>
#include <cstdint>
#include <span>

namespace waxwork {

struct PointCloud {
    std::span<const Eigen::Vector3d> points;
    size_t kdtree_get_point_count() const { return points.size(); }
    double kdtree_get_pt(size_t index, size_t dim) const { return points[index][static_cast<int>(dim)]; }
    template <class BoundingBox>
    bool kdtree_get_bbox(BoundingBox&) const { return false; }
};

using PointKdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloud>, PointCloud, 3, uint32_t>;

}  // namespace waxwork
