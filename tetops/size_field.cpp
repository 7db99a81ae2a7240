#include "tetops/size_field.h"

#include <Eigen/Geometry>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>

namespace waxwork {

namespace {
// Inexact construction is enough here: the distance only steers the size field, it decides no
// topology.
using Kernel = CGAL::Simple_cartesian<double>;
using Triangle = Kernel::Triangle_3;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, std::vector<Triangle>::const_iterator>;
using AabbTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Kernel::Point_3 to_cgal(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }
}  // namespace

double SizeField::edge_at_depth(double depth) const {
    return std::min(surface_edge + grading * std::max(depth, 0.0), max_edge);
}

struct SurfaceDistance::Tree {
    std::vector<Triangle> triangles;
    AabbTree tree;
};

SurfaceDistance::SurfaceDistance(const TriangleSurface& surface) : tree_(std::make_unique<Tree>()) {
    tree_->triangles.reserve(surface.triangles.size());
    for (const auto& t : surface.triangles) {
        tree_->triangles.emplace_back(to_cgal(surface.points[t[0]]), to_cgal(surface.points[t[1]]),
                                      to_cgal(surface.points[t[2]]));
    }
    tree_->tree.insert(tree_->triangles.cbegin(), tree_->triangles.cend());
    // Built here rather than at the first query, so that queries from many threads only read.
    tree_->tree.build();
    tree_->tree.accelerate_distance_queries();
}

SurfaceDistance::~SurfaceDistance() = default;

double SurfaceDistance::operator()(const Eigen::Vector3d& p) const {
    return std::sqrt(tree_->tree.squared_distance(to_cgal(p)));
}

bool SurfaceDistance::contains(const Eigen::Vector3d& p) const {
    // Directions with no simple relation to the axes, which CAD faces and grids are aligned with.
    static const Kernel::Vector_3 kDirections[3] = {{0.5773, 0.6109, 0.5417}, {-0.7071, 0.1283, 0.6953},
                                                    {0.2672, -0.9161, 0.2985}};
    int inside_votes = 0;
    for (const auto& direction : kDirections) {
        const Kernel::Ray_3 ray(to_cgal(p), direction);
        if (tree_->tree.number_of_intersected_primitives(ray) % 2 == 1) ++inside_votes;
    }
    return inside_votes >= 2;
}

double enclosed_volume(const TriangleSurface& surface) {
    double six_volume = 0;
    for (const auto& t : surface.triangles) {
        const Eigen::Vector3d& a = surface.points[t[0]];
        six_volume += a.dot(surface.points[t[1]].cross(surface.points[t[2]]));
    }
    return six_volume / 6;
}

double surface_area(const TriangleSurface& surface) {
    double twice_area = 0;
    for (const auto& t : surface.triangles) {
        const Eigen::Vector3d& a = surface.points[t[0]];
        twice_area += (surface.points[t[1]] - a).cross(surface.points[t[2]] - a).norm();
    }
    return twice_area / 2;
}

}  // namespace waxwork
