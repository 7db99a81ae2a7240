// The camera-ray Monte Carlo image checked against exact answers: the radiance reflected by a
// semi-infinite isotropically scattering medium (Chandrasekhar's law of diffuse reflection, single
// scattering included), the light a purely absorbing block lets through, determinism per seed, and the
// budgets. Numbers: docs/monte_carlo.md.
#include "base/error.h"
#include "base/progress.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "solver/reference/camera_rays.h"
#include "solver/reference/monte_carlo.h"
#include "solver/reference/monte_carlo_image.h"
#include "tetops/box_mesh.h"

#include "monte_carlo_volume.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <Eigen/Geometry>

namespace waxwork {
namespace {

using test::uniform_material;
using Volume = test::MonteCarloVolume;

// A camera at `distance` from `target` along unit `from`, with a narrow field of view (half-width
// tan = `spread`), so every pixel looks at target along very nearly -from.
PixelCamera narrow_camera(const Eigen::Vector3d& target, const Eigen::Vector3d& from, double distance, double spread,
                          int size) {
    PixelCamera camera;
    camera.eye = target + distance * from;
    camera.forward = -from;
    const Eigen::Vector3d helper = std::abs(from.y()) < 0.9 ? Eigen::Vector3d(0, 1, 0) : Eigen::Vector3d(1, 0, 0);
    camera.right = camera.forward.cross(helper).normalized();
    camera.up = camera.right.cross(camera.forward);
    camera.tan_half_width = camera.tan_half_height = spread;
    camera.width = camera.height = size;
    return camera;
}

MonteCarloOptions path_budget(int64_t paths, uint64_t seed = 1) {
    MonteCarloOptions options;
    options.max_photons = paths;
    options.seed = seed;
    return options;
}

double mean_radiance(const MonteCarloImage& mc, int c) {
    double sum = 0;
    int n = 0;
    for (size_t p = 0; p < mc.image.radiance.size(); ++p) {
        if (mc.image.coverage[p] < 1) continue;
        sum += mc.image.radiance[p][c];
        ++n;
    }
    return n > 0 ? sum / n : 0.0;
}

// Chandrasekhar's H-function for isotropic scattering of albedo a, from the H-equation
// 1/H(mu) = sqrt(1 - a) + (a/2) int_0^1 mu' H(mu') / (mu + mu') dmu' (Chandrasekhar 1960, Radiative
// Transfer, Eq. V.50), solved by iteration to convergence on a 400-point midpoint rule (H(1) agrees
// with the 400-point Gauss-Legendre values of monte_carlo_test.cpp to 1e-4).
class HFunction {
public:
    explicit HFunction(double a) : a_(a), h_(kNodes, 1.0) {
        for (int iteration = 0; iteration < 1000; ++iteration) {
            double change = 0;
            for (int i = 0; i < kNodes; ++i) {
                const double next = evaluate(node(i));
                change = std::max(change, std::abs(next - h_[i]));
                h_[i] = next;
            }
            if (change < 1e-12) break;
        }
    }
    double evaluate(double mu) const {
        double integral = 0;
        for (int j = 0; j < kNodes; ++j) integral += node(j) * h_[j] / (mu + node(j));
        return 1.0 / (std::sqrt(1 - a_) + 0.5 * a_ * integral / kNodes);
    }

private:
    static constexpr int kNodes = 400;
    static double node(int i) { return (i + 0.5) / kNodes; }
    double a_;
    std::vector<double> h_;
};

// A semi-infinite medium of mu_t = 1 / mm: a box of 2000 x 2000 x 1000 mean free paths whose top is
// z = 0, and collimated light straight down transmitting q = 1 through the top.
Volume semi_infinite(double albedo, double eta) {
    const double half = 1000, depth = 1000;
    return Volume(make_box_mesh({4, 4, 1}, Eigen::Vector3d(-half, -half, -depth), Eigen::Vector3d(half, half, 0)),
                  uniform_material(1 - albedo, albedo, eta));
}

PhotonSource normal_light_on_top(const Volume& volume) {
    PhotonSource source;
    source.entry = PhotonEntry::Collimated;
    source.vector = Eigen::Vector3d(0, 0, -1);
    source.q.assign(volume.surface.positions.size(), {0, 0, 0});
    for (size_t s = 0; s < volume.surface.positions.size(); ++s)
        if (volume.surface.positions[s].z() == 0) source.q[s] = {1, 1, 1};
    return source;
}

TEST(MonteCarloImage, HFunctionMatchesTheTabulatedValues) {
    EXPECT_NEAR(HFunction(0.5).evaluate(1.0), 1.25126, 1e-4);
    EXPECT_NEAR(HFunction(0.9).evaluate(1.0), 1.85010, 1e-4);
}

// The radiance reflected by a semi-infinite, index-matched medium with isotropic scattering under
// normally incident collimated light of irradiance E, seen at mu = cos(theta) from the normal:
//     L(mu) = a E H(mu) H(1) / (4 pi (mu + 1))
// (Chandrasekhar 1960, Eq. IV.44 with mu_0 = 1 and the incident flux pi F = E): every order of
// scattering, the single scattering a E / (4 pi (mu + 1)) included. The medium is
// semi_infinite lit on its top (q = 1: eta 1 transmits all), seen at its centre through a narrow camera.
TEST(MonteCarloImage, SemiInfiniteRadianceMatchesChandrasekhar) {
    struct Case {
        double albedo, mu;
    };
    for (const Case& k : {Case{0.5, 1.0}, Case{0.9, 1.0}, Case{0.9, 0.5}}) {
        const Volume volume = semi_infinite(k.albedo, 1.0);
        const PhotonSource source = normal_light_on_top(volume);
        const Eigen::Vector3d from(std::sqrt(1 - k.mu * k.mu), 0, k.mu);
        const PixelCamera camera = narrow_camera(Eigen::Vector3d::Zero(), from, 10, 0.01, 4);
        const MonteCarloImage mc = trace_camera_image(volume.mesh, volume.connectivity, volume.materials,
                                                      volume.surface, volume.grid, {source}, camera, path_budget(12000));
        const HFunction h(k.albedo);
        const double expected = k.albedo * h.evaluate(k.mu) * h.evaluate(1.0) / (4 * std::numbers::pi * (k.mu + 1));
        const double traced = mean_radiance(mc, 1);
        // The standard error of the mean over the (fully covered) pixels.
        double error2 = 0;
        int pixels = 0;
        for (size_t p = 0; p < mc.radiance_error.size(); ++p) {
            if (mc.image.coverage[p] < 1) continue;
            error2 += mc.radiance_error[p][1] * mc.radiance_error[p][1];
            ++pixels;
        }
        const double standard_error = std::sqrt(error2) / pixels / expected;
        std::printf("albedo %.2f mu %.2f: L = %.5f traced, %.5f Chandrasekhar (ratio %.4f, standard error %.4f)\n",
                    k.albedo, k.mu, traced, expected, traced / expected, standard_error);
        EXPECT_EQ(mc.lost_paths, 0);
        ASSERT_EQ(pixels, 16);
        // 12000 paths leave about 1% standard error on the mean: 3% is three of them (the H-function's
        // quadrature adds 1e-4).
        EXPECT_LT(standard_error, 0.012);
        EXPECT_NEAR(traced / expected, 1.0, 0.03);
    }
}

// With an index mismatch there is no closed form, but the two tracers must agree on energy: the
// radiance the camera sees, integrated over the hemisphere (M = 2 pi int_0^1 L(mu) mu dmu, 6-point
// Gauss-Legendre in mu), is the power per area the photon tracer sees leave (its diffuse reflectance
// times q = 1). This checks the refraction, the Fresnel factors and the eta^2 of both ends.
TEST(MonteCarloImage, IntegratedRadianceIsThePhotonTracersExitance) {
    const double albedo = 0.9, eta = 1.4;
    const Volume volume = semi_infinite(albedo, eta);
    const PhotonSource source = normal_light_on_top(volume);
    MonteCarloOptions photons;
    photons.max_photons = 16000;
    photons.batch_photons = 1000;
    const MonteCarloFluence fluence = trace_fluence(volume.mesh, volume.connectivity, volume.materials,
                                                    volume.surface, {source}, photons);
    const double reflectance = fluence.escaped[1] / fluence.injected[1];
    // Gauss-Legendre on [0, 1].
    const double nodes[6] = {0.033765242898424, 0.169395306766868, 0.380690406958402,
                             0.619309593041598, 0.830604693233132, 0.966234757101576};
    const double weights[6] = {0.085662246189585, 0.180380786524069, 0.233956967286346,
                               0.233956967286346, 0.180380786524069, 0.085662246189585};
    double exitance = 0;
    for (int i = 0; i < 6; ++i) {
        const double mu = nodes[i];
        const Eigen::Vector3d from(std::sqrt(1 - mu * mu), 0, mu);
        const PixelCamera camera = narrow_camera(Eigen::Vector3d::Zero(), from, 10, 0.01, 4);
        const MonteCarloImage mc = trace_camera_image(volume.mesh, volume.connectivity, volume.materials,
                                                      volume.surface, volume.grid, {source}, camera, path_budget(6000));
        exitance += 2 * std::numbers::pi * weights[i] * mean_radiance(mc, 1) * mu;
    }
    std::printf("eta %.1f, albedo %.1f: integrated radiance %.4f, photon tracer's reflectance %.4f (ratio %.4f)\n",
                eta, albedo, exitance, reflectance, exitance / reflectance);
    // The photon tracer's reflectance carries about 1% standard error at 16000 photons, the integral
    // about 1.5%: 5% is over three of their combined errors.
    EXPECT_NEAR(exitance / reflectance, 1.0, 0.05);
}

// A block that absorbs and (almost) does not scatter, under ambient light only: a camera ray straight
// through it sees the ambient's radiance inside, eta^2 q / pi (monte_carlo_image.h), attenuated by the
// chord and by the reflections at both faces:
//     L = T q / pi e^-tau / (1 - R e^-tau),  T = 1 - R, R = ((eta - 1) / (eta + 1))^2, tau = mu_a 2 mm.
// Nothing else may reach the camera: a directional light adds only single scattering, zero here.
TEST(MonteCarloImage, AnAbsorbingBlockShowsOnlyTheAmbientLightThrough) {
    const double eta = 1.3, mua = 0.5;
    Volume volume(make_box_mesh({2, 2, 2}, Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)),
                  uniform_material(mua, 1e-9, eta));
    Lighting lighting;
    lighting.ambient = {0.2, 0.4, 0.8};
    lighting.lights = {Light{LightType::Directional, Eigen::Vector3d(0.3, -1, -0.2), {5, 5, 5}}};
    lighting.shadows = false;
    const auto sources = photon_sources(volume.surface, volume.bvh, lighting);
    ASSERT_EQ(sources.size(), 2u);
    const PixelCamera camera = narrow_camera(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1), 10, 1e-4, 3);
    const MonteCarloImage mc = trace_camera_image(volume.mesh, volume.connectivity, volume.materials, volume.surface,
                                                  volume.grid, sources, camera, path_budget(400));
    const double r = std::pow((eta - 1) / (eta + 1), 2), attenuation = std::exp(-2 * mua);
    for (int c = 0; c < 3; ++c) {
        const double expected = (1 - r) * lighting.ambient[c] / std::numbers::pi * attenuation / (1 - r * attenuation);
        EXPECT_NEAR(mean_radiance(mc, c) / expected, 1.0, 1e-3) << "channel " << c;
    }
}

