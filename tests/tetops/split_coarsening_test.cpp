// Collapsing the vertices of splits nothing needs any more (tetops/split_coarsening.h): a cube split
// by two planes, the second of which swallows the first on its positive side, as a later Voronoi cell
// swallows an earlier wall.
#include "base/error.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/exact_cut.h"
#include "tetops/mesh_checks.h"
#include "tetops/quality.h"
#include "tetops/split_coarsening.h"
#include "tetops/split_quality.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>

namespace waxwork {
namespace {

using testing::make_cube_mesh;
using testing::on_unit_cube_boundary;

const PlaneCut kFirst(Eigen::Vector3d(1, 0.3, 0.2), 0.52);
const PlaneCut kSecond(Eigen::Vector3d(-0.2, 1, 0.35), 0.61);

// Region of a tet: 2 on the second plane's positive side, else 1 or 0 by the first plane's side.
int64_t region(bool first_positive, bool second_positive) { return second_positive ? 2 : (first_positive ? 1 : 0); }

struct SplitCube {
    TetMesh mesh = make_cube_mesh(6);
    size_t vertices_before = mesh.vertex_count();
    std::vector<int64_t> labels = std::vector<int64_t>(mesh.tet_count(), 0);
    std::vector<double> reference = std::vector<double>(mesh.tet_count(), std::numeric_limits<double>::quiet_NaN());
    std::vector<VertexOrigin> origins;
    std::vector<uint8_t> first_positive = std::vector<uint8_t>(mesh.tet_count(), 0);
};

// Without snapping or smoothing nothing moves, so every vertex the splits made lies exactly on the
// edge its origin names.
SplitCube split_cube() {
    SplitCube s;
    for (size_t v = 0; v < s.vertices_before; ++v) s.origins.push_back(VertexOrigin::vertex(static_cast<int32_t>(v)));
    SplitOptions options;
    options.snap_fraction = 0;
    options.smooth_below_deg = 0;
    options.tet_labels = &s.labels;
    options.reference_deg = &s.reference;
    for (const PlaneCut* plane : {&kFirst, &kSecond}) {
        std::vector<Eigen::Vector3d> world = s.mesh.positions;
        std::vector<double> values(world.size());
        for (size_t v = 0; v < world.size(); ++v) values[v] = plane->side(world[v]);
        const SplitReport report = split_along_field(s.mesh, world, values, CuttingSurfaceField(*plane), options);
        s.reference = report.reference_deg;
        s.origins.insert(s.origins.end(), report.appended_vertex_origins.begin(), report.appended_vertex_origins.end());
        for (int32_t parent : report.appended_parents) {
            s.labels.push_back(s.labels[static_cast<size_t>(parent)]);
            s.first_positive.push_back(s.first_positive[static_cast<size_t>(parent)]);
        }
        for (size_t t = 0; t < s.mesh.tet_count(); ++t) {
            if (plane == &kFirst) s.first_positive[t] = report.positive[t];
            s.labels[t] = region(s.first_positive[t], plane == &kSecond && report.positive[t]);
        }
    }
    return s;
}

std::map<int64_t, double> volume_by_label(const TetMesh& mesh, const std::vector<int64_t>& labels) {
    std::map<int64_t, double> volume;
    for (size_t t = 0; t < mesh.tet_count(); ++t) volume[labels[t]] += signed_volume(mesh, t);
    return volume;
}

TEST(CollapseSplitVertices, RemovesTheSwallowedWallAndKeepsTheOthersFlat) {
    SplitCube s = split_cube();
    const TetMesh before = s.mesh;
    const auto volumes_before = volume_by_label(s.mesh, s.labels);
    const double worst_before = mesh_min_dihedral_deg(s.mesh);
    const size_t under_before = count_tets_under_guard(s.mesh, s.reference, 0.5);

    const SplitCoarsening result =
        collapse_unneeded_split_vertices(s.mesh, s.labels, s.reference, s.origins, s.vertices_before, 5.0, 0.5);
    EXPECT_GT(result.vertices_collapsed, 0u);
    EXPECT_GT(result.tets_removed, 0u);
    EXPECT_EQ(s.mesh.vertex_count() + result.vertices_collapsed, before.vertex_count());
    EXPECT_EQ(s.mesh.tet_count() + result.tets_removed, before.tet_count());
    ASSERT_EQ(s.labels.size(), s.mesh.tet_count());
    ASSERT_EQ(s.reference.size(), s.mesh.tet_count());
    ASSERT_EQ(s.origins.size(), s.mesh.vertex_count());
    testing::expect_valid_conforming(s.mesh);

    // Each region keeps its volume, and its tets stay on their sides of both planes: the walls
    // between regions are where they were.
    const auto volumes_after = volume_by_label(s.mesh, s.labels);
    ASSERT_EQ(volumes_after.size(), 3u);
    for (const auto& [label, volume] : volumes_before) EXPECT_NEAR(volumes_after.at(label), volume, 1e-12) << label;
    for (size_t t = 0; t < s.mesh.tet_count(); ++t) {
        for (int32_t v : s.mesh.tets[t]) {
            const Eigen::Vector3d& p = s.mesh.positions[static_cast<size_t>(v)];
            const double first = kFirst.side(p), second = kSecond.side(p);
            switch (s.labels[t]) {
            case 0: EXPECT_TRUE(first <= 1e-12 && second <= 1e-12) << t; break;
            case 1: EXPECT_TRUE(first >= -1e-12 && second <= 1e-12) << t; break;
            default: EXPECT_GE(second, -1e-12) << t; break;
            }
        }
    }
    // Inside region 2 no vertex of the first plane is left but those a kept vertex names or the
    // cube's boundary holds; the outer surface is the cube's.
    const TetConnectivity c = build_connectivity(s.mesh);
    for (const BoundaryFace& f : c.boundary_faces)
        for (int32_t v : f.vertices) EXPECT_TRUE(on_unit_cube_boundary(s.mesh.positions[static_cast<size_t>(v)]));

    // The origins of the vertices left are exact: lower indices, and the vertex on that edge.
    for (size_t v = s.vertices_before; v < s.mesh.vertex_count(); ++v) {
        const auto [a, b, t] = s.origins[v];
        ASSERT_TRUE(a >= 0 && b >= 0 && static_cast<size_t>(a) < v && static_cast<size_t>(b) < v && a != b) << v;
        const Eigen::Vector3d on_edge = (1 - t) * s.mesh.positions[static_cast<size_t>(a)] + t * s.mesh.positions[static_cast<size_t>(b)];
        EXPECT_LT((on_edge - s.mesh.positions[v]).norm(), 1e-12) << v;
    }
    for (size_t v = 0; v < s.vertices_before; ++v) EXPECT_TRUE(s.origins[v] == VertexOrigin::vertex(static_cast<int32_t>(v)));

    // Quality: nothing under min(5 degrees, the worst before), and no more tets under the guard.
    EXPECT_GE(mesh_min_dihedral_deg(s.mesh), std::min(5.0, worst_before));
    EXPECT_LE(count_tets_under_guard(s.mesh, s.reference, 0.5), under_before);
}

TEST(CollapseSplitVertices, OneRegionPerSideOfEachWallCollapsesNothing) {
    // Label every side of both planes apart: each vertex the splits made is on a wall and stays.
    SplitCube s = split_cube();
    for (size_t t = 0; t < s.mesh.tet_count(); ++t) {
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (int32_t v : s.mesh.tets[t]) centroid += 0.25 * s.mesh.positions[static_cast<size_t>(v)];
        s.labels[t] = (kFirst.side(centroid) > 0 ? 1 : 0) + (kSecond.side(centroid) > 0 ? 2 : 0);
    }
    const TetMesh before = s.mesh;
    const SplitCoarsening result =
        collapse_unneeded_split_vertices(s.mesh, s.labels, s.reference, s.origins, s.vertices_before, 5.0, 0.5);
    EXPECT_EQ(result.vertices_collapsed, 0u);
    EXPECT_EQ(s.mesh, before);
}

TEST(CollapseSplitVertices, RefusesMismatchedArraysAndAngles) {
    SplitCube s = split_cube();
    std::vector<int64_t> short_labels(s.labels.begin(), s.labels.end() - 1);
    EXPECT_THROW(collapse_unneeded_split_vertices(s.mesh, short_labels, s.reference, s.origins, s.vertices_before, 5, 0.5),
                 InvalidArgumentError);
    for (double bad : {0.0, -1.0, 70.0, std::numeric_limits<double>::quiet_NaN()})
        EXPECT_THROW(collapse_unneeded_split_vertices(s.mesh, s.labels, s.reference, s.origins, s.vertices_before, bad, 0.5),
                     InvalidArgumentError)
            << bad;
    EXPECT_THROW(collapse_unneeded_split_vertices(s.mesh, s.labels, s.reference, s.origins, s.vertices_before, 5, -1),
                 InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
