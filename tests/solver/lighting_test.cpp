#include "base/error.h"
#include "solver/lighting.h"
#include "solver/ray_caster.h"
#include "tetops/connectivity.h"
#include "tetops/test_meshes.h"
#include "tetops/tet_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace waxwork {
namespace {

// Appends b to a as a new piece moved by `transform`.
void append_piece(TetMesh& a, const TetMesh& b, const RigidTransform& transform) {
    const auto offset = static_cast<int32_t>(a.positions.size());
    const auto piece = static_cast<int32_t>(a.piece_transforms.size());
    a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
    for (Tet t : b.tets) {
        for (int32_t& v : t) v += offset;
        a.tets.push_back(t);
        a.original_ids.push_back(static_cast<int32_t>(a.original_ids.size()));
        a.piece_ids.push_back(piece);
    }
    a.piece_transforms.push_back(transform);
}

std::vector<TetMaterial> materials_with_eta(const TetMesh& mesh, double eta) {
    TetMaterial m;
    m.mua = {0.01, 0.01, 0.01};
    m.musp = {1, 1, 1};
    m.eta = eta;
    return std::vector<TetMaterial>(mesh.tet_count(), m);
}

// Fresnel transmittance at normal incidence, the textbook closed form 1 - ((eta-1)/(eta+1))^2.
double normal_transmittance(double eta) {
    const double r = (eta - 1) / (eta + 1);
    return 1 - r * r;
}

bool on_top_face_interior(const Eigen::Vector3d& p, double top) {
    return std::abs(p.z() - top) < 1e-12 && p.x() > 1e-9 && p.x() < 1 - 1e-9 && p.y() > 1e-9 && p.y() < 1 - 1e-9;
}

TEST(Lighting, CubeLitFromAboveIsLitOnlyOnTheTopFace) {
    const TetMesh mesh = testing::make_box_mesh(4, {0, 0, 0}, {1, 1, 1});
    const TetConnectivity connectivity = build_connectivity(mesh);
    const double eta = 1.4;
    Lighting lighting;
    lighting.lights.push_back({LightType::Directional, {0, 0, -3}, {1.0, 2.0, 0.5}});
    lighting.ambient = {0.05, 0.1, 0.2};
    const BoundarySurface surface = extract_boundary_surface(mesh, connectivity, materials_with_eta(mesh, eta));
    const std::vector<Rgb> q = incident_light(surface, lighting);
    ASSERT_EQ(q.size(), surface.positions.size());

    const double ft = normal_transmittance(eta);
    int top_interior = 0;
    for (size_t s = 0; s < q.size(); ++s) {
        const Eigen::Vector3d& p = surface.positions[s];
        for (int c = 0; c < 3; ++c) {
            if (on_top_face_interior(p, 1.0)) {
                EXPECT_NEAR(q[s][c], lighting.lights[0].intensity[c] * ft + lighting.ambient[c], 1e-6) << p.transpose();
            } else if (p.z() < 1 - 1e-9) {
                // Sides and bottom: their normals have no +z component, so only the ambient term.
                EXPECT_EQ(q[s][c], lighting.ambient[c]) << p.transpose();
            } else {
                // Rim of the top face: the normal leans towards the light.
                EXPECT_GT(q[s][c], lighting.ambient[c]) << p.transpose();
            }
        }
        top_interior += on_top_face_interior(p, 1.0);
    }
    EXPECT_EQ(top_interior, 9);
}

TEST(Lighting, VolumeVertexFormZeroesInteriorVertices) {
    const TetMesh mesh = testing::make_box_mesh(3, {0, 0, 0}, {1, 1, 1});
    const TetConnectivity connectivity = build_connectivity(mesh);
    Lighting lighting;
    lighting.lights.push_back({LightType::Directional, {0, 0, -1}, {1, 1, 1}});
    lighting.ambient = {0.1, 0.1, 0.1};
    const std::vector<Rgb> q = incident_light(mesh, connectivity, materials_with_eta(mesh, 1.3), lighting);
    ASSERT_EQ(q.size(), mesh.vertex_count());
    for (size_t v = 0; v < q.size(); ++v) {
        if (connectivity.is_boundary_vertex[v]) {
            EXPECT_GE(q[v][0], 0.1);
        } else {
            EXPECT_EQ(q[v][0], 0.0);
        }
    }
}

// Cube A in [0,1]^3; a wider slab, as a second piece moved above it by its rigid transform.
TetMesh cube_under_floating_slab() {
    TetMesh mesh = testing::make_box_mesh(4, {0, 0, 0}, {1, 1, 1});
    const TetMesh slab = testing::make_box_mesh(2, {-0.5, -0.5, 0}, {1.5, 1.5, 0.3});
    RigidTransform lift;
    lift.translation = {0, 0, 2};
    append_piece(mesh, slab, lift);
    return mesh;
}

TEST(Lighting, PieceBetweenLightAndCubeCastsAShadow) {
    const TetMesh mesh = cube_under_floating_slab();
    const TetConnectivity connectivity = build_connectivity(mesh);
    Lighting lighting;
    lighting.lights.push_back({LightType::Directional, {0, 0, -1}, {1, 1, 1}});
    lighting.ambient = {0.05, 0.05, 0.05};
    const BoundarySurface surface = extract_boundary_surface(mesh, connectivity, materials_with_eta(mesh, 1.3));
    const std::vector<Rgb> shadowed = incident_light(surface, lighting);
    lighting.shadows = false;
    const std::vector<Rgb> unshadowed = incident_light(surface, lighting);

    int cube_top = 0, slab_top = 0;
    for (size_t s = 0; s < surface.positions.size(); ++s) {
        const Eigen::Vector3d& p = surface.positions[s];
        if (std::abs(p.z() - 1.0) < 1e-12) {  // top of the cube: behind the slab
            ++cube_top;
            EXPECT_EQ(shadowed[s][0], 0.05) << p.transpose();
            EXPECT_GT(unshadowed[s][0], 0.05) << p.transpose();
        } else if (std::abs(p.z() - 2.3) < 1e-12) {  // top of the slab (moved by the transform): lit
            ++slab_top;
            EXPECT_GT(shadowed[s][0], 0.05) << p.transpose();
            EXPECT_EQ(shadowed[s][0], unshadowed[s][0]);
        }
    }
    EXPECT_EQ(cube_top, 25);
    EXPECT_EQ(slab_top, 9);
}

TEST(Lighting, VisibilityOutputIsWhatTheShadowRaysFound) {
    // The same scene with two lights: one from above (the slab shadows the cube's top), one from the
    // side (+x travelling -x: nothing in its way for the cube's +x face).
    const TetMesh mesh = cube_under_floating_slab();
    const TetConnectivity connectivity = build_connectivity(mesh);
    Lighting lighting;
    lighting.lights.push_back({LightType::Directional, {0, 0, -1}, {1, 1, 1}});
    lighting.lights.push_back({LightType::Directional, {-1, 0, 0}, {1, 1, 1}});
    const BoundarySurface surface = extract_boundary_surface(mesh, connectivity, materials_with_eta(mesh, 1.3));
    std::vector<float> visibility;
    const std::vector<Rgb> q = incident_light(surface, lighting, &visibility);
    ASSERT_EQ(visibility.size(), 2 * surface.positions.size());
    EXPECT_EQ(q, incident_light(surface, lighting));  // asking for it changes nothing else
    int shadowed_top = 0, lit_side = 0;
    for (size_t s = 0; s < surface.positions.size(); ++s) {
        const Eigen::Vector3d& p = surface.positions[s];
        if (on_top_face_interior(p, 1.0)) {
            ++shadowed_top;
            EXPECT_EQ(visibility[2 * s], 0.0f) << p.transpose();
        }
        if (std::abs(p.x() - 1.0) < 1e-12 && p.z() > 1e-9 && p.z() < 1 - 1e-9 && p.y() > 1e-9 && p.y() < 1 - 1e-9) {
            ++lit_side;
            EXPECT_EQ(visibility[2 * s + 1], 1.0f) << p.transpose();
        }
        for (int l = 0; l < 2; ++l) EXPECT_TRUE(visibility[2 * s + l] == 0.0f || visibility[2 * s + l] == 1.0f);
    }
    EXPECT_GT(shadowed_top, 0);
    EXPECT_GT(lit_side, 0);
    // Without shadows nothing is occluded.
    lighting.shadows = false;
    incident_light(surface, lighting, &visibility);
    for (float v : visibility) EXPECT_EQ(v, 1.0f);
}

TEST(Lighting, PointLightFallsOffWithInverseSquareDistance) {
    const TetMesh mesh = testing::make_box_mesh(4, {0, 0, 0}, {1, 1, 1});
    const TetConnectivity connectivity = build_connectivity(mesh);
    const double eta = 1.5;
    const BoundarySurface surface = extract_boundary_surface(mesh, connectivity, materials_with_eta(mesh, eta));
    size_t centre = surface.positions.size();
    for (size_t s = 0; s < surface.positions.size(); ++s) {
        if ((surface.positions[s] - Eigen::Vector3d(0.5, 0.5, 1)).norm() < 1e-12) centre = s;
    }
    ASSERT_LT(centre, surface.positions.size());
    for (double d : {0.5, 1.0, 2.0, 7.0}) {
        Lighting lighting;
        lighting.lights.push_back({LightType::Point, {0.5, 0.5, 1 + d}, {3, 3, 3}});
        const std::vector<Rgb> q = incident_light(surface, lighting);
        EXPECT_NEAR(q[centre][1], 3 / (d * d) * normal_transmittance(eta), 1e-9) << d;
    }
}

TEST(Lighting, PointLightInsideOrOnTheObjectGivesOnlyAmbientAndNoNaN) {
    const TetMesh mesh = testing::make_box_mesh(3, {0, 0, 0}, {1, 1, 1});
    const TetConnectivity connectivity = build_connectivity(mesh);
    const BoundarySurface surface = extract_boundary_surface(mesh, connectivity, {});
    Lighting lighting;
    lighting.ambient = {0.25, 0.25, 0.25};
    lighting.lights.push_back({LightType::Point, {0.5, 0.5, 0.5}, {10, 10, 10}});  // inside
    lighting.lights.push_back({LightType::Point, {0, 0, 0}, {10, 10, 10}});        // on a corner vertex
    for (const Rgb& q : incident_light(surface, lighting)) {
        for (double x : q) {
            ASSERT_TRUE(std::isfinite(x));
            EXPECT_EQ(x, 0.25);
        }
    }
}

TEST(Lighting, InvalidLightsThrow) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    auto expect_throw = [](Light light) {
        Lighting lighting;
        lighting.lights.push_back(light);
        EXPECT_THROW(validate(lighting), InvalidArgumentError);
    };
    expect_throw({LightType::Directional, {0, 0, 0}, {1, 1, 1}});
    expect_throw({LightType::Directional, {nan, 0, -1}, {1, 1, 1}});
    expect_throw({LightType::Point, {0, inf, 0}, {1, 1, 1}});
    expect_throw({LightType::Point, {0, 0, 0}, {1, nan, 1}});
    expect_throw({LightType::Directional, {0, 0, 1}, {1, inf, 1}});
    expect_throw({LightType::Directional, {0, 0, 1}, {-1, 1, 1}});
    Lighting bad_ambient;
    bad_ambient.ambient = {0, nan, 0};
    EXPECT_THROW(validate(bad_ambient), InvalidArgumentError);
    // A point light at the origin is fine (its position, unlike a direction, may be zero).
    Lighting ok;
    ok.lights.push_back({LightType::Point, {0, 0, 0}, {1, 1, 1}});
    EXPECT_NO_THROW(validate(ok));

