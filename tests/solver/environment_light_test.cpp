#include "base/error.h"
#include "solver/environment_light.h"
#include "solver/environment_map.h"
#include "solver/environment_transfer.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "solver/sky_model.h"
#include "solver/spherical_harmonics.h"
#include "tetops/icosphere.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <utility>

namespace waxwork {
namespace {

constexpr double kPi = std::numbers::pi;

// An environment map whose pixel (x, y) holds f(centre direction).
std::shared_ptr<const EnvironmentMap> map_of(int width, int height, const std::function<Rgb(const Eigen::Vector3d&)>& f) {
    std::vector<Rgb> pixels(static_cast<size_t>(width) * height);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            pixels[static_cast<size_t>(y) * width + x] = f(EnvironmentMap::direction((x + 0.5) / width, (y + 0.5) / height));
    return std::make_shared<const EnvironmentMap>(width, height, std::move(pixels), "test map");
}

// The boundary of a sphere of radius 1 (an icosphere), as the lighting sees it.
BoundarySurface sphere_surface(int level, double eta) {
    const TriangleSurface sphere = make_icosphere(level, 1.0);
    BoundarySurface surface;
    surface.positions = sphere.points;
    surface.triangles = sphere.triangles;
    surface.normals = area_weighted_normals(surface.positions, surface.triangles);
    surface.eta.assign(surface.positions.size(), eta);
    surface.vertices.resize(surface.positions.size());
    for (size_t s = 0; s < surface.vertices.size(); ++s) surface.vertices[s] = static_cast<int32_t>(s);
    surface.triangle_tets.assign(surface.triangles.size(), 0);
    return surface;
}

// Adds a square plate of side 2 h centred at `centre`, facing +y and -y (two triangles each way).
void add_plate(BoundarySurface& surface, const Eigen::Vector3d& centre, double h) {
    const auto base = static_cast<int32_t>(surface.positions.size());
    for (const auto& [dx, dz] : {std::pair{-h, -h}, {h, -h}, {h, h}, {-h, h}}) {
        surface.positions.push_back(centre + Eigen::Vector3d(dx, 0, dz));
        surface.eta.push_back(1.3);
        surface.vertices.push_back(static_cast<int32_t>(surface.vertices.size()));
    }
    for (const std::array<int32_t, 3>& t : std::initializer_list<std::array<int32_t, 3>>{
             {base, base + 2, base + 1}, {base, base + 3, base + 2}, {base, base + 1, base + 2}, {base, base + 2, base + 3}}) {
        surface.triangles.push_back(t);
        surface.triangle_tets.push_back(0);
    }
    surface.normals = area_weighted_normals(surface.positions, surface.triangles);
}

// Lighting by the environment alone.
Lighting lit_by(const EnvironmentLight& environment) {
    Lighting lighting;
    lighting.environment = environment;
    return lighting;
}

// The exact q of a constant environment of radiance L on an unoccluded point:
// L * 2 pi * integral_0^1 F_t(mu, eta) mu dmu (the midpoint rule on 65536 panels: exact to about 1e-9).
double uniform_q(double radiance, double eta) {
    const int n = 1 << 16;
    double sum = 0;
    for (int i = 0; i < n; ++i) {
        const double mu = (i + 0.5) / n;
        sum += fresnel_transmittance(mu, eta) * mu;
    }
    return radiance * 2 * kPi * sum / n;
}

TEST(SphericalHarmonics, BasisIsOrthonormal) {
    // Midpoint quadrature over a fine latitude-longitude grid.
    const int order = 6, count = sh_coefficient_count(order);
    const int width = 720, height = 360;
    std::vector<double> gram(count * count, 0.0), y(count);
    for (int j = 0; j < height; ++j) {
        const double d_omega = 2 * kPi / width * (std::cos(kPi * j / height) - std::cos(kPi * (j + 1) / height));
        for (int i = 0; i < width; ++i) {
            evaluate_sh(order, EnvironmentMap::direction((i + 0.5) / width, (j + 0.5) / height), y);
            for (int a = 0; a < count; ++a)
                for (int b = 0; b < count; ++b) gram[a * count + b] += y[a] * y[b] * d_omega;
        }
    }
    for (int a = 0; a < count; ++a)
        for (int b = 0; b < count; ++b) EXPECT_NEAR(gram[a * count + b], a == b ? 1.0 : 0.0, 2e-4) << a << " " << b;
}

TEST(SphericalHarmonics, RotatingCoefficientsEqualsProjectingTheRotatedField) {
    const auto field = [](const Eigen::Vector3d& w) {
        return Rgb{std::exp(3 * w.dot(Eigen::Vector3d(0.6, 0.3, -0.74).normalized())), 1 + w.x() * w.y(), 0.5 + 0.5 * w.z()};
    };
    const int order = 5;
    const double angle = 0.7;
    const Eigen::AngleAxisd unrotate(-angle, Eigen::Vector3d::UnitY());
    const auto rotated_field = [&](const Eigen::Vector3d& w) { return field(unrotate * w); };
    const std::vector<Rgb> expected = map_of(1024, 512, rotated_field)->project_to_sh(order);
    const std::vector<Rgb> rotated = rotate_sh_about_up(map_of(1024, 512, field)->project_to_sh(order), order, angle);
    for (size_t k = 0; k < expected.size(); ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(rotated[k][c], expected[k][c], 2e-3 * (1 + std::abs(expected[k][c]))) << k;
}

TEST(SphericalHarmonics, RejectsOrdersOutsideTheTable) {
    std::vector<double> out(1000);
    EXPECT_THROW(evaluate_sh(-1, Eigen::Vector3d::UnitY(), out), InvalidArgumentError);
    EXPECT_THROW(evaluate_sh(kMaxShOrder + 1, Eigen::Vector3d::UnitY(), out), InvalidArgumentError);
    EXPECT_THROW(evaluate_sh(4, Eigen::Vector3d::UnitY(), std::span<double>(out.data(), 24)), InvalidArgumentError);
}

// A constant environment on a convex body: every vertex sees the same hemisphere of the same radiance,
// so q is the same everywhere, and only the l = 0 term of the projection contributes.
TEST(EnvironmentLight, ConstantEnvironmentOnAConvexBodyGivesEveryVertexTheExactUniformQ) {
    const double radiance = 2.5, eta = 1.3;
    const BoundarySurface surface = sphere_surface(3, eta);
    const TriangleBvh bvh = build_shadow_bvh(surface);
    EnvironmentLight environment = environment_light(map_of(64, 32, [&](const Eigen::Vector3d&) {
        return Rgb{radiance, radiance, radiance};
    }));
    const double exact = uniform_q(radiance, eta);

    const EnvironmentTransfer transfer = compute_environment_transfer(surface, bvh, {});
    const std::vector<Rgb> q = apply_environment_transfer(transfer, environment);
    const std::vector<Rgb> reference = sampled_environment_light(surface, bvh, true, environment);
    double worst_transfer = 0, worst_reference = 0;
    for (size_t s = 0; s < q.size(); ++s) {
        for (int c = 0; c < 3; ++c) {
            worst_transfer = std::max(worst_transfer, std::abs(q[s][c] / exact - 1));
            worst_reference = std::max(worst_reference, std::abs(reference[s][c] / exact - 1));
        }
    }
    std::printf("uniform: worst relative error: transfer %.2e, sampled %.2e\n", worst_transfer, worst_reference);
    EXPECT_LT(worst_transfer, 1e-3);
    EXPECT_LT(worst_reference, 1e-3);
    // A rotation changes nothing.
    environment.rotation_degrees = 123;
    EXPECT_NEAR(apply_environment_transfer(transfer, environment)[7][1], q[7][1], 1e-5 * exact);
}

// An upper-hemisphere environment of radiance L on a sphere: a point whose normal makes the angle
// alpha with the up axis sees it over the lune between its tangent plane and the horizon, which gives
// the irradiance E = pi L (1 + cos alpha) / 2 (eta = 1: no Fresnel loss).
TEST(EnvironmentLight, UpperHemisphereEnvironmentOnASphereGivesTheClosedFormIrradiance) {
    const double radiance = 1.0;
    const BoundarySurface surface = sphere_surface(3, 1.0);
    const TriangleBvh bvh = build_shadow_bvh(surface);
    const EnvironmentLight environment = environment_light(map_of(512, 256, [&](const Eigen::Vector3d& w) {
        return w.y() > 0 ? Rgb{radiance, radiance, radiance} : Rgb{0, 0, 0};
    }));
    const std::vector<Rgb> q = apply_environment_transfer(compute_environment_transfer(surface, bvh, {}), environment);
    const std::vector<Rgb> reference = sampled_environment_light(surface, bvh, true, environment);
    double worst_transfer = 0, worst_reference = 0;
    for (size_t s = 0; s < q.size(); ++s) {
        const double exact = kPi * radiance * (1 + surface.normals[s].y()) / 2;
        worst_transfer = std::max(worst_transfer, std::abs(q[s][0] - exact) / (kPi * radiance));
        worst_reference = std::max(worst_reference, std::abs(reference[s][0] - exact) / (kPi * radiance));
    }
    std::printf("hemisphere: worst error / (pi L): transfer %.2e, sampled %.2e\n", worst_transfer, worst_reference);
    EXPECT_LT(worst_transfer, 5e-3);
    EXPECT_LT(worst_reference, 0.005);
}

TEST(EnvironmentLight, AnOccluderShadowsTheVerticesBelowIt) {
    BoundarySurface surface = sphere_surface(2, 1.3);
    const size_t sphere_vertices = surface.positions.size();
    const EnvironmentLight environment = environment_light(map_of(64, 32, [](const Eigen::Vector3d&) {
        return Rgb{1, 1, 1};
    }));
    const std::vector<Rgb> open = incident_light(surface, lit_by(environment));
    add_plate(surface, Eigen::Vector3d(0, 1.2, 0), 3.0);
    Lighting lighting = lit_by(environment);
    const std::vector<Rgb> covered = incident_light(surface, lighting);
    size_t top = 0;
    for (size_t s = 0; s < sphere_vertices; ++s)
        if (surface.positions[s].y() > surface.positions[top].y()) top = s;
    EXPECT_LT(covered[top][0], 0.2 * open[top][0]);
    lighting.shadows = false;
    EXPECT_NEAR(incident_light(surface, lighting)[top][0], open[top][0], 1e-6);
}

// Only vertices that see the changed region can change: updating those after adding an occluder gives
// the full recomputation bit for bit.
TEST(EnvironmentLight, UpdatingTheVerticesThatSeeAChangeEqualsRecomputingAll) {
    BoundarySurface surface = sphere_surface(2, 1.3);
    add_plate(surface, Eigen::Vector3d(1.5, 0, 0), 0.01);  // a tiny plate beside +x: the "before"
    const EnvironmentTransfer before = compute_environment_transfer(surface, build_shadow_bvh(surface), {});
    const BoundarySurface before_surface = surface;
    const size_t n = surface.positions.size();
    // The plate's four triangles, before and after.
    std::vector<WorldTriangle> changed;
    const auto plate_triangles = [&] {
        for (size_t t = surface.triangles.size() - 4; t < surface.triangles.size(); ++t) {
            const auto& c = surface.triangles[t];
            changed.push_back({surface.positions[c[0]], surface.positions[c[1]], surface.positions[c[2]]});
        }
    };
    plate_triangles();
    // Grow the plate to a side of 1.
    for (size_t s = n - 4; s < n; ++s) surface.positions[s] = Eigen::Vector3d(1.5, 0, 0) + (surface.positions[s] - Eigen::Vector3d(1.5, 0, 0)) * 50;
    surface.normals = area_weighted_normals(surface.positions, surface.triangles);
    plate_triangles();
    const TriangleBvh bvh = build_shadow_bvh(surface);
    const EnvironmentTransfer after = compute_environment_transfer(surface, bvh, {});

    std::vector<int32_t> update = vertices_seeing_triangles(surface, changed);
    EXPECT_GT(update.size(), 4u);
    for (const int32_t s : update) EXPECT_GT(surface.positions[s].x(), -0.5) << "the far side cannot see the plate";
    EnvironmentTransfer updated = before;
    update_environment_transfer(surface, bvh, update, updated);
    size_t differing = 0;
    for (size_t s = 0; s < n; ++s) {
        const std::span<const float> a = after.at(s), b = std::as_const(updated).at(s);
        differing += !std::equal(a.begin(), a.end(), b.begin());
    }
    EXPECT_EQ(differing, 0u);

    // Carried over from the surface before the change: the same vectors, with fewer rays cast.
    size_t recomputed = 0;
    const EnvironmentTransfer carried = carry_environment_transfer(before_surface, before, surface, bvh, {}, &recomputed);
    EXPECT_GT(recomputed, 4u);
    EXPECT_LT(recomputed, n);
    for (size_t s = 0; s < n; ++s) {
        const std::span<const float> a = after.at(s), b = carried.at(s);
        EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin())) << s;
    }

