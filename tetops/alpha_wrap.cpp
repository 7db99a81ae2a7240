#include "tetops/alpha_wrap.h"

#include "base/error.h"
#include "base/progress.h"
#include "tetops/disjoint_sets.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

namespace waxwork {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point3 = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point3>;

// CGAL 5.5's wrapper has no "stop" query in its visitor (its flood fill runs until the queue is
// empty), but every callback runs between two complete steps of the flood fill, with the
// triangulation consistent; throwing CancelledError from one unwinds through the wrapper, whose state
// is all owned by objects on the stack. Checking every 1024 gates costs nothing measurable and stops
// within milliseconds.
struct CancellingVisitor : CGAL::Alpha_wraps_3::internal::Wrapping_default_visitor {
    const Progress* progress = nullptr;
    size_t gates = 0;

    template <typename AlphaWrapper, typename Gate>
    void before_facet_treatment(const AlphaWrapper&, const Gate&) {
        if ((++gates & 1023u) == 0) check_cancelled(progress);
    }
};

std::string length_text(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", value);
    return text;
}

void check_length(const std::optional<double>& value, const char* option, double floor_fraction, double diagonal,
                  const char* why) {
    if (!value) return;
    if (!std::isfinite(*value) || !(*value > 0))
        throw InvalidArgumentError(std::string(option) + ": must be a positive length in model units (got " +
                                   number_text(*value) + ")");
    if (diagonal > 0 && *value < floor_fraction * diagonal)
        throw InvalidArgumentError(std::string(option) + ": " + number_text(*value) + " is below " +
                                   number_text(floor_fraction) + " of the model's diagonal (" +
                                   number_text(diagonal) + "), the smallest taken: " + why);
}

}  // namespace

void validate_wrap_options(const WrapOptions& options, double diagonal) {
    check_length(options.alpha, "--wrap-alpha", kMinWrapAlphaFraction, diagonal,
                 "the wrap's work and triangle count grow like (diagonal / alpha)^2");
    check_length(options.offset, "--wrap-offset", kMinWrapOffsetFraction, diagonal,
                 "closer than that to the input is below double precision at the model's size");
}

std::string WrapReport::describe() const {
    std::string line = "wrapped (alpha " + length_text(alpha) + ", offset " + length_text(offset) +
                       "): " + std::to_string(triangles) + " triangles, Hausdorff distance " +
                       length_text(hausdorff) + " (" + length_text(100.0 * hausdorff / diagonal) +
                       "% of the diagonal)";
    if (ignored_triangles)
        line += "; ignored " + std::to_string(ignored_triangles) + " triangle" + (ignored_triangles == 1 ? "" : "s") +
                " with a missing or non-finite vertex";
    return line;
}

namespace {

// The bounding-box diagonal of the widest hole of `triangles` (a loop of edges each in one triangle
// only; orientation ignored, as a soup's may be inconsistent), or 0 when it is closed.
double widest_hole_extent(const std::vector<Point3>& points, const std::vector<std::array<size_t, 3>>& triangles) {
    std::map<std::pair<size_t, size_t>, int> edge_uses;
    for (const auto& t : triangles)
        for (int k = 0; k < 3; ++k) ++edge_uses[std::minmax(t[k], t[(k + 1) % 3])];
    DisjointSets loops(points.size());
    std::vector<bool> on_hole(points.size(), false);
    for (const auto& [edge, uses] : edge_uses) {
        if (uses != 1) continue;
        loops.unite(static_cast<int32_t>(edge.first), static_cast<int32_t>(edge.second));
        on_hole[edge.first] = on_hole[edge.second] = true;
    }
    std::map<int32_t, Eigen::AlignedBox3d> boxes;
    for (size_t v = 0; v < points.size(); ++v)
        if (on_hole[v])
            boxes[loops.find(static_cast<int32_t>(v))].extend(
                Eigen::Vector3d(points[v].x(), points[v].y(), points[v].z()));
    double widest = 0;
    for (const auto& [root, box] : boxes) widest = std::max(widest, box.diagonal().norm());
    return widest;
}

}  // namespace