    // The throwing path through incident_light, too.
    const TetMesh mesh = testing::make_box_mesh(1, {0, 0, 0}, {1, 1, 1});
    const TetConnectivity connectivity = build_connectivity(mesh);
    Lighting lighting;
    lighting.lights.push_back({LightType::Directional, {0, 0, 0}, {1, 1, 1}});
    EXPECT_THROW(incident_light(mesh, connectivity, {}, lighting), InvalidArgumentError);
}

// `count` triangles around random centres in the unit cube, corners `size` x a normal deviate away.
void add_random_triangles(std::mt19937& rng, int count, float size, std::vector<Eigen::Vector3f>& points,
                          std::vector<std::array<int32_t, 3>>& triangles) {
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    for (int t = 0; t < count; ++t) {
        const Eigen::Vector3f c(unit(rng), unit(rng), unit(rng));
        for (int k = 0; k < 3; ++k) points.push_back(c + size * Eigen::Vector3f(gauss(rng), gauss(rng), gauss(rng)));
        const auto base = static_cast<int32_t>(points.size() - 3);
        triangles.push_back({base, base + 1, base + 2});
    }
}

TEST(RayCaster, BvhAnyHitAgreesWithBruteForce) {
    std::mt19937 rng(12345);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    // Random small triangles in the unit cube plus a few large ones, so that both deep leaves and
    // boxes spanning everything occur.
    std::vector<Eigen::Vector3f> points;
    std::vector<std::array<int32_t, 3>> triangles;
    add_random_triangles(rng, 20, 0.5f, points, triangles);
    add_random_triangles(rng, 2980, 0.04f, points, triangles);
    const TriangleBvh bvh(points, triangles);
    EXPECT_EQ(bvh.triangle_count(), triangles.size());
    EXPECT_GT(bvh.node_count(), 1u);

    int hits = 0, misses = 0;
    for (int r = 0; r < 5000; ++r) {
        const Eigen::Vector3f origin(1.6f * unit(rng) - 0.3f, 1.6f * unit(rng) - 0.3f, 1.6f * unit(rng) - 0.3f);
        Eigen::Vector3f direction(gauss(rng), gauss(rng), gauss(rng));
        if (r % 10 == 0) direction = Eigen::Vector3f(0, 0, r % 20 == 0 ? 1.0f : -1.0f);  // axis-parallel rays
        const float t_max = r % 3 == 0 ? std::numeric_limits<float>::infinity() : 0.5f * unit(rng);
        bool brute = false;
        for (const auto& t : triangles) {
            if (ray_hits_triangle(origin, direction, 0.0f, t_max, points[t[0]], points[t[1]], points[t[2]])) {
                brute = true;
                break;
            }
        }
        ASSERT_EQ(bvh.occluded(origin, direction, 0.0f, t_max), brute) << "ray " << r;
        (brute ? hits : misses)++;
    }
    // Both outcomes must be well represented for the comparison to mean anything.
    EXPECT_GT(hits, 500);
    EXPECT_GT(misses, 500);
}

