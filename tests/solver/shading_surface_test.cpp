#include "solver/shading_surface.h"

#include "base/error.h"
#include "solver/diffusion_matrix.h"
#include "solver/material.h"
#include "solver/radiance.h"
#include "solver/solver_test_meshes.h"
#include "tetops/connectivity.h"
#include "tetops/test_meshes.h"

#include "io/surface_reader.h"
#include "tetops/tetrahedralize.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <iostream>
#include <map>
#include <set>
#include <string>

namespace waxwork {
namespace {

BoundarySurface surface_of(const TetMesh& mesh) {
    return extract_boundary_surface(mesh, build_connectivity(mesh), {});
}

Eigen::Vector3d face_normal(const BoundarySurface& surface, const std::array<int32_t, 3>& t) {
    const auto& p = surface.positions;
    return (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]).normalized();
}

// How many of the cube's faces (0 <= x, y, z <= side) a point lies on.
int faces_touching(const Eigen::Vector3d& p, double side) {
    int faces = 0;
    for (int k = 0; k < 3; ++k) faces += std::abs(p[k]) < 1e-12 || std::abs(p[k] - side) < 1e-12;
    return faces;
}

bool is_split_copy(const ShadingSurface& shading, int32_t d) {
    return std::binary_search(shading.split_copies.begin(), shading.split_copies.end(), d);
}

TEST(ShadingSurface, CubeSplitsIntoOneCopyPerFaceAtEdgesAndCorners) {
    const int n = 3;
    const BoundarySurface surface = surface_of(test::make_cube_mesh(n));
    const ShadingSurface shading = split_at_creases(surface);
    const size_t m = surface.vertices.size();

    // A copy per face a vertex lies on: edge vertices get one more, corners two more.
    std::vector<int> copies(m, 0);
    for (const int32_t s : shading.surface_vertex) ++copies[s];
    size_t expected_extra = 0;
    for (size_t s = 0; s < m; ++s) {
        const int faces = faces_touching(surface.positions[s], n);
        EXPECT_EQ(copies[s], faces) << surface.positions[s].transpose();
        expected_extra += faces - 1;
    }
    EXPECT_EQ(expected_extra, static_cast<size_t>(12 * (n - 1) + 8 * 2));
    EXPECT_EQ(shading.size(), m + expected_extra);
    for (size_t d = 0; d < m; ++d) EXPECT_EQ(shading.surface_vertex[d], static_cast<int32_t>(d));

    // Same triangles, corners renumbered to copies that have the triangle's own (face) normal.
    ASSERT_EQ(shading.triangles.size(), surface.triangles.size());
    for (size_t t = 0; t < surface.triangles.size(); ++t) {
        const Eigen::Vector3d normal = face_normal(surface, surface.triangles[t]);
        for (int k = 0; k < 3; ++k) {
            const int32_t d = shading.triangles[t][k];
            EXPECT_EQ(shading.surface_vertex[d], surface.triangles[t][k]);
            EXPECT_LT((shading.normals[d] - normal).norm(), 1e-12) << "triangle " << t;
        }
    }
    // The split copies are exactly the copies of the vertices on edges, ascending and unique.
    EXPECT_TRUE(std::is_sorted(shading.split_copies.begin(), shading.split_copies.end()));
    EXPECT_EQ(std::adjacent_find(shading.split_copies.begin(), shading.split_copies.end()), shading.split_copies.end());
    for (size_t d = 0; d < shading.size(); ++d) {
        const bool on_edge = faces_touching(surface.positions[shading.surface_vertex[d]], n) > 1;
        EXPECT_EQ(is_split_copy(shading, static_cast<int32_t>(d)), on_edge) << d;
        // Face interiors keep the surface's normal bit for bit.
        if (!on_edge) {
            EXPECT_EQ(shading.normals[d], surface.normals[shading.surface_vertex[d]]);
        }
    }
}

// Spot as TetGen meshes it for the solver tests (its own triangles kept, about 50K tets): a smooth
// model whose coarse triangles turn by more than 40 degrees only at horn, ear and udder tips. The
// default crease angle must leave it almost unsplit (the figure kDefaultCreaseAngleDegrees quotes).
TEST(ShadingSurface, SmoothModelsSplitAlmostNothingAtTheDefaultAngle) {
    MeshingOptions options;
    options.sizing.target_tets = 50'000;
    const TetMesh spot =
        tetrahedralize(load_closed_surface(std::string(WAXWORK_ASSET_DIR) + "/meshes/spot.obj").surface, options).mesh;
    const BoundarySurface surface = surface_of(spot);
    std::set<int32_t> split_vertices;
    const ShadingSurface shading = split_at_creases(surface);
    for (const int32_t d : shading.split_copies) split_vertices.insert(shading.surface_vertex[d]);
    const double fraction = static_cast<double>(split_vertices.size()) / surface.vertices.size();
    std::cout << "spot, " << spot.tet_count() << " tets: " << split_vertices.size() << " of " << surface.vertices.size()
              << " surface vertices split at " << kDefaultCreaseAngleDegrees << " degrees, "
              << split_at_creases(surface, 20.0).size() - surface.vertices.size() << " copies at 20 degrees\n";
    EXPECT_LT(fraction, 0.02);
}

TEST(ShadingSurface, AStraightAngleSplitsNothingAndSmoothModelsKeepTheirNormals) {
    const BoundarySurface cube = surface_of(test::make_cube_mesh(2));
    const ShadingSurface unsplit = split_at_creases(cube, 180.0);
    EXPECT_EQ(unsplit.size(), cube.vertices.size());
    EXPECT_EQ(unsplit.normals, cube.normals);
    EXPECT_EQ(unsplit.triangles, cube.triangles);
    EXPECT_TRUE(unsplit.split_copies.empty());
    // A cube's edges turn by 90 degrees: just under that keeps them whole, just over splits them.
    EXPECT_EQ(split_at_creases(cube, 90.5).size(), cube.vertices.size());
    EXPECT_GT(split_at_creases(cube, 89.5).size(), cube.vertices.size());

    // A tet-meshed ball turns by a few degrees between neighbouring triangles: nothing splits, and
    // every shaded value equals the unsplit one.
    const BoundarySurface ball = surface_of(test::make_ball_mesh(3, 3000));
    const ShadingSurface shading = split_at_creases(ball);
    EXPECT_TRUE(shading.split_copies.empty());
    EXPECT_EQ(shading.normals, ball.normals);
    EXPECT_EQ(shading.triangles, ball.triangles);
    // At 0 degrees every vertex not on a plane splits into one copy per triangle (faceted shading).
    const ShadingSurface faceted = split_at_creases(ball, 0.0);
    size_t corners = 0;
    for (const auto& t : ball.triangles) corners += t.size();
    EXPECT_EQ(faceted.size(), corners);
}

// Coplanar triangles whose normals differ only by rounding (a cube turned by an arbitrary rotation)
// stay one fan even at 0 degrees: the cube splits at 0 exactly as at 40.
TEST(ShadingSurface, RoundingDoesNotSplitCoplanarTrianglesAtZeroDegrees) {
    BoundarySurface cube = surface_of(test::make_cube_mesh(4));
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    for (Eigen::Vector3d& p : cube.positions) p = turn * p + Eigen::Vector3d(1e3, -2e3, 0.5);
    cube.normals = area_weighted_normals(cube.positions, cube.triangles);
    const ShadingSurface at_zero = split_at_creases(cube, 0.0), at_forty = split_at_creases(cube);
    EXPECT_EQ(at_zero.surface_vertex, at_forty.surface_vertex);
    EXPECT_EQ(at_zero.triangles, at_forty.triangles);
}

// A hand-made surface: vertex 0 at the centre of a flat fan of four triangles, one of them of zero
// area, then a fifth folded up by 60 degrees.
BoundarySurface flat_fan_with_a_fold() {
    BoundarySurface s;
    const double c = std::cos(M_PI / 3), h = std::sin(M_PI / 3);
    s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {-1, 0, 0}, {0, -1, 0}, {c, -1, h}};
    s.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}, {0, 5, 1}};
    // Fold: the last triangle's far corner lifted (vertex 6 replaces 1 there).
    s.triangles[4] = {0, 5, 6};
    s.vertices = {0, 1, 2, 3, 4, 5, 6};
    s.normals = area_weighted_normals(s.positions, s.triangles);
    s.eta.assign(s.positions.size(), 1.3);
    return s;
}