    // Deferred: the sphere's vertices that see the plate keep their old vectors and are listed, and
    // sampling the list later gives the same vectors again. The plate's corners, whose normals vanish
    // (its two sides cancel), have no direction to stand in with: they are sampled at once, coarsely,
    // and listed first.
    size_t now = 0;
    std::vector<int32_t> deferred;
    EnvironmentTransfer deferring = carry_environment_transfer(before_surface, before, surface, bvh, {}, &now, {}, &deferred);
    EXPECT_EQ(now, 4u);
    EXPECT_EQ(deferred.size(), recomputed);
    for (int k = 0; k < 4; ++k) EXPECT_GE(deferred[k], static_cast<int32_t>(n - 4));
    size_t stale = 0;
    for (const int32_t s : deferred) {
        const std::span<const float> a = after.at(s), b = std::as_const(deferring).at(s);
        stale += !std::equal(a.begin(), a.end(), b.begin());
    }
    EXPECT_GT(stale, 0u) << "the plate shadows some of the listed vertices";
    // A further carry with nothing changed keeps the list waiting (sampling at once only the corners,
    // which never have a vector to stand in with), or samples it when not deferring.
    std::vector<int32_t> still;
    const EnvironmentTransfer again =
        carry_environment_transfer(surface, deferring, surface, bvh, {}, &now, deferred, &still);
    EXPECT_EQ(now, 4u);
    EXPECT_EQ(still, deferred);
    const EnvironmentTransfer sampled = carry_environment_transfer(surface, deferring, surface, bvh, {}, &now, deferred);
    EXPECT_EQ(now, deferred.size());
    update_environment_transfer(surface, bvh, deferred, deferring);
    for (size_t s = 0; s < n; ++s) {
        const std::span<const float> a = after.at(s), b = std::as_const(deferring).at(s), c = sampled.at(s);
        EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin())) << s;
        EXPECT_TRUE(std::equal(a.begin(), a.end(), c.begin())) << s;
    }
}