// A tree refitted to moved points (the triangles turned and stretched about the centre) answers every
// ray as a tree built on the moved points does, and refuses a point set that does not fit.
TEST(RayCaster, RefittedBvhAnswersAsAFreshTreeOnMovedPoints) {
    std::mt19937 rng(777);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    std::vector<Eigen::Vector3f> points;
    std::vector<std::array<int32_t, 3>> triangles;
    add_random_triangles(rng, 2000, 0.05f, points, triangles);
    TriangleBvh refitted(points, triangles);
    std::vector<Eigen::Vector3f> moved = points;
    for (Eigen::Vector3f& p : moved) {
        const float angle = 1.5f * p.y();  // a twist about y, and a stretch along x
        const float x = p.x() - 0.5f, z = p.z() - 0.5f;
        p = Eigen::Vector3f(0.5f + 1.7f * (std::cos(angle) * x - std::sin(angle) * z), p.y(),
                            0.5f + std::sin(angle) * x + std::cos(angle) * z);
    }
    refitted.refit(moved);
    const TriangleBvh fresh(moved, triangles);
    int hits = 0;
    for (int r = 0; r < 4000; ++r) {
        const Eigen::Vector3f origin(2 * unit(rng) - 0.5f, 2 * unit(rng) - 0.5f, 2 * unit(rng) - 0.5f);
        const Eigen::Vector3f direction(gauss(rng), gauss(rng), gauss(rng));
        const float t_max = r % 2 == 0 ? std::numeric_limits<float>::infinity() : unit(rng);
        const bool expected = fresh.occluded(origin, direction, 0.0f, t_max);
        ASSERT_EQ(refitted.occluded(origin, direction, 0.0f, t_max), expected) << "ray " << r;
        hits += expected ? 1 : 0;
    }
    EXPECT_GT(hits, 400);
    EXPECT_LT(hits, 3600);
    moved.pop_back();
    EXPECT_THROW(refitted.refit(moved), InvalidArgumentError);
    moved.push_back(Eigen::Vector3f(std::numeric_limits<float>::quiet_NaN(), 0, 0));
    EXPECT_THROW(refitted.refit(moved), InvalidArgumentError);
}