TEST(ShadingSurface, DegenerateTrianglesJoinTheirFanAndFoldsSplit) {
    const BoundarySurface surface = flat_fan_with_a_fold();
    const ShadingSurface shading = split_at_creases(surface, 30.0);
    // Vertex 0: the flat fan (with the zero-area triangle 2, vertices 3 and 4 coincide) and the folded
    // triangle: two copies; vertex 5 on the fold too.
    std::map<int32_t, int> copies;
    for (const int32_t s : shading.surface_vertex) ++copies[s];
    EXPECT_EQ(copies[0], 2);
    EXPECT_EQ(copies[5], 2);
    EXPECT_EQ(copies[3], 1);
    EXPECT_EQ(copies[4], 1);
    // The flat fan's copy of vertex 0 faces +z exactly; no copy has a zero or non-finite normal.
    EXPECT_LT((shading.normals[0] - Eigen::Vector3d(0, 0, 1)).norm(), 1e-12);
    for (const Eigen::Vector3d& normal : shading.normals) EXPECT_NEAR(normal.norm(), 1.0, 1e-12);
    // Triangles 0-3 share vertex 0's first copy; the folded one has the other.
    for (int t = 0; t < 4; ++t) EXPECT_EQ(shading.triangles[t][0], 0);
    EXPECT_NE(shading.triangles[4][0], 0);
    EXPECT_EQ(shading.surface_vertex[shading.triangles[4][0]], 0);
}

