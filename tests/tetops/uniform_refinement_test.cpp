// Uniform 1:8 refinement (tetops/uniform_refinement.h): counts, volume, validity, inherited per-tet data,
// boundary projection and shape over levels.
#include "tetops/uniform_refinement.h"

#include "base/error.h"
#include "tetops/connectivity.h"
#include "tetops/icosphere.h"
#include "tetops/quality.h"
#include "tetops/tetrahedralize.h"
#include "test_meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

namespace waxwork {
namespace {

constexpr double kRadius = 10.0;

Eigen::Vector3d onto_sphere(const Eigen::Vector3d& p) { return kRadius * p.normalized(); }

// A coarse TetGen mesh of the icosphere of radius 10 (all its boundary vertices on the sphere).
TetMesh coarse_ball(int surface_level, size_t target_tets) {
    MeshingOptions meshing;
    meshing.sizing.target_tets = target_tets;
    return tetrahedralize(make_icosphere(surface_level, kRadius), meshing).mesh;
}

double mean_edge_length(const TetMesh& mesh) { return measure_quality(mesh).mean_edge_length; }

// What every refinement without projection gives: 8 tets per tet, a vertex per edge, the volume kept,
// a valid mesh and half the mean edge length.
void expect_plain_refinement(const TetMesh& mesh, const TetMesh& fine) {
    EXPECT_EQ(fine.tet_count(), 8 * mesh.tet_count());
    EXPECT_EQ(fine.vertex_count(), mesh.vertex_count() + build_connectivity(mesh).edges.size());
    EXPECT_NEAR(total_volume(fine) / total_volume(mesh), 1.0, 1e-12);
    EXPECT_TRUE(find_invariant_violations(fine).empty());
    const double ratio = mean_edge_length(fine) / mean_edge_length(mesh);
    EXPECT_GE(ratio, 0.45);
    EXPECT_LE(ratio, 0.55);
}

TEST(UniformRefinement, SplitsEveryTetIntoEightAtTheEdgeMidpoints) {
    const TetMesh mesh = testing::make_box_mesh(3, Eigen::Vector3d(-1, 0, 2), Eigen::Vector3d(2, 1.5, 4));
    const TetMesh fine = refine_uniformly(mesh);
    expect_plain_refinement(mesh, fine);
    for (size_t v = 0; v < mesh.vertex_count(); ++v) EXPECT_EQ(fine.positions[v], mesh.positions[v]);
    for (size_t t = 0; t < fine.tet_count(); ++t) ASSERT_GT(signed_volume(fine, t), 0) << t;
    // The children of one tet fill it exactly.
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        double children = 0;
        for (size_t c = 0; c < 8; ++c) children += signed_volume(fine, 8 * t + c);
        EXPECT_NEAR(children, signed_volume(mesh, t), 1e-12 * signed_volume(mesh, t));
    }
}

TEST(UniformRefinement, KeepsAnUnstructuredMeshValidAndItsVolumeWithoutProjection) {
    const TetMesh mesh = coarse_ball(1, 100);
    const TetMesh fine = refine_uniformly(mesh);
    expect_plain_refinement(mesh, fine);
}

TEST(UniformRefinement, ChildrenInheritMaterialOriginalIdAndPiece) {
    TetMesh mesh = testing::make_cube_mesh(2);
    mesh.piece_transforms.resize(2);
    mesh.piece_transforms[1].translation = Eigen::Vector3d(5, 0, 0);
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const double k = 0.01 * static_cast<double>(t + 1);
        mesh.materials.push_back({{k, k, k}, {1.0, 1.0, 1.0}, 1.3});
        mesh.original_ids[t] = static_cast<int32_t>(100 + t);
        mesh.piece_ids[t] = static_cast<int32_t>(t % 2);
    }
    ASSERT_TRUE(find_invariant_violations(mesh).empty());
    const TetMesh fine = refine_uniformly(mesh);
    ASSERT_EQ(fine.tet_count(), 8 * mesh.tet_count());
    ASSERT_EQ(fine.materials.size(), fine.tet_count());
    ASSERT_EQ(fine.original_ids.size(), fine.tet_count());
    ASSERT_EQ(fine.piece_ids.size(), fine.tet_count());
    for (size_t t = 0; t < fine.tet_count(); ++t) {
        EXPECT_EQ(fine.materials[t], mesh.materials[t / 8]) << t;
        EXPECT_EQ(fine.original_ids[t], mesh.original_ids[t / 8]) << t;
        EXPECT_EQ(fine.piece_ids[t], mesh.piece_ids[t / 8]) << t;
    }
    EXPECT_EQ(fine.piece_transforms, mesh.piece_transforms);
    EXPECT_TRUE(find_invariant_violations(fine).empty());

    // Without materials the refined mesh has none either.
    const TetMesh bare = refine_uniformly(testing::make_cube_mesh(1));
    EXPECT_FALSE(bare.has_materials());
    EXPECT_TRUE(find_invariant_violations(bare).empty());
}

