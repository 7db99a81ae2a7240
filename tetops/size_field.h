// The target edge length of a meshing run as a function of depth below the surface, shared by the
// TetGen and CGAL meshers (tetrahedralize.h documents how MeshSizing maps onto it).
#pragma once

#include "tetops/triangle_surface.h"

#include <Eigen/Core>

#include <limits>
#include <memory>
#include <vector>

namespace waxwork {

// edge(d) = min(surface_edge + grading * d, max_edge) at depth d below the surface. grading == 0 is
// a uniform size; surface_edge == infinity means "no size bound" (only the quality bounds refine).
struct SizeField {
    double surface_edge = std::numeric_limits<double>::infinity();
    double grading = 0;
    double max_edge = std::numeric_limits<double>::infinity();

    bool is_uniform() const { return grading == 0 || surface_edge >= max_edge; }
    bool is_bounded() const { return surface_edge < std::numeric_limits<double>::infinity(); }
    double edge_at_depth(double depth) const;

    static SizeField uniform(double edge) { return {edge, 0, edge}; }
    static SizeField unbounded() { return {}; }
};

// Unsigned distance from points to a triangle surface, and which side of it they lie on, answered
// by a CGAL AABB tree. Built once per meshing run: the graded size field asks it for every point of a
// background mesh (TetGen) or for every refinement query (CGAL). Its queries are safe from many
// threads at once.
class SurfaceDistance {
public:
    explicit SurfaceDistance(const TriangleSurface& surface);
    ~SurfaceDistance();
    SurfaceDistance(const SurfaceDistance&) = delete;
    SurfaceDistance& operator=(const SurfaceDistance&) = delete;

    double operator()(const Eigen::Vector3d& p) const;
    // Whether p lies inside the (closed) surface: the parity of the triangles three rays from p
    // cross, by majority, so that a ray grazing an edge or vertex (counted twice) is outvoted.
    bool contains(const Eigen::Vector3d& p) const;

private:
    struct Tree;
    std::unique_ptr<Tree> tree_;
};

// Volume enclosed by a closed, outward-oriented surface (divergence theorem: the sum of the signed
// volumes of the tets spanned by the origin and each triangle).
double enclosed_volume(const TriangleSurface& surface);

// Total area of the triangles.
double surface_area(const TriangleSurface& surface);

}  // namespace waxwork
