#include "tetops/surface_remesh.h"

#include "base/error.h"
#include "base/progress.h"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace waxwork {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point3 = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point3>;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;
namespace PMP = CGAL::Polygon_mesh_processing;

// Remeshing iterations at the target edge: each splits, collapses, flips and relaxes once (CGAL's
// examples use 3).
constexpr int kIterations = 3;
// A surface far finer than the target is coarsened towards it first, at most this factor per
// iteration: one iteration's collapses at a target many times the edges stall once the collapsed
// edges reach 4/3 of it (an 81,920-triangle sphere remeshed at 13 times its edge kept over 3,000
// triangles after 5 iterations, where 700 are the target's), so the edge grows geometrically.
constexpr double kCoarseningPerIteration = 2.0;

Mesh to_mesh(const TriangleSurface& surface) {
    std::vector<Point3> points;
    points.reserve(surface.points.size());
    for (const auto& p : surface.points) points.emplace_back(p.x(), p.y(), p.z());
    std::vector<std::array<size_t, 3>> polygons;
    polygons.reserve(surface.triangles.size());
    for (const auto& t : surface.triangles) polygons.push_back({size_t(t[0]), size_t(t[1]), size_t(t[2])});
    if (!PMP::is_polygon_soup_a_polygon_mesh(polygons))
        throw InvalidMeshError("surface remeshing: the surface is not a manifold polygon mesh");
    Mesh mesh;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
    return mesh;
}

TriangleSurface to_surface(const Mesh& mesh) {
    TriangleSurface surface;
    std::vector<int32_t> index(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), -1);
    for (const auto v : mesh.vertices()) {
        index[v.idx()] = static_cast<int32_t>(surface.points.size());
        const Point3& p = mesh.point(v);
        surface.points.emplace_back(p.x(), p.y(), p.z());
    }
    for (const auto f : mesh.faces()) {
        std::array<int32_t, 3> tri{};
        int k = 0;
        for (const auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            if (k == 3) throw AlgorithmError("surface remeshing made a face that is not a triangle");
            tri[k++] = index[v.idx()];
        }
        surface.triangles.push_back(tri);
    }
    return surface;
}

}  // namespace

double mean_edge_length(const TriangleSurface& surface) {
    double sum = 0;
    for (const auto& t : surface.triangles)
        for (int k = 0; k < 3; ++k) sum += (surface.points[t[k]] - surface.points[t[(k + 1) % 3]]).norm();
    return surface.triangles.empty() ? 0.0 : sum / double(3 * surface.triangles.size());
}

RemeshedSurface remesh_surface(const TriangleSurface& surface, double edge, Progress* progress) {
    if (!(edge > 0) || !std::isfinite(edge))
        throw InvalidArgumentError("surface remeshing: edge length " + number_text(edge) + " must be positive");
    report_stage(progress, "remeshing the surface (CGAL)");
    const Mesh input = to_mesh(surface);
    Mesh mesh = input;
    // Every moved or created vertex goes back onto the input surface, not onto the previous
    // iteration's: the iterations run one at a time (so that a cancel is seen between them), and
    // projecting onto each iteration's result would let the surface drift.
    const Tree tree(faces(input).first, faces(input).second, input);
    const auto project = [&](Mesh::Vertex_index v) { return tree.closest_point(mesh.point(v)); };
    const auto iterate = [&](double step) {
        check_cancelled(progress);
        PMP::isotropic_remeshing(faces(mesh), step, mesh,
                                 CGAL::parameters::number_of_iterations(1).projection_functor(project));
    };
    for (double step = kCoarseningPerIteration * mean_edge_length(surface); step < edge;
         step *= kCoarseningPerIteration)
        iterate(step);
    for (int i = 0; i < kIterations; ++i) iterate(edge);
    check_cancelled(progress);
    mesh.collect_garbage();
    report_stage(progress, "checking the remeshed surface");
    const std::string what = "surface remeshing at edge " + number_text(edge) + " (from " +
                             std::to_string(surface.triangles.size()) + " triangles to " +
                             std::to_string(mesh.number_of_faces()) + ")";
    if (mesh.number_of_faces() < 4 || !CGAL::is_closed(mesh) || !CGAL::is_triangle_mesh(mesh))
        throw AlgorithmError(what + ": the result is not a closed triangle surface");
    if (PMP::does_self_intersect(mesh))
        throw AlgorithmError(what + ": the result intersects itself (a part thinner than the edge folded)");
    if (!PMP::is_outward_oriented(mesh))
        throw AlgorithmError(what + ": the result is not outward oriented");
    RemeshedSurface result;
    result.surface = to_surface(mesh);
    result.report = {surface.triangles.size(), result.surface.triangles.size(), edge};
    return result;
}

}  // namespace waxwork