TEST(EnvironmentLight, RotationMovesTheLitSide) {
    const BoundarySurface surface = sphere_surface(2, 1.3);
    const TriangleBvh bvh = build_shadow_bvh(surface);
    // Bright towards +x only.
    EnvironmentLight environment = environment_light(map_of(128, 64, [](const Eigen::Vector3d& w) {
        return w.x() > 0.7 ? Rgb{5, 5, 5} : Rgb{0.1, 0.1, 0.1};
    }));
    const EnvironmentTransfer transfer = compute_environment_transfer(surface, bvh, {});
    size_t plus_x = 0, minus_z = 0;
    for (size_t s = 0; s < surface.positions.size(); ++s) {
        if (surface.positions[s].x() > surface.positions[plus_x].x()) plus_x = s;
        if (surface.positions[s].z() < surface.positions[minus_z].z()) minus_z = s;
    }
    const std::vector<Rgb> q0 = apply_environment_transfer(transfer, environment);
    EXPECT_GT(q0[plus_x][0], 3 * q0[minus_z][0]);
    // +x turned by +90 degrees about +y goes to -z.
    environment.rotation_degrees = 90;
    const std::vector<Rgb> q90 = apply_environment_transfer(transfer, environment);
    EXPECT_GT(q90[minus_z][0], 3 * q90[plus_x][0]);
    // The transfer and the sampled reference agree on the rotated environment.
    const std::vector<Rgb> reference = sampled_environment_light(surface, bvh, true, environment, 4096);
    EXPECT_NEAR(q90[minus_z][0], reference[minus_z][0], 0.05 * reference[minus_z][0]);
}

