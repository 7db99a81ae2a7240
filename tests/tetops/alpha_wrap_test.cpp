#include "tetops/alpha_wrap.h"

#include "base/error.h"
#include "base/progress.h"
#include "tetops/disjoint_sets.h"
#include "tetops/icosphere.h"
#include "tetops/surface_check.h"
#include "tetops/test_surfaces.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <limits>
#include <set>

namespace waxwork {
namespace {

using testing::combine;
using testing::make_cube_surface;

// Connected components of a surface's triangles (through shared vertices).
size_t component_count(const TriangleSurface& s) {
    DisjointSets sets(s.points.size());
    for (const auto& t : s.triangles) {
        sets.unite(t[0], t[1]);
        sets.unite(t[1], t[2]);
    }
    std::set<int32_t> roots;
    for (const auto& t : s.triangles) roots.insert(sets.find(t[0]));
    return roots.size();
}

// The checks every wrap must pass: what the meshers require (find_surface_defects finds nothing, not
// even a safe repair such as an inward orientation), and a distance that is positive (the wrap
// strictly contains its input) and bounded. Returns the enclosed volume.
double expect_valid_wrap(const WrapResult& r, size_t components, double hausdorff_bound) {
    const SurfaceDefects d = find_surface_defects(r.surface);
    EXPECT_TRUE(d.is_clean()) << [&] {
        std::string all;
        for (const auto& line : d.describe()) all += line + "; ";
        return all;
    }();
    EXPECT_EQ(d.boundary_edges, 0u);
    EXPECT_EQ(d.non_manifold_edges + d.non_manifold_vertices, 0u);
    EXPECT_EQ(d.self_intersecting_pairs, 0u);
    EXPECT_GT(d.signed_volume, 0.0);
    EXPECT_EQ(component_count(r.surface), components);
    EXPECT_EQ(r.report.triangles, r.surface.triangles.size());
    EXPECT_GT(r.report.hausdorff, 0.0);
    EXPECT_LE(r.report.hausdorff, hausdorff_bound);
    return d.signed_volume;
}

// Every triangle with its own three points (no vertex shared), as an STL file stores them.
TriangleSurface as_soup(const TriangleSurface& s) {
    TriangleSurface soup;
    for (const auto& t : s.triangles) {
        const auto first = static_cast<int32_t>(soup.points.size());
        for (int32_t i : t) soup.points.push_back(s.points[i]);
        soup.triangles.push_back({first, first + 1, first + 2});
    }
    return soup;
}

// The distance bound for a convex input: the wrap's vertices lie on the offset surface, at distance
// offset from the input, and its facets are chords of that convex surface, so the wrap lies between
// the input and the offset surface and every input point is within offset of it (plus the
// measurement's error bound, alpha/10). At a concave crease the wrap cannot follow into a gap narrower
// than alpha, so there the bound is alpha + offset.
double measurement_error(const WrapReport& r) { return kWrapHausdorffErrorFractionOfAlpha * r.alpha; }
double convex_bound(const WrapReport& r) { return r.offset + measurement_error(r) + 1e-12; }
double crease_bound(const WrapReport& r) { return r.alpha + r.offset + measurement_error(r); }

TEST(AlphaWrap, DefaultsAreRelativeToTheDiagonal) {
    const WrapResult r = wrap_surface(make_cube_surface(), {});
    EXPECT_DOUBLE_EQ(r.report.diagonal, std::sqrt(3.0));
    EXPECT_DOUBLE_EQ(r.report.alpha, kDefaultWrapAlphaFraction * std::sqrt(3.0));
    EXPECT_DOUBLE_EQ(r.report.offset, kDefaultWrapOffsetFractionOfAlpha * r.report.alpha);
    const double volume = expect_valid_wrap(r, 1, convex_bound(r.report));
    // The wrap contains the cube and lies within its offset surface, inside the box grown by offset.
    EXPECT_GT(volume, 1.0);
    EXPECT_LE(volume, std::pow(1.0 + 2.0 * r.report.offset, 3));
    // On the cube's flat faces the wrap lies on the offset plane: the distance is the offset.
    EXPECT_NEAR(r.report.hausdorff, r.report.offset, measurement_error(r.report));
}

TEST(AlphaWrap, SoupWithUnsharedVerticesAndDuplicatesBecomesOneClosedCube) {
    TriangleSurface soup = as_soup(make_cube_surface());
    for (int k : {0, 5, 7}) soup.triangles.push_back(soup.triangles[k]);  // repeated faces
    soup.triangles.push_back({soup.triangles[3][0], soup.triangles[3][2], soup.triangles[3][1]});  // and flipped
    ASSERT_FALSE(find_surface_defects(soup).describe().empty());  // the meshers refuse it as it is
    const WrapResult r = wrap_surface(soup, {.alpha = 0.05, .offset = 0.005});
    EXPECT_EQ(r.report.alpha, 0.05);
    EXPECT_EQ(r.report.offset, 0.005);
    const double volume = expect_valid_wrap(r, 1, convex_bound(r.report));
    EXPECT_GT(volume, 1.0);
    EXPECT_LE(volume, std::pow(1.0 + 2.0 * r.report.offset, 3));
}

TEST(AlphaWrap, CubeWithHolesIsClosed) {
    TriangleSurface open = make_cube_surface();
    open.triangles.erase(open.triangles.begin() + 2, open.triangles.begin() + 4);  // the top face: a square hole
    open.triangles.erase(open.triangles.begin() + 6);                              // and a triangle of a side
    ASSERT_GT(find_surface_defects(open).boundary_edges, 0u);
    const WrapResult r = wrap_surface(open, {.alpha = 0.05, .offset = 0.005});
    // Over the holes the wrap is laid around the holes' rims: it closes them (the hole is wider than
    // alpha, so the wrap also dips into it, but it stays closed and outside the input).
    const double volume = expect_valid_wrap(r, 1, crease_bound(r.report));
    EXPECT_GT(volume, 0.0);
}

// An open model's holes set the default alpha: wide enough to close the widest hole, so the wrap is a
// solid of about the sphere's volume, not a hollow skin around both sides of the shell (the diagonal's
// D/100 entered bad_stanford-bunny.obj's holes so).
TEST(AlphaWrap, DefaultAlphaClosesTheWidestHole) {
    TriangleSurface open = make_icosphere(2, 1.0);
    Eigen::AlignedBox3d hole;  // one triangle removed: a triangular hole
    for (const int32_t v : open.triangles[0]) hole.extend(open.points[v]);
    open.triangles.erase(open.triangles.begin());
    const WrapResult r = wrap_surface(open, {});
    EXPECT_DOUBLE_EQ(r.report.alpha, kDefaultWrapAlphaPerHole * hole.diagonal().norm());
    EXPECT_GT(r.report.alpha, kDefaultWrapAlphaFraction * r.report.diagonal);
    const double volume = expect_valid_wrap(r, 1, crease_bound(r.report));
    EXPECT_GT(volume, 0.8 * 4.0 / 3.0 * std::numbers::pi);
}

TEST(AlphaWrap, IntersectingCubesBecomeOneComponent) {
    const TriangleSurface two = combine(make_cube_surface(), make_cube_surface(Eigen::Vector3d(0.5, 0.5, 0.5)));
    ASSERT_GT(find_surface_defects(two).self_intersecting_pairs, 0u);
    const WrapResult r = wrap_surface(two, {});
    // Each cube's faces inside the other are buried up to 1/2 below the union's surface (the second
    // cube's corner (0.5, 0.5, 0.5) is 0.5 from the first cube's faces x, y, z = 0 and from the parts of
    // its faces x, y, z = 1 outside the second cube); the distance from the input sees them.
    const double volume = expect_valid_wrap(r, 1, 0.5 + crease_bound(r.report));
    EXPECT_GT(r.report.hausdorff, 0.5);
    // The union of the cubes is 2 - 1/8; the wrap holds it and a thin shell around it.
    EXPECT_GT(volume, 1.875);
    EXPECT_LT(volume, 1.875 * 1.05);
}

TEST(AlphaWrap, DisjointSpheresStayTwoComponents) {
    TriangleSurface b = make_icosphere(3, 1.0);
    for (auto& p : b.points) p.x() += 3.0;
    const WrapResult r = wrap_surface(combine(make_icosphere(3, 1.0), b), {});
    // The icosphere is convex: its wrap stays within the offset.
    expect_valid_wrap(r, 2, convex_bound(r.report));
}

TEST(AlphaWrap, DegenerateTrianglesAreWrappedOver) {
    TriangleSurface s = make_cube_surface();
    s.points.push_back({0.5, 0.0, 0.0});                   // on the edge from vertex 0 to vertex 1
    const auto mid = static_cast<int32_t>(s.points.size() - 1);
    s.triangles.push_back({0, mid, 1});                     // zero area, three distinct vertices
    s.triangles.push_back({0, 0, 1});                       // repeated vertex
    s.triangles.push_back({2, 2, 2});                       // a point
    ASSERT_GT(find_surface_defects(s).zero_area_triangles, 0u);
    const WrapResult r = wrap_surface(s, {.alpha = 0.05, .offset = 0.005});
    const double volume = expect_valid_wrap(r, 1, convex_bound(r.report));
    EXPECT_GT(volume, 1.0);
    EXPECT_LE(volume, std::pow(1.0 + 2.0 * r.report.offset, 3));
}

TEST(AlphaWrap, TrianglesWithMissingOrNonFiniteVerticesAreIgnoredAndCounted) {
    TriangleSurface s = make_cube_surface();
    s.points.push_back({std::numeric_limits<double>::quiet_NaN(), 0, 0});
    s.triangles.push_back({0, 1, 8});   // non-finite vertex
    s.triangles.push_back({0, 1, 42});  // missing vertex
    const WrapResult r = wrap_surface(s, {});
    EXPECT_EQ(r.report.ignored_triangles, 2u);
    expect_valid_wrap(r, 1, convex_bound(r.report));
    EXPECT_NE(r.report.describe().find("ignored 2 triangles with a missing or non-finite vertex"), std::string::npos)
        << r.report.describe();
}

TEST(AlphaWrap, ReportLine) {
    const WrapResult r = wrap_surface(make_cube_surface(), {.alpha = 0.05, .offset = 0.005});
    const std::string line = r.report.describe();
    EXPECT_EQ(line.rfind("wrapped (alpha 0.05, offset 0.005): " + std::to_string(r.report.triangles) +
                             " triangles, Hausdorff distance ",
                         0),
              0u)
        << line;
    EXPECT_NE(line.find("% of the diagonal)"), std::string::npos) << line;
}

TEST(AlphaWrap, BadOptionsAreRefusedNamingTheOption) {
    const TriangleSurface cube = make_cube_surface();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    struct Case {
        WrapOptions options;
        std::string expected;
    };
    for (const Case& c : {Case{{.alpha = -1.0, .offset = {}}, "--wrap-alpha: must be a positive length"},
                          Case{{.alpha = 0.0, .offset = {}}, "--wrap-alpha: must be a positive length"},
                          Case{{.alpha = nan, .offset = {}}, "--wrap-alpha: must be a positive length"},
                          Case{{.alpha = {}, .offset = -0.1}, "--wrap-offset: must be a positive length"},
                          Case{{.alpha = {}, .offset = INFINITY}, "--wrap-offset: must be a positive length"},
                          // The cube's diagonal is sqrt(3): alpha below sqrt(3)/2000 is refused.
                          Case{{.alpha = 5e-4, .offset = {}}, "--wrap-alpha: 0.0005 is below 0.0005 of the model's diagonal"},
                          Case{{.alpha = {}, .offset = 1e-7}, "--wrap-offset: 1e-07 is below 1e-06 of the model's diagonal"}}) {
        try {
            wrap_surface(cube, c.options);
            ADD_FAILURE() << c.expected;
        } catch (const InvalidArgumentError& e) {
            EXPECT_EQ(std::string(e.what()).rfind(c.expected, 0), 0u) << e.what();
        }
    }
    EXPECT_NO_THROW(validate_wrap_options({.alpha = 1e-3, .offset = 2e-6}, std::sqrt(3.0)));
}

TEST(AlphaWrap, NothingToWrapIsAnInvalidMesh) {
    TriangleSurface s;
    s.points = {{0, 0, 0}};
    s.triangles = {{0, 0, 0}};
    EXPECT_THROW(wrap_surface(s, {}), InvalidMeshError);
}

// Cancellation reaches into CGAL's flood fill through the wrapper's visitor: asked to stop once the
// wrap has started, it stops there, before the distance is measured.
TEST(AlphaWrap, CancellationStopsTheFloodFill) {
    struct CancelOnWrapping : Progress {
        void on_stage(const std::string& stage) override {
            if (stage == "wrapping") request_cancel();
        }
    } progress;
    try {
        wrap_surface(make_icosphere(4, 1.0), {.alpha = 0.01, .offset = {}}, &progress);
        ADD_FAILURE() << "not cancelled";
    } catch (const CancelledError&) {
        EXPECT_EQ(progress.stage(), "wrapping");
    }
}

}  // namespace
}  // namespace waxwork
