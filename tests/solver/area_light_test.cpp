#include "base/error.h"
#include "solver/area_light.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "tetops/connectivity.h"
#include "tetops/test_meshes.h"
#include "tetops/tet_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace waxwork {
namespace {

constexpr double kPi = std::numbers::pi;

Light area_light(LightType type, const Eigen::Vector3d& centre, const Eigen::Vector3d& axis, const Eigen::Vector2d& size,
                 const Rgb& intensity = {1, 1, 1}) {
    Light light;
    light.type = type;
    light.vector = centre;
    light.axis = axis;
    light.tangent = default_rect_tangent(axis);
    light.size = size;
    light.intensity = intensity;
    return light;
}

BoundarySurface cube_surface(double eta) {
    const TetMesh mesh = testing::make_box_mesh(4, {0, 0, 0}, {1, 1, 1});
    TetMaterial m;
    m.mua = {0.01, 0.01, 0.01};
    m.musp = {1, 1, 1};
    m.eta = eta;
    return extract_boundary_surface(mesh, build_connectivity(mesh), std::vector<TetMaterial>(mesh.tet_count(), m));
}

// q of one light alone (no ambient), shadows on.
std::vector<Rgb> q_of(const BoundarySurface& surface, const Light& light, std::vector<float>* visibility = nullptr) {
    Lighting lighting;
    lighting.lights = {light};
    return incident_light(surface, lighting, visibility);
}

// The largest difference between a and b over every vertex and channel, relative to the largest value of b.
double relative_difference(const std::vector<Rgb>& a, const std::vector<Rgb>& b) {
    double difference = 0, largest = 0;
    for (size_t s = 0; s < a.size(); ++s)
        for (int c = 0; c < 3; ++c) {
            difference = std::max(difference, std::abs(a[s][c] - b[s][c]));
            largest = std::max(largest, std::abs(b[s][c]));
        }
    return difference / largest;
}

// A light off a corner of the cube, so that it lights three faces at once and the others not at all.
const Eigen::Vector3d kLightCentre(1.7, 2.3, 2.9);

TEST(AreaLight, SphereLightShrinksToThePointLightOfTheSameIntensity) {
    const BoundarySurface surface = cube_surface(1.4);
    const Rgb intensity = {3, 2, 1};
    const std::vector<Rgb> point = q_of(surface, Light{LightType::Point, kLightCentre, intensity});
    const double distance = (kLightCentre - Eigen::Vector3d(0.5, 0.5, 0.5)).norm();
    double previous = std::numeric_limits<double>::infinity();
    for (double fraction : {1e-1, 1e-2, 1e-3}) {
        const std::vector<Rgb> sphere =
            q_of(surface, area_light(LightType::Sphere, kLightCentre, {0, 0, 1}, Eigen::Vector2d::Constant(fraction * distance), intensity));
        const double difference = relative_difference(sphere, point);
        EXPECT_LT(difference, previous) << fraction;
        previous = difference;
    }
    EXPECT_LT(previous, 1e-3);
}

TEST(AreaLight, RectangleAndDiskShrinkToAPointLightTimesTheEmissionCosine) {
    const BoundarySurface surface = cube_surface(1.4);
    const Rgb intensity = {1, 2, 3};
    const std::vector<Rgb> point = q_of(surface, Light{LightType::Point, kLightCentre, intensity});
    // Tilted off the direction to the cube, so the emission cosine varies over it (and some vertices
    // lie behind the emitter).
    const Eigen::Vector3d axis = (Eigen::Vector3d(0.5, 0.5, 0.5) - kLightCentre).normalized() + Eigen::Vector3d(2.5, 0, 0);
    std::vector<Rgb> expected = point;
    int behind = 0;
    for (size_t s = 0; s < expected.size(); ++s) {
        const double cos_emit = axis.normalized().dot((surface.positions[s] - kLightCentre).normalized());
        behind += cos_emit <= 0;
        for (double& c : expected[s]) c *= std::max(0.0, cos_emit);
    }
    EXPECT_GT(behind, 0);
    const double distance = (kLightCentre - Eigen::Vector3d(0.5, 0.5, 0.5)).norm();
    for (LightType type : {LightType::Rectangle, LightType::Disk}) {
        double previous = std::numeric_limits<double>::infinity();
        for (double fraction : {1e-1, 1e-2, 1e-3}) {
            const Eigen::Vector2d size = fraction * distance * Eigen::Vector2d(1.0, 0.6);
            const std::vector<Rgb> area = q_of(surface, area_light(type, kLightCentre, axis, size, intensity));
            const double difference = relative_difference(area, expected);
            EXPECT_LT(difference, previous) << light_type_name(type) << " " << fraction;
            previous = difference;
        }
        EXPECT_LT(previous, 1e-3) << light_type_name(type);
    }
}

// Irradiance at a point facing a disk of radiance L on its axis at distance d (eta = 1, so F_t = 1):
// E = pi L R^2 / (R^2 + d^2), the classic disk-to-point form factor; with L = I / (pi R^2), I / (R^2 + d^2).
// Area sampling resolves the integrand d^2 / (rho^2 + d^2)^2 well while the disk is no wider than the
// receiver is far from it (R <= d); beyond, its peak under the receiver holds few of the samples.
TEST(AreaLight, DiskOnTheAxisMatchesTheClosedFormIrradiance) {
    ASSERT_DOUBLE_EQ(fresnel_transmittance(0.3, 1.0), 1.0);
    const TriangleBvh none;
    Lighting lighting;
    lighting.shadows = false;
    for (double ratio : {0.05, 0.25, 0.5, 1.0, 2.0}) {
        double worst = 0, mean = 0;
        int cases = 0;
        for (double d : {0.3, 1.0, 5.0}) {
            // Different receivers, so different rotations of the sample pattern.
            for (int k = 0; k < 16; ++k) {
                const Eigen::Vector3d receiver(0.37 * k, -0.11 * k * k, 0.05 * k);
                const double radius = ratio * d;
                lighting.lights = {area_light(LightType::Disk, receiver + Eigen::Vector3d(0, 0, d), {0, 0, -1},
                                              Eigen::Vector2d::Constant(radius), {2, 2, 2})};
                const double expected = 2 / (radius * radius + d * d);
                const Rgb q = incident_light_at(receiver, {0, 0, 1}, 1.0, 0.0, none, lighting);
                worst = std::max(worst, std::abs(q[0] / expected - 1));
                mean += q[0] / expected - 1;
                ++cases;
            }
        }
        // Each receiver within 2% while R <= d; wider disks only without bias: the error averaged over
        // the receivers (each with its own rotation of the pattern) within 1%.
        if (ratio <= 1) {
            EXPECT_LT(worst, 0.02) << "R / d = " << ratio;
        }
        EXPECT_LT(std::abs(mean / cases), 0.01) << "R / d = " << ratio;
    }
}

// A sphere wholly above the receiver's horizon gives E = pi L sin^2(theta_max) = I / d^2 at any size.
TEST(AreaLight, SphereAboveTheHorizonGivesTheInverseSquareIrradianceAtAnySize) {
    const TriangleBvh none;
    Lighting lighting;
    lighting.shadows = false;
    double worst = 0;
    for (double ratio : {0.01, 0.3, 0.7, 0.95}) {
        for (int k = 0; k < 8; ++k) {
            const Eigen::Vector3d receiver(0.3 * k, 0.1 * k, -0.7 * k);
            const double d = 2.0;
            lighting.lights = {area_light(LightType::Sphere, receiver + Eigen::Vector3d(0, d, 0), {0, 0, 1},
                                          Eigen::Vector2d::Constant(ratio * d), {5, 5, 5})};
            const Rgb q = incident_light_at(receiver, {0, 1, 0}, 1.0, 0.0, none, lighting);
            worst = std::max(worst, std::abs(q[1] / (5 / (d * d)) - 1));
        }
    }
    // The cosine is linear in the sampled coordinate, whose mean the rotated midpoints miss by at most
    // 1 / (2N): a relative error of at most (1 - cos(theta_max)) / (N (1 + cos(theta_max))), 1.7% at
    // sin(theta_max) = 0.95.
    EXPECT_LT(worst, 0.02);
}

TEST(AreaLight, PointsInsideASphereOrBehindAnEmitterGetNothing) {
    const TriangleBvh none;
    Lighting lighting;
    lighting.shadows = false;
    const auto q_at = [&](const Light& light, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
        lighting.lights = {light};
        float visibility = -1;
        const Rgb q = incident_light_at(p, n, 1.3, 0.0, none, lighting, &visibility);
        for (double c : q) EXPECT_TRUE(std::isfinite(c));
        EXPECT_GE(visibility, 0.0f);
        EXPECT_LE(visibility, 1.0f);
        return q[0];
    };
    const Light sphere = area_light(LightType::Sphere, {0, 0, 0}, {0, 0, 1}, {1, 1});
    EXPECT_EQ(q_at(sphere, {0.2, 0.3, 0.1}, {0, 0, 1}), 0.0);
    EXPECT_EQ(q_at(sphere, {0, 0, 0}, {0, 0, 1}), 0.0);  // at the centre: no direction
    EXPECT_EQ(q_at(sphere, {1, 0, 0}, {-1, 0, 0}), 0.0);  // on its surface
    EXPECT_GT(q_at(sphere, {2, 0, 0}, {-1, 0, 0}), 0.0);
    for (LightType type : {LightType::Rectangle, LightType::Disk}) {
        const Light flat = area_light(type, {0, 0, 0}, {0, 0, 1}, {1, 0.5});
        EXPECT_EQ(q_at(flat, {0.1, 0.2, -1}, {0, 0, 1}), 0.0) << "behind";
        EXPECT_EQ(q_at(flat, {0.1, 0.2, 0}, {0, 0, -1}), 0.0) << "in its plane";
        EXPECT_EQ(q_at(flat, {0, 0, 0}, {0, 0, -1}), 0.0) << "at its centre";
        EXPECT_EQ(q_at(flat, {0, 0, 1}, {0, 0, 1}), 0.0) << "in front, facing away";
        EXPECT_GT(q_at(flat, {0, 0, 1}, {0, 0, -1}), 0.0) << "in front, facing it";
        // Right next to the emitter the estimate stays below pi L (L = 1 / area).
        const double area = type == LightType::Rectangle ? 0.5 : kPi;
        EXPECT_LE(q_at(flat, {0.01, 0.02, 1e-9}, {0, 0, -1}), kPi / area);
    }
}

TEST(AreaLight, AHalfCoveredVertexIsPartlyVisibleAndTheResultIsDeterministic) {
    // The cube [0,1]^3 under a slab covering x < 0.5 at z in [2, 2.3], lit by a disk above facing down:
    // the slab's edge passes over the middle of the top face, which sees half the disk.
    const TetMesh mesh = join_meshes(testing::make_box_mesh(4, {0, 0, 0}, {1, 1, 1}),
                                              testing::make_box_mesh(2, {-1, -1, 2}, {0.5, 2, 2.3}));
    const TetConnectivity connectivity = build_connectivity(mesh);
    const BoundarySurface surface = extract_boundary_surface(mesh, connectivity, {});
    size_t middle = surface.positions.size();
    for (size_t s = 0; s < surface.positions.size(); ++s)
        if ((surface.positions[s] - Eigen::Vector3d(0.5, 0.5, 1)).norm() < 1e-12) middle = s;
    ASSERT_LT(middle, surface.positions.size());

    Lighting lighting;
    lighting.lights = {area_light(LightType::Disk, {0.5, 0.5, 4}, {0, 0, -1}, {1, 1})};
    std::vector<float> visibility;
    const std::vector<Rgb> shadowed = incident_light(surface, lighting, &visibility);
    ASSERT_EQ(visibility.size(), surface.positions.size());
    EXPECT_GT(visibility[middle], 0.25f);
    EXPECT_LT(visibility[middle], 0.75f);
    for (float v : visibility) {
        EXPECT_GE(v, 0.0f);
        EXPECT_LE(v, 1.0f);
    }
    lighting.shadows = false;
    const std::vector<Rgb> unshadowed = incident_light(surface, lighting);
    EXPECT_GT(shadowed[middle][0], 0.2 * unshadowed[middle][0]);
    EXPECT_LT(shadowed[middle][0], 0.8 * unshadowed[middle][0]);
    lighting.shadows = true;

    // The same pattern every time, and at a vertex whatever else is recomputed.
    EXPECT_EQ(incident_light(surface, lighting), shadowed);
    const TriangleBvh bvh = build_shadow_bvh(surface);
    std::vector<Rgb> q = shadowed;
    std::vector<int32_t> some;
    for (size_t s = 0; s < q.size(); s += 5) {
        some.push_back(static_cast<int32_t>(s));
        q[s] = {-1, -1, -1};
    }
    update_incident_light(surface, bvh, lighting, some, q);
    EXPECT_EQ(q, shadowed);
}

TEST(AreaLight, DegenerateAreaLightsAreRejectedNamingTheLight) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    const auto error = [](const Light& light) -> std::string {
        Lighting lighting;
        lighting.lights = {Light{LightType::Point, {0, 0, 0}, {1, 1, 1}}, light};
        try {
            validate(lighting);
        } catch (const InvalidArgumentError& e) {
            return e.what();
        }
        return "no error";
    };
    const Eigen::Vector3d up(0, 0, 1);
    const auto with = [&](LightType type, auto change) {
        Light light = area_light(type, {0, 0, 2}, -up, {1, 0.5});
        change(light);
        return error(light);
    };
    struct Case {
        std::string message, expected;
    };
    const std::vector<Case> cases = {
        {with(LightType::Rectangle, [](Light& l) { l.size = {0, 1}; }), "light 1 (rect): width and height must be positive"},
        {with(LightType::Rectangle, [](Light& l) { l.size = {1, -2}; }), "light 1 (rect): width and height"},
        {with(LightType::Rectangle, [&](Light& l) { l.size = {inf, 1}; }), "light 1 (rect): width and height"},
        {with(LightType::Rectangle, [&](Light& l) { l.size = {1, nan}; }), "light 1 (rect): width and height"},
        {with(LightType::Disk, [](Light& l) { l.size = {0, 1}; }), "light 1 (disk): radius must be positive"},
        {with(LightType::Disk, [&](Light& l) { l.size = {nan, 1}; }), "light 1 (disk): radius"},
        {with(LightType::Sphere, [](Light& l) { l.size = {-1, 1}; }), "light 1 (sphere): radius must be positive"},
        {with(LightType::Sphere, [&](Light& l) { l.size = {inf, 1}; }), "light 1 (sphere): radius"},
        {with(LightType::Sphere, [](Light& l) { l.size = {2e100, 1}; }), "light 1 (sphere): radius"},
        {with(LightType::Disk, [](Light& l) { l.axis = {0, 0, 0}; }), "light 1 (disk): axis is the zero vector"},
        {with(LightType::Rectangle, [&](Light& l) { l.axis = {0, nan, 1}; }), "light 1 (rect): axis"},
        {with(LightType::Disk, [&](Light& l) { l.axis = {inf, 0, 1}; }), "light 1 (disk): axis"},
        {with(LightType::Rectangle, [](Light& l) { l.tangent = {0, 0, 3}; }), "light 1 (rect): tangent"},
        {with(LightType::Rectangle, [](Light& l) { l.tangent = {0, 0, 0}; }), "light 1 (rect): tangent is the zero vector"},
        {with(LightType::Rectangle, [&](Light& l) { l.tangent = {nan, 0, 0}; }), "light 1 (rect): tangent"},
        {with(LightType::Sphere, [&](Light& l) { l.vector = {0, inf, 0}; }), "light 1 (sphere): center has a non-finite"},
        {with(LightType::Rectangle, [](Light& l) { l.vector = {0, 0, 2e100}; }), "light 1 (rect): center"},
        {with(LightType::Disk, [](Light& l) { l.intensity = {1, -1, 1}; }), "light 1 (disk): intensity must be non-negative"},
        {with(LightType::Sphere, [](Light& l) { l.intensity = {1, 1, 2e15}; }), "light 1 (sphere): intensity"},
    };
    for (const Case& c : cases) {
        EXPECT_NE(c.message.find(c.expected), std::string::npos) << c.message;
        EXPECT_EQ(c.message.find('\n'), std::string::npos) << c.message;
    }
    // What only rectangles use does not matter to disks and spheres; a sphere needs no axis.
    EXPECT_EQ(with(LightType::Disk, [](Light& l) { l.tangent = {0, 0, 0}; }), "no error");
    EXPECT_EQ(with(LightType::Sphere, [](Light& l) { l.axis = {0, 0, 0}; }), "no error");
    EXPECT_EQ(with(LightType::Rectangle, [](Light& l) { l.tangent = {1, 0, 5}; }), "no error");  // not perpendicular
    Light unknown = area_light(LightType::Sphere, {0, 0, 0}, up, {1, 1});
    unknown.type = static_cast<LightType>(17);
    EXPECT_NE(error(unknown).find("unknown light type"), std::string::npos);
}

TEST(AreaLight, DefaultTangentIsUnitAndPerpendicular) {
    for (const Eigen::Vector3d& axis : {Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(1, 0, 0),
                                        Eigen::Vector3d(-3, 0.1, 0.2), Eigen::Vector3d(0.3, -1, 0.5)}) {
        const Eigen::Vector3d t = default_rect_tangent(axis);
        EXPECT_NEAR(t.norm(), 1.0, 1e-12);
        EXPECT_NEAR(t.dot(axis), 0.0, 1e-12);
    }
    // A light facing down has its width along +x.
    EXPECT_TRUE(default_rect_tangent({0, -1, 0}).isApprox(Eigen::Vector3d(1, 0, 0)));
}

}  // namespace
}  // namespace waxwork