WrapResult wrap_surface(const TriangleSurface& soup, const WrapOptions& options, Progress* progress) {
    validate_wrap_options(options, 0.0);  // the sign and finiteness before any work

    // The usable triangles: CGAL's soup oracle asserts valid indices and cannot place non-finite points.
    std::vector<Point3> points;
    points.reserve(soup.points.size());
    for (const auto& p : soup.points) points.emplace_back(p.x(), p.y(), p.z());
    std::vector<std::array<size_t, 3>> triangles;
    triangles.reserve(soup.triangles.size());
    WrapResult result;
    Eigen::AlignedBox3d box;
    for (const auto& t : soup.triangles) {
        bool usable = true;
        for (int32_t i : t) usable = usable && i >= 0 && static_cast<size_t>(i) < soup.points.size() &&
                                     soup.points[i].allFinite();
        if (!usable) {
            ++result.report.ignored_triangles;
            continue;
        }
        triangles.push_back({size_t(t[0]), size_t(t[1]), size_t(t[2])});
        for (int32_t i : t) box.extend(soup.points[i]);
    }
    // The input as a mesh of unconnected triangles (three vertices each), for the distance measured at
    // the end: bounded_error_Hausdorff_distance needs a face graph, and a soup need not be one.
    // Zero-area triangles are left out as the wrap's oracle leaves them out.
    Mesh input;
    input.reserve(3 * triangles.size(), 3 * triangles.size(), triangles.size());
    for (const auto& t : triangles) {
        if (CGAL::collinear(points[t[0]], points[t[1]], points[t[2]])) continue;
        input.add_face(input.add_vertex(points[t[0]]), input.add_vertex(points[t[1]]), input.add_vertex(points[t[2]]));
    }
    if (input.number_of_faces() == 0)
        throw InvalidMeshError("nothing to wrap: no triangle with three finite, non-collinear vertices");
    const double diagonal = box.diagonal().norm();
    validate_wrap_options(options, diagonal);

    WrapReport& report = result.report;
    report.diagonal = diagonal;
    report.alpha = options.alpha.value_or(
        std::clamp(kDefaultWrapAlphaPerHole * widest_hole_extent(points, triangles), kDefaultWrapAlphaFraction * diagonal,
                   kMaxDefaultWrapAlphaFraction * diagonal));
    report.offset = options.offset.value_or(kDefaultWrapOffsetFractionOfAlpha * report.alpha);

    check_cancelled(progress);
    report_stage(progress, "wrapping");
    Mesh wrap;
    CancellingVisitor visitor;
    visitor.progress = progress;
    CGAL::alpha_wrap_3(points, triangles, report.alpha, report.offset, wrap, CGAL::parameters::default_values(),
                       CGAL::parameters::visitor(visitor));
    if (wrap.is_empty() || wrap.number_of_faces() == 0)
        throw AlgorithmError("the alpha wrap produced no surface (alpha " + number_text(report.alpha) + ", offset " +
                             number_text(report.offset) + ")");

    TriangleSurface& surface = result.surface;
    surface.points.reserve(wrap.number_of_vertices());
    for (auto v : wrap.vertices()) {
        const Point3& p = wrap.point(v);
        surface.points.emplace_back(p.x(), p.y(), p.z());
    }
    surface.triangles.reserve(wrap.number_of_faces());
    for (auto f : wrap.faces()) {
        std::array<int32_t, 3> t{};
        int k = 0;
        for (auto v : CGAL::vertices_around_face(wrap.halfedge(f), wrap)) t[k++] = static_cast<int32_t>(v.idx());
        surface.triangles.push_back(t);
    }
    report.triangles = surface.triangles.size();

    // Input to wrap, the direction that sees lost features. Why the bounded-error variant:
    // approximate_Hausdorff_distance samples the input and so can only under-estimate (it misses a
    // narrow cavity between samples), while this one subdivides only the triangles that may still
    // hold the maximum and guarantees the result within the error bound. Why alpha/10 as the bound:
    // the wrap cannot represent detail finer than alpha anyway, and the work grows like 1/bound^2
    // where the whole input lies near the maximum (a convex input, all at about the offset): a unit
    // cube at 1e-4 of its diagonal took over a minute, at alpha/10 well under a second.
    check_cancelled(progress);
    report_stage(progress, "measuring the wrap's distance");
    report.hausdorff = CGAL::Polygon_mesh_processing::bounded_error_Hausdorff_distance<CGAL::Sequential_tag>(
        input, wrap, kWrapHausdorffErrorFractionOfAlpha * report.alpha, CGAL::parameters::match_faces(false),
        CGAL::parameters::match_faces(false));
    return result;
}

}  // namespace waxwork