// Pieces are traced in their rest frame: turning and moving a piece together with its lights and the
// camera changes nothing but rounding, so the images agree pixel by pixel within their errors. A
// weakly scattering medium (mostly single scattering, which depends on the directions to the lights)
// under a point light and a directional light.
TEST(MonteCarloImage, APieceTurnedWithItsLightsAndCameraLooksTheSame) {
    auto trace = [](const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation) {
        TetMesh mesh = make_box_mesh({4, 4, 4}, Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1));
        mesh.piece_transforms[0] = {rotation, translation};
        const Volume volume(std::move(mesh), uniform_material(0.3, 0.4, 1.3));
        Lighting lighting;
        lighting.lights = {Light{LightType::Point, rotation * Eigen::Vector3d(2, 3, 1) + translation, {6, 6, 6}},
                           Light{LightType::Directional, rotation * Eigen::Vector3d(0.8, 0.3, -1), {1, 1, 1}}};
        const auto sources = photon_sources(volume.surface, volume.bvh, lighting);
        PixelCamera camera = narrow_camera(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.6, 0.5, 0.8).normalized(), 6, 0.3, 10);
        camera.eye = rotation * camera.eye + translation;
        camera.forward = rotation * camera.forward;
        camera.right = rotation * camera.right;
        camera.up = rotation * camera.up;
        return trace_camera_image(volume.mesh, volume.connectivity, volume.materials, volume.surface, volume.grid,
                                  sources, camera, path_budget(6000));
    };
    const MonteCarloImage rest = trace(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
    const MonteCarloImage turned =
        trace(Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix(), Eigen::Vector3d(5, -3, 1));
    EXPECT_EQ(rest.image.coverage, turned.image.coverage);
    double chi2 = 0, sum_rest = 0, sum_turned = 0;
    int n = 0;
    for (size_t p = 0; p < rest.image.radiance.size(); ++p) {
        if (rest.image.coverage[p] < 1) continue;
        for (int c = 0; c < 3; ++c) {
            sum_rest += rest.image.radiance[p][c];
            sum_turned += turned.image.radiance[p][c];
            const double e2 = std::pow(rest.radiance_error[p][c], 2) + std::pow(turned.radiance_error[p][c], 2);
            if (!(e2 > 0)) continue;
            chi2 += std::pow(rest.image.radiance[p][c] - turned.image.radiance[p][c], 2) / e2;
            ++n;
        }
    }
    ASSERT_GT(n, 100);
    EXPECT_LT(chi2 / n, 1.5);
    EXPECT_NEAR(sum_turned / sum_rest, 1.0, 0.02);
}