TEST(ShadingSurface, TetsMeetingAtAVertexOnlyGetACopyEach) {
    // Two tets sharing vertex 0 only: the boundary is not a manifold there. Below 180 degrees the
    // vertex has a copy per tet even where each tet's own faces would stay one fan.
    TetMesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
    mesh.tets = {{0, 1, 2, 3}, {0, 4, 6, 5}};
    mesh.original_ids = {0, 1};
    mesh.piece_ids = {0, 0};
    mesh.piece_transforms = {RigidTransform{}};
    ASSERT_GT(signed_volume(mesh.positions[0], mesh.positions[1], mesh.positions[2], mesh.positions[3]), 0);
    ASSERT_GT(signed_volume(mesh.positions[0], mesh.positions[4], mesh.positions[6], mesh.positions[5]), 0);
    const BoundarySurface surface = surface_of(mesh);
    const auto apex = std::find(surface.vertices.begin(), surface.vertices.end(), 0) - surface.vertices.begin();
    const auto copies_of_apex = [&](const ShadingSurface& shading) {
        return std::count(shading.surface_vertex.begin(), shading.surface_vertex.end(), apex);
    };
    EXPECT_EQ(copies_of_apex(split_at_creases(surface, 179.0)), 2);
    EXPECT_EQ(copies_of_apex(split_at_creases(surface, 180.0)), 1);
}

TEST(ShadingSurface, RefusesBadAnglesAndTriangles) {
    const BoundarySurface surface = surface_of(test::make_cube_mesh(1));
    for (const double bad : {-1.0, 180.5, std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity()}) {
        try {
            split_at_creases(surface, bad);
            ADD_FAILURE() << bad << " was accepted";
        } catch (const InvalidArgumentError& e) {
            EXPECT_NE(std::string(e.what()).find("crease angle"), std::string::npos) << e.what();
        }
    }
    BoundarySurface broken = surface;
    broken.triangles[3][1] = static_cast<int32_t>(broken.positions.size());
    EXPECT_THROW(split_at_creases(broken), InvalidArgumentError);
    broken = surface;
    broken.normals.pop_back();
    EXPECT_THROW(split_at_creases(broken), InvalidArgumentError);
}