TEST(UniformRefinement, ProjectedBoundaryMidpointsLieOnTheSphereAndTheVolumeApproachesTheBall) {
    TetMesh mesh = coarse_ball(1, 100);
    const double ball_volume = 4.0 / 3.0 * std::numbers::pi * kRadius * kRadius * kRadius;
    double previous_gap = ball_volume - total_volume(mesh);
    for (int level = 1; level <= 2; ++level) {
        const TetMesh fine = refine_uniformly(mesh, onto_sphere);
        ASSERT_TRUE(find_invariant_violations(fine).empty()) << level;
        const TetConnectivity connectivity = build_connectivity(fine);
        size_t projected = 0;
        for (const int32_t v : connectivity.boundary_vertices)
            if (static_cast<size_t>(v) >= mesh.vertex_count()) {
                EXPECT_NEAR(fine.positions[v].norm(), kRadius, 1e-12 * kRadius) << v;
                ++projected;
            }
        EXPECT_GT(projected, 0u);
        // Interior midpoints stay at the midpoints.
        const std::vector<std::array<int32_t, 2>> edges = build_connectivity(mesh).edges;
        for (size_t e = 0; e < edges.size(); ++e) {
            const auto v = static_cast<int32_t>(mesh.vertex_count() + e);
            if (!connectivity.is_boundary_vertex[v]) {
                EXPECT_EQ(fine.positions[v], 0.5 * (mesh.positions[edges[e][0]] + mesh.positions[edges[e][1]]));
            }
        }
        // The inscribed polyhedron's missing volume falls by about 4x per level (second order in h).
        const double gap = ball_volume - total_volume(fine);
        EXPECT_GT(gap, 0);
        EXPECT_LT(gap, 0.35 * previous_gap) << level;
        previous_gap = gap;
        mesh = fine;
    }
}

// The smallest dihedral angle of each of four levels (the given mesh refined three times).
std::array<double, 4> min_dihedral_by_level(TetMesh mesh, bool project) {
    std::array<double, 4> mins{mesh_min_dihedral_deg(mesh)};
    double mean_edge = mean_edge_length(mesh);
    for (int level = 1; level <= 3; ++level) {
        mesh = project ? refine_uniformly(mesh, onto_sphere) : refine_uniformly(mesh);
        EXPECT_TRUE(find_invariant_violations(mesh).empty()) << level;
        mins[level] = mesh_min_dihedral_deg(mesh);
        const double edge = mean_edge_length(mesh);
        EXPECT_GE(edge / mean_edge, 0.45) << level;
        EXPECT_LE(edge / mean_edge, 0.55) << level;
        mean_edge = edge;
    }
    std::printf("min dihedral by level (%s projection): %.2f %.2f %.2f %.2f degrees\n", project ? "with" : "without",
                mins[0], mins[1], mins[2], mins[3]);
    return mins;
}

TEST(UniformRefinement, MinimumDihedralAngleDoesNotCollapseOverThreeLevels) {
    // Without projection the children fall into finitely many shapes: after the first splits the smallest
    // angle stops changing.
    const std::array<double, 4> plain = min_dihedral_by_level(coarse_ball(1, 100), false);
    EXPECT_GT(plain[1], 0.5 * plain[0]);
    EXPECT_GE(plain[3], plain[2] - 1e-9);
    EXPECT_GT(plain[3], 0.5 * plain[0]);

    // With projection, on a ball whose tets each have one face on the sphere (TetGen's mesh of the
    // 320-triangle icosphere: one tet per triangle around a centre vertex), the projected midpoints move
    // by h^2 / 8R, a vanishing share of the tets' size h. (The first split of these tall tets, 10 mm
    // high on a base of about 3 mm, makes flatter inner tets from the octahedron; after it the angle holds.)
    const TetMesh star = coarse_ball(2, 400);
    ASSERT_EQ(star.tet_count(), 320u);
    const std::array<double, 4> projected = min_dihedral_by_level(star, true);
    EXPECT_GT(projected[1], 10.0);
    EXPECT_GE(projected[2], 0.8 * projected[1]);
    EXPECT_GE(projected[3], 0.95 * projected[2]);
}

TEST(UniformRefinement, ProjectionFlattensTheDescendantsOfTetsWithTwoFacesOnTheSphere) {
    // TetGen's mesh of the 80-triangle icosphere has no interior vertex: tets with two faces on the
    // sphere, whose descendants keep four vertices near the sphere and get flatter as it looks flatter.
    const std::array<double, 4> mins = min_dihedral_by_level(coarse_ball(1, 100), true);
    EXPECT_LT(mins[3], 0.25 * mins[1]);
}

TEST(UniformRefinement, AProjectionThatInvertsATetIsAnAlgorithmError) {
    const TetMesh mesh = testing::make_cube_mesh(1);
    EXPECT_THROW(refine_uniformly(mesh, [](const Eigen::Vector3d& p) { return Eigen::Vector3d(-5 * p); }),
                 AlgorithmError);
}

}  // namespace
}  // namespace waxwork