TEST(MonteCarloImage, DeterministicPerSeedOnAnyThreadCount) {
    Volume volume(make_box_mesh({3, 3, 3}, Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)),
                  uniform_material(0.05, 1.0, 1.4));
    Lighting lighting;
    lighting.lights = {Light{LightType::Point, Eigen::Vector3d(2, 3, 1), {4, 4, 4}}};
    lighting.ambient = {0.05, 0.05, 0.05};
    const auto sources = photon_sources(volume.surface, volume.bvh, lighting);
    const PixelCamera camera = narrow_camera(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.6, 0.5, 0.8).normalized(), 6, 0.3, 12);
    auto run = [&](int threads, uint64_t seed) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        return trace_camera_image(volume.mesh, volume.connectivity, volume.materials, volume.surface, volume.grid,
                                  sources, camera, path_budget(3000, seed));
    };
    const MonteCarloImage one = run(1, 7), two = run(2, 7), other = run(2, 8);
    EXPECT_EQ(one.image.radiance, two.image.radiance);
    EXPECT_EQ(one.radiance_error, two.radiance_error);
    EXPECT_EQ(one.image.coverage, two.image.coverage);
    EXPECT_NE(one.image.radiance, other.image.radiance);
    // A different seed agrees within the stated errors: mean chi^2 over the covered pixels below 3.
    double chi2 = 0;
    int n = 0;
    for (size_t p = 0; p < one.image.radiance.size(); ++p) {
        if (one.image.coverage[p] < 1 || other.image.coverage[p] < 1) continue;
        for (int c = 0; c < 3; ++c) {
            const double e2 = std::pow(one.radiance_error[p][c], 2) + std::pow(other.radiance_error[p][c], 2);
            if (!(e2 > 0)) continue;
            chi2 += std::pow(one.image.radiance[p][c] - other.image.radiance[p][c], 2) / e2;
            ++n;
        }
    }
    ASSERT_GT(n, 100);
    EXPECT_LT(chi2 / n, 3.0);
}