// A unit cube lit from straight above: its top face takes the light, its sides are grazed.
struct LitCube {
    BoundarySurface surface = surface_of(test::make_cube_mesh(3));
    Lighting lighting;
    LitCube() {
        lighting.lights.push_back({LightType::Directional, Eigen::Vector3d(0, -1, 0), {2, 2, 2}});
        lighting.ambient = {0.01, 0.01, 0.01};
    }
};

// A surface's light, its split at the default angle and the copies' light, as the renderer makes them.
struct LitShading {
    TriangleBvh bvh;
    std::vector<float> visibility;
    std::vector<Rgb> q;
    ShadingSurface shading;
    ShadingLight light;
    LitShading(const BoundarySurface& surface, const Lighting& lighting)
        : bvh(build_shadow_bvh(surface)),
          q(incident_light(surface, bvh, lighting, &visibility)),
          shading(split_at_creases(surface)),
          light(shading_light(surface, shading, bvh, lighting, q, visibility)) {}
};

TEST(ShadingLight, EachCopyIsLitWithItsOwnNormal) {
    const LitCube cube;
    const LitShading lit(cube.surface, cube.lighting);
    const auto& [bvh, visibility, q, shading, light] = lit;
    ASSERT_EQ(light.q.size(), shading.size());
    ASSERT_EQ(light.visibility.size(), shading.size());
    const double top = 0.01 + 2 * fresnel_transmittance(1.0, 1.3);
    size_t top_edge_copies = 0;
    for (size_t d = 0; d < shading.size(); ++d) {
        const int32_t s = shading.surface_vertex[d];
        if (!is_split_copy(shading, static_cast<int32_t>(d))) {
            EXPECT_EQ(light.q[d], q[s]);  // bit for bit
            EXPECT_EQ(light.visibility[d], visibility[s]);
            continue;
        }
        // Copies on the top face get the full light; side copies only the ambient, where the
        // averaged normal of their vertex gave them a share of the top's.
        const bool faces_up = shading.normals[d].y() > 0.99;
        EXPECT_NEAR(light.q[d][0], faces_up ? top : 0.01, 1e-12) << cube.surface.positions[s].transpose();
        if (!faces_up && cube.surface.positions[s].y() > 3 - 1e-12) {
            EXPECT_GT(q[s][0], 0.5) << "the vertex's own q mixes the top's light in";
            ++top_edge_copies;
        }
    }
    EXPECT_EQ(top_edge_copies, 4u * 2 * 1 + 4u * 2);  // 4 edges x 2 inner points x 1 side, 4 corners x 2 sides
    // Without the visibility of the surface, none for the copies either.
    EXPECT_TRUE(shading_light(cube.surface, shading, bvh, cube.lighting, q, {}).visibility.empty());
    // Sizes that do not fit are refused.
    std::vector<Rgb> short_q = q;
    short_q.pop_back();
    EXPECT_THROW(shading_light(cube.surface, shading, bvh, cube.lighting, short_q, visibility), InvalidArgumentError);
    EXPECT_THROW(shading_light(cube.surface, shading, bvh, cube.lighting, q, std::vector<float>(3)),
                 InvalidArgumentError);
}

