// The nearest boundary triangle along a ray: what a camera ray sees first. TriangleBvh
// (ray_caster.h) answers only "is anything in the way?" for shadow rays; this is a uniform grid walked
// with a 3D-DDA (Amanatides and Woo 1987, "A fast voxel traversal algorithm"), enough for the rays of
// one image per pass, in double precision so the hit lies on the triangle the walk then enters by.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace waxwork {

class FirstHitGrid {
public:
    struct Hit {
        int32_t triangle = -1;  // index into the constructor's triangles
        double t = 0;           // along the ray, in units of |direction|
        double u = 0, v = 0;    // barycentric weights of the second and third corners
    };

    FirstHitGrid() = default;
    // About two cells per triangle; each triangle is listed in every cell its bounding box overlaps.
    // Throws InvalidArgumentError for out-of-range indices or non-finite points.
    FirstHitGrid(const std::vector<Eigen::Vector3d>& points, const std::vector<std::array<int32_t, 3>>& triangles);

    // The nearest triangle hit by origin + t direction, t > 0 (both sides count). Thread-safe.
    std::optional<Hit> first_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;

    size_t triangle_count() const { return triangles_.size(); }

private:
    std::vector<Eigen::Vector3d> points_;
    std::vector<std::array<int32_t, 3>> triangles_;
    Eigen::AlignedBox3d box_;
    std::array<int, 3> cells_{1, 1, 1};
    Eigen::Vector3d cell_size_ = Eigen::Vector3d::Ones();
    std::vector<int32_t> cell_start_;  // per cell, into cell_items_ (one more entry than cells)
    std::vector<int32_t> cell_items_;
};

}  // namespace waxwork