TEST(MonteCarloImage, StopsAtTheErrorTargetAndCanBeCancelled) {
    Volume volume(make_box_mesh({2, 2, 2}, Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)),
                  uniform_material(0.1, 1.0, 1.3));
    Lighting lighting;
    lighting.lights = {Light{LightType::Directional, Eigen::Vector3d(0, -1, -1), {1, 1, 1}}};
    const auto sources = photon_sources(volume.surface, volume.bvh, lighting);
    const PixelCamera camera = narrow_camera(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0.6, 0.8), 6, 0.25, 8);
    MonteCarloOptions options;
    options.target_relative_error = 0.05;
    int reports = 0;
    const MonteCarloImage mc =
        trace_camera_image(volume.mesh, volume.connectivity, volume.materials, volume.surface, volume.grid, sources,
                           camera, options, [&](const MonteCarloProgress&) { ++reports; });
    EXPECT_EQ(mc.stop_reason, "error");
    EXPECT_LE(*std::max_element(mc.relative_error.begin(), mc.relative_error.end()), 0.05);
    EXPECT_GE(mc.passes, options.min_batches);
    EXPECT_EQ(reports * 4, mc.passes);

    Progress cancel;
    cancel.request_cancel();
    EXPECT_THROW(trace_camera_image(volume.mesh, volume.connectivity, volume.materials, volume.surface, volume.grid,
                                    sources, camera, options, {}, &cancel),
                 CancelledError);
    options.anisotropy = 1.0;
    EXPECT_THROW(trace_camera_image(volume.mesh, volume.connectivity, volume.materials, volume.surface, volume.grid,
                                    sources, camera, options),
                 InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