TEST(ShadingLight, SplitCopiesCastTheirOwnShadowRays) {
    // An L: a floor [0, 2] x [0, 1] with a tower [0, 1] x [1, 2] on its left half, lit from the upper
    // left. The tower shades the floor's top. Along the concave edge where the two meet, the averaged
    // normal faces away from the light, so the vertex itself casts no ray (visibility 1, the renderer's
    // n.l test darkens it); its floor copy faces the light and must find the tower in the way.
    const TetMesh mesh = testing::make_cell_mesh(2, 2, 1, [](int i, int j, int) { return j == 0 || i == 0; });
    const BoundarySurface surface = surface_of(mesh);
    Lighting lighting;
    lighting.lights.push_back({LightType::Directional, Eigen::Vector3d(1, -0.3, 0), {1, 1, 1}});
    lighting.ambient = {0.01, 0.01, 0.01};
    const LitShading lit(surface, lighting);
    const auto& [bvh, visibility, q, shading, light] = lit;
    size_t floor_copies = 0;
    for (size_t d = 0; d < shading.size(); ++d) {
        const int32_t s = shading.surface_vertex[d];
        const Eigen::Vector3d& p = surface.positions[s];
        const bool concave_edge = std::abs(p.x() - 1) < 1e-12 && std::abs(p.y() - 1) < 1e-12;
        if (!concave_edge || shading.normals[d].y() < 0.99) continue;
        ++floor_copies;
        EXPECT_EQ(visibility[s], 1.0f) << "the vertex faced away and cast no ray";
        EXPECT_EQ(light.visibility[d], 0.0f) << p.transpose();
        EXPECT_NEAR(light.q[d][0], 0.01, 1e-12) << p.transpose();
    }
    EXPECT_EQ(floor_copies, 2u);  // z = 0 and z = 1
}

// The light Eq. 12's source S_i q_i carries into the volume, summed over the surface: the lumped
// integral of q (S_i = a third of the area of each triangle at vertex i).
double source_power(const BoundarySurface& surface, const std::vector<Rgb>& q, int channel) {
    std::vector<double> area(surface.positions.size(), 0.0);
    for (const auto& [a, b, c] : surface.triangles) {
        const double third =
            (surface.positions[b] - surface.positions[a]).cross(surface.positions[c] - surface.positions[a]).norm() / 6;
        area[a] += third;
        area[b] += third;
        area[c] += third;
    }
    double power = 0;
    for (size_t s = 0; s < q.size(); ++s) power += area[s] * q[s][channel];
    return power;
}

TEST(SourceLight, IntegratesEachSideOfACreaseWithItsOwnLight) {
    // A 3-unit cube lit from straight above: the exact integral of q is the top's 9 units of area at
    // full light, plus the ambient over all 54. With the averaged normals the vertices along the top's
    // rim carry light at 45 degrees into the sides' share of their area as well.
    const LitCube cube;
    const LitShading lit(cube.surface, cube.lighting);
    const auto& [bvh, visibility, q, shading, light] = lit;
    const std::vector<Rgb> source = source_light(cube.surface, shading, light.q);
    ASSERT_EQ(source.size(), q.size());

    const double top = 2 * fresnel_transmittance(1.0, 1.3);
    const double exact = 9 * top + 54 * 0.01;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(source_power(cube.surface, source, c), exact, 1e-12 * exact);
    const double averaged = source_power(cube.surface, q, 0);
    std::cout << "cube lit from above: the averaged normals carry " << averaged / exact
              << " times the light the faces receive\n";
    EXPECT_GT(averaged, 1.1 * exact);

    for (size_t s = 0; s < q.size(); ++s) {
        if (!is_split_copy(shading, static_cast<int32_t>(s))) {
            EXPECT_EQ(source[s], q[s]);  // bit for bit away from creases
            continue;
        }
        // The side copies receive the ambient only, so a split vertex's light lies between the
        // ambient and the top's, and below what its averaged normal received.
        EXPECT_GE(source[s][0], 0.01 - 1e-15);
        EXPECT_LE(source[s][0], q[s][0] + 1e-15);
    }

    // Nothing split, nothing changed: at 180 degrees the solve's light is incident_light's.
    const ShadingSurface unsplit = split_at_creases(cube.surface, 180.0);
    EXPECT_EQ(source_light(cube.surface, unsplit, shading_light(cube.surface, unsplit, bvh, cube.lighting, q, visibility).q),
              q);

    std::vector<Rgb> short_q = light.q;
    short_q.pop_back();
    EXPECT_THROW(source_light(cube.surface, shading, short_q), InvalidArgumentError);
    EXPECT_THROW(source_light(cube.surface, shading, q), InvalidArgumentError);  // per surface vertex, not copy
}