TEST(EnvironmentLight, BadMapsAndSpecsAreRejectedWithTheirName) {
    const auto message = [](const std::function<void()>& f) {
        try {
            f();
        } catch (const InvalidArgumentError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message([] { EnvironmentMap(0, 0, {}, "empty.hdr"); }).find("empty.hdr"), std::string::npos);
    EXPECT_NE(message([] {
                  EnvironmentMap(2, 1, {Rgb{1, 1, 1}, Rgb{std::nan(""), 0, 0}}, "nan.hdr");
              }).find("nan.hdr: pixel (1, 0) is NaN"),
              std::string::npos);
    EXPECT_NE(message([] { EnvironmentMap(1, 1, {Rgb{-1, 0, 0}}, "neg.hdr"); }).find("negative"), std::string::npos);
    EXPECT_NE(message([] { EnvironmentMap(2, 2, {Rgb{1, 1, 1}}, "short.hdr"); }).find("1 pixels for a 2 x 2"),
              std::string::npos);

    EnvironmentLight environment = environment_light(map_of(4, 2, [](const Eigen::Vector3d&) { return Rgb{1, 1, 1}; }));
    environment.intensity = -1;
    EXPECT_NE(message([&] { validate(environment); }).find("intensity must be non-negative"), std::string::npos);
    environment.intensity = 1;
    environment.rotation_degrees = std::numeric_limits<double>::infinity();
    EXPECT_NE(message([&] { validate(environment); }).find("rotation must be finite"), std::string::npos);

    for (const char* spec : {"", "sky", "sky:45", "sky:-5,0", "sky:45,0,11", "sky:45,nan", "a.hdr:x", "a.hdr:0:-1",
                             "a.hdr:0:1:2", "sky:45,0:inf"})
        EXPECT_NE(message([&] { parse_environment_spec(spec); }).find("bad environment spec"), std::string::npos) << spec;
    const EnvironmentSpec spec = parse_environment_spec("studio.hdr:90:2.5");
    EXPECT_EQ(spec.file, "studio.hdr");
    EXPECT_EQ(spec.rotation_degrees, 90);
    EXPECT_EQ(spec.intensity, 2.5);
    const EnvironmentSpec sky = parse_environment_spec("sky:30,45,4");
    ASSERT_TRUE(sky.sky);
    EXPECT_EQ(sky.sky->sun_elevation_degrees, 30);
    EXPECT_EQ(sky.sky->turbidity, 4);
}

TEST(SkyModel, BrightAroundTheSunBlueOverheadAndTheSunReddensTowardsTheHorizon) {
    SkySettings settings;
    settings.sun_elevation_degrees = 30;
    settings.sun_azimuth_degrees = 0;
    const EnvironmentMap sky = make_sky_map(settings);
    const Eigen::Vector3d sun = sun_direction(settings);
    EXPECT_NEAR(sun.y(), 0.5, 1e-12);
    const Eigen::Vector3d near_sun = (sun + Eigen::Vector3d(0, 0.1, 0)).normalized();
    const Eigen::Vector3d opposite(-sun.x(), 0.3, -sun.z());
    EXPECT_GT(luminance(sky.radiance(near_sun)), 2 * luminance(sky.radiance(opposite.normalized())));
    const Rgb zenith = sky.radiance(Eigen::Vector3d::UnitY());
    EXPECT_GT(zenith[2], zenith[0]);
    // The ground: uniform below the horizon, lit by the sun and the sky.
    const Rgb ground = sky.radiance(-Eigen::Vector3d::UnitY());
    EXPECT_EQ(ground, sky.radiance(Eigen::Vector3d(0.5, -0.2, 0.3).normalized()));
    EXPECT_GT(ground[0], 0);
    // The sun: white-ish high up, redder and dimmer low down.
    const Rgb high = sun_irradiance({.sun_elevation_degrees = 80});
    const Rgb low = sun_irradiance({.sun_elevation_degrees = 5});
    EXPECT_GT(high[2], 0.9);
    EXPECT_LT(low[2] / low[0], high[2] / high[0]);
    // The sky's sun joins the direct lights.
    const Lighting lighting = lit_by(sky_environment_light(settings));
    const std::vector<Light> lights = direct_lights(lighting);
    ASSERT_EQ(lights.size(), 1u);
    EXPECT_NEAR((-lights[0].vector).dot(sun), 1.0, 1e-12);
}

}  // namespace
}  // namespace waxwork