TEST(RayCaster, EmptyAndInvalidInput) {
    const TriangleBvh empty;
    EXPECT_FALSE(empty.occluded({0, 0, 0}, {0, 0, 1}, 0, 1));
    std::vector<Eigen::Vector3f> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    std::vector<std::array<int32_t, 3>> bad = {{0, 1, 3}};
    EXPECT_THROW(TriangleBvh(points, bad), InvalidArgumentError);
    points[1].x() = std::numeric_limits<float>::quiet_NaN();
    std::vector<std::array<int32_t, 3>> ok = {{0, 1, 2}};
    EXPECT_THROW(TriangleBvh(points, ok), InvalidArgumentError);
}

TEST(Lighting, UpdatingSomeVerticesEqualsTheFullComputationThere) {
    // Two boxes, one shadowing the other, and a point light: the update must reproduce shadows too.
    const TetMesh mesh = join_meshes(testing::make_box_mesh(3, {0, 0, 0}, {1, 1, 1}),
                                              testing::make_box_mesh(2, {-0.5, 1.5, -0.5}, {1.5, 1.8, 1.5}));
    const TetConnectivity connectivity = build_connectivity(mesh);
    BoundarySurface surface = extract_boundary_surface(mesh, connectivity, {});
    const TriangleBvh bvh = build_shadow_bvh(surface);
    Lighting lighting;
    lighting.lights = {Light{LightType::Directional, Eigen::Vector3d(0.3, -1, 0.2), {1, 1, 1}},
                       Light{LightType::Point, Eigen::Vector3d(2, 0.5, 0.5), {2, 1, 1}}};
    lighting.ambient = {0.01, 0.02, 0.03};
    std::vector<Rgb> q = incident_light(surface, bvh, lighting);
    // Change eta at every third vertex, update those, compare with a full recomputation.
    std::vector<int32_t> changed;
    for (size_t s = 0; s < surface.eta.size(); s += 3) {
        surface.eta[s] = 1.8;
        changed.push_back(static_cast<int32_t>(s));
    }
    const std::vector<Rgb> before = q;
    update_incident_light(surface, bvh, lighting, changed, q);
    const std::vector<Rgb> full = incident_light(surface, bvh, lighting);
    size_t differing = 0;
    for (size_t s = 0; s < q.size(); ++s) {
        EXPECT_EQ(q[s], full[s]) << s;
        differing += q[s] != before[s] ? 1 : 0;
    }
    EXPECT_GT(differing, changed.size() / 4);  // eta matters where light arrives
    const std::vector<int32_t> bad = {static_cast<int32_t>(q.size())};
    EXPECT_THROW(update_incident_light(surface, bvh, lighting, bad, q), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