// The right-hand side with the corners' light (corner_light + add_corner_light) against Eq. 12 written
// out face by face: every boundary face f adds its source weight 8 S_f / (A_f (1 - F_dr,f)) times its
// face mass (lumped S_f / 3 on the diagonal; FEM S_f / 6 and S_f / 12) times the light of ITS corners,
// the q of the shading copy each corner belongs to. The cube's tets get four different etas, so the
// faces on either side of an edge weigh their light differently: the case where source_light's
// area-weighted mean alone is not exact even for the lumped source.
TEST(CornerLight, MakesTheRightHandSideIntegrateEachFacesOwnLight) {
    const TetMesh mesh = test::make_cube_mesh(3);
    const TetConnectivity connectivity = build_connectivity(mesh);
    std::vector<TetMaterial> materials(mesh.tet_count(), material_preset("marble"));
    for (size_t t = 0; t < materials.size(); ++t) materials[t].eta = 1.0 + 0.15 * static_cast<double>(t % 4);
    const BoundarySurface surface = extract_boundary_surface(mesh, connectivity, materials);
    Lighting lighting;  // oblique: every face gets its own light, three in shade
    lighting.lights.push_back({LightType::Directional, Eigen::Vector3d(0.5, -1, -0.3), {1, 1, 1}});
    lighting.ambient = {0.01, 0.01, 0.01};
    const LitShading lit(surface, lighting);
    const std::vector<Rgb> source = source_light(surface, lit.shading, lit.light.q);
    const std::vector<CornerLight> corners = corner_light(surface, lit.shading, lit.light.q, source);
    ASSERT_FALSE(corners.empty());
    for (const CornerLight& corner : corners) {  // only corners at split vertices, whose light differs
        const auto& face = connectivity.boundary_faces[corner.face];
        EXPECT_EQ(corner.tet, face.tet);
        EXPECT_TRUE(std::is_permutation(corner.vertices.begin(), corner.vertices.end(), face.vertices.begin()));
        EXPECT_NE(corner.delta, (Rgb{0, 0, 0}));
    }
    const std::vector<Rgb> q = to_volume_vertices(surface, source, mesh.vertex_count());

    for (const Discretization discretization : {Discretization::TransCut, Discretization::Fem}) {
        AssemblyOptions options;
        options.discretization = discretization;
        const DiffusionMatrix matrix = assemble_diffusion_matrix(mesh, connectivity, materials, options);
        for (int c = 0; c < 3; ++c) {
            std::vector<double> expected(matrix.size(), 0.0);
            for (size_t t = 0; t < surface.triangles.size(); ++t) {
                const auto& tri = surface.triangles[t];
                const double area =
                    0.5 * (surface.positions[tri[1]] - surface.positions[tri[0]])
                              .cross(surface.positions[tri[2]] - surface.positions[tri[0]])
                              .norm();
                const double eta = materials[surface.triangle_tets[t]].eta;
                const double fdr = diffuse_fresnel_reflectance(eta);
                const double weight = 8.0 * area / (boundary_reflection_parameter(eta) * (1 - fdr));
                for (int j = 0; j < 3; ++j) {
                    const double light = lit.light.q[lit.shading.triangles[t][j]][c];
                    for (int i = 0; i < 3; ++i) {
                        const double mass = discretization == Discretization::TransCut ? (i == j ? 1.0 / 3 : 0.0)
                                                                                       : (i == j ? 1.0 / 6 : 1.0 / 12);
                        expected[surface.vertices[tri[i]]] += weight * mass * light;
                    }
                }
            }
            std::vector<double> b(matrix.size()), without(matrix.size());
            diffusion_right_hand_side(matrix, q, c, without);
            b = without;
            add_corner_light(matrix, corners, c, b);
            double worst = 0, worst_without = 0, scale = 0;
            for (size_t i = 0; i < b.size(); ++i) {
                worst = std::max(worst, std::abs(b[i] - expected[i]));
                worst_without = std::max(worst_without, std::abs(without[i] - expected[i]));
                scale = std::max(scale, std::abs(expected[i]));
            }
            EXPECT_LT(worst, 1e-12 * scale) << (discretization == Discretization::Fem ? "FEM" : "TransCut");
            EXPECT_GT(worst_without, 1e-3 * scale) << "the mean alone must miss: else this test tests nothing";
        }
    }

    // Nothing split, no corners; sizes are checked.
    const ShadingSurface unsplit = split_at_creases(surface, 180.0);
    const ShadingLight unsplit_light = shading_light(surface, unsplit, lit.bvh, lighting, lit.q, lit.visibility);
    EXPECT_TRUE(corner_light(surface, unsplit, unsplit_light.q, source_light(surface, unsplit, unsplit_light.q)).empty());
    EXPECT_THROW(corner_light(surface, lit.shading, lit.q, source), InvalidArgumentError);
    const DiffusionMatrix matrix = assemble_diffusion_matrix(mesh, connectivity, materials);
    std::vector<double> b(matrix.size() - 1);
    EXPECT_THROW(add_corner_light(matrix, corners, 0, b), InvalidArgumentError);
    std::vector<CornerLight> outside = {corners.front()};
    outside.front().face = static_cast<int32_t>(connectivity.boundary_faces.size());
    b.resize(matrix.size());
    EXPECT_THROW(add_corner_light(matrix, outside, 0, b), InvalidArgumentError);
}

TEST(ShadingRadiance, EqualsTheVertexRadianceWhereNotSplitAndUsesTheCopysLightWhereSplit) {
    const LitCube cube;
    TetMesh mesh = test::make_cube_mesh(3);
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<TetMaterial> materials(mesh.tet_count(), material_preset("marble"));
    const BoundarySurface surface = extract_boundary_surface(mesh, connectivity, materials);
    const TriangleBvh bvh = build_shadow_bvh(surface);
    const std::vector<Rgb> surface_q = incident_light(surface, bvh, cube.lighting);
    const std::vector<Rgb> q = to_volume_vertices(surface, surface_q, mesh.vertex_count());
    const ShadingSurface shading = split_at_creases(surface);
    const ShadingLight light = shading_light(surface, shading, bvh, cube.lighting, surface_q, {});
    // Any phi will do: E is pointwise in phi and q.
    std::vector<std::array<double, 3>> phi(mesh.vertex_count());
    for (size_t v = 0; v < phi.size(); ++v) phi[v] = {1.0 + 0.1 * v, 2.0, 0.5 + 0.01 * v};
    for (const bool clamp : {true, false}) {
        const auto per_vertex = exitant_radiance_factors(mesh, connectivity, materials, phi, q, RadianceOptions{clamp});
        const auto shaded = shading_radiance_factors(surface, shading, phi, light.q, RadianceOptions{clamp});
        ASSERT_EQ(shaded.size(), shading.size());
        for (size_t d = 0; d < shading.size(); ++d) {
            const int32_t s = shading.surface_vertex[d];
            const int32_t v = surface.vertices[s];
            if (!is_split_copy(shading, static_cast<int32_t>(d))) {
                EXPECT_EQ(shaded[d], per_vertex[v]);
                continue;
            }
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(shaded[d][c], static_cast<float>(exitant_radiance_factor(phi[v][c], light.q[d][c],
                                                                                  surface.eta[s], clamp)));
        }
    }
    EXPECT_THROW(shading_radiance_factors(surface, shading, phi, surface_q), InvalidArgumentError);
    phi.pop_back();
    EXPECT_THROW(shading_radiance_factors(surface, shading, phi, light.q), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
