// The Monte Carlo tracer checked on its own: energy balance, the exact reflectance of a semi-infinite
// isotropically scattering medium, the diffusion solution deep inside a large high-albedo ball, and
// determinism per seed. Numbers and their sources: docs/monte_carlo.md.
#include "base/error.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "solver/reference/analytic_ball.h"
#include "solver/reference/monte_carlo.h"
#include "solver_test_meshes.h"
#include "tetops/box_mesh.h"

#include "monte_carlo_volume.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <numbers>

namespace waxwork {
namespace {

using test::uniform_material;
using Volume = test::MonteCarloVolume;

// A directional light straight down, without shadows (a convex box shadows nothing).
std::vector<PhotonSource> light_from_above(const Volume& volume) {
    Lighting lighting;
    lighting.lights = {Light{LightType::Directional, Eigen::Vector3d(0, 0, -1), {1, 1, 1}}};
    lighting.shadows = false;
    return photon_sources(volume.surface, TriangleBvh(), lighting);
}

MonteCarloOptions budget(int64_t photons, int batch = 1000) {
    MonteCarloOptions options;
    options.max_photons = photons;
    options.batch_photons = batch;
    return options;
}

TEST(MonteCarlo, WithoutAbsorptionAllLightLeaves) {
    // mu_a = 0: weight is never lost and never rouletted, so what leaves equals what entered up to
    // rounding, whatever the internal reflection (eta 1.4 reflects most light back at the surface).
    Volume volume(make_box_mesh({3, 3, 3}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(3, 3, 3)),
                  uniform_material(0.0, 2.0, 1.4));
    const auto sources = light_from_above(volume);
    const MonteCarloFluence mc = trace_fluence(volume.mesh, volume.connectivity, volume.materials, volume.surface,
                                               sources, budget(8000));
    EXPECT_EQ(mc.lost_photons, 0);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(mc.absorbed[c], 0.0);
        EXPECT_NEAR(mc.escaped[c] / mc.injected[c], 1.0, 1e-12);
    }
    // The power that entered is the lighting's: the integral of q (linear over each face) over the
    // boundary, to the sampling noise of the entry weights. The top is 9 mm^2 at q = F_t(1, 1.4); the
    // vertex normals along its edges also let some light into the sides.
    double power = 0;
    const auto& p = volume.mesh.positions;
    for (size_t f = 0; f < volume.surface.triangles.size(); ++f) {
        const auto& v = volume.connectivity.boundary_faces[f].vertices;
        const auto& tri = volume.surface.triangles[f];
        power += 0.5 * (p[v[1]] - p[v[0]]).cross(p[v[2]] - p[v[0]]).norm() *
                 (sources[0].q[tri[0]][0] + sources[0].q[tri[1]][0] + sources[0].q[tri[2]][0]) / 3;
    }
    EXPECT_GT(power, 9.0 * fresnel_transmittance(1.0, 1.4));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mc.injected[c] / power, 1.0, 0.01);
    double exitance = 0;
    for (size_t f = 0; f < mc.face_exitance.size(); ++f) {
        const auto& v = volume.connectivity.boundary_faces[f].vertices;
        exitance += mc.face_exitance[f][0] * 0.5 * (p[v[1]] - p[v[0]]).cross(p[v[2]] - p[v[0]]).norm();
    }
    EXPECT_NEAR(exitance / mc.escaped[0], 1.0, 1e-12);
}

TEST(MonteCarlo, WithAbsorptionAbsorbedPlusEscapedIsInjected) {
    // Russian roulette keeps the balance only in expectation: 1% at 16000 photons per channel.
    Volume volume(make_box_mesh({3, 3, 3}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(3, 3, 3)),
                  uniform_material(0.5, 2.0, 1.3));
    const MonteCarloFluence mc = trace_fluence(volume.mesh, volume.connectivity, volume.materials, volume.surface,
                                               light_from_above(volume), budget(16000));
    EXPECT_EQ(mc.lost_photons, 0);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(mc.absorbed[c], 0.1 * mc.injected[c]);
        EXPECT_NEAR((mc.absorbed[c] + mc.escaped[c]) / mc.injected[c], 1.0, 0.01);
        // The track-length estimator and the absorption tally are the same integral: sum mu_a phi_t V_t.
        double absorbed = 0;
        for (size_t t = 0; t < volume.mesh.tet_count(); ++t)
            absorbed += 0.5 * mc.tet_phi[t][c] * signed_volume(volume.mesh, t);
        EXPECT_NEAR(absorbed / mc.absorbed[c], 1.0, 1e-9);
    }
}

// Total diffuse reflectance of a semi-infinite, index-matched medium with isotropic scattering of
// single-scattering albedo a under normally incident collimated light: R = 1 - H(1) sqrt(1 - a)
// (Chandrasekhar 1960, Radiative Transfer, Sec. 47, the plane albedo of a semi-infinite atmosphere),
// with Chandrasekhar's H-function for isotropic scattering. H(1) solved from the H-equation
// 1/H(mu) = sqrt(1 - a) + (a/2) int_0^1 mu' H(mu') / (mu + mu') dmu' with 400-point Gauss-Legendre:
// H(1; 0.5) = 1.25126, H(1; 0.9) = 1.85010, H(1; 0.99) = 2.47279 (docs/monte_carlo.md gives the
// script).
struct SemiInfiniteCase {
    double albedo;
    double reflectance;
};
constexpr SemiInfiniteCase kSemiInfinite[] = {{0.5, 0.115226}, {0.9, 0.414947}, {0.99, 0.752721}};

// The total diffuse reflectance (over the light that entered) of a semi-infinite medium of mu_t = 1 / mm
// under normally incident collimated light: a box 2000 x 2000 x 1000 mean free paths, lit only on its
// central top square (q = 1 at the top's interior vertices, so no side triangle receives light); the
// sides and the bottom lie hundreds of diffusion lengths away.
double semi_infinite_reflectance(double albedo, double eta, int64_t photons) {
    const std::array<int, 3> cells = {4, 4, 1};
    const double half = 1000, depth = 1000;
    Volume volume(make_box_mesh(cells, Eigen::Vector3d(-half, -half, -depth), Eigen::Vector3d(half, half, 0)),
                  uniform_material(1 - albedo, albedo, eta));
    PhotonSource source;
    source.entry = PhotonEntry::Collimated;
    source.vector = Eigen::Vector3d(0, 0, -1);
    source.q.assign(volume.surface.positions.size(), {0, 0, 0});
    for (size_t s = 0; s < volume.surface.positions.size(); ++s) {
        const Eigen::Vector3d& p = volume.surface.positions[s];
        if (p.z() == 0 && std::abs(p.x()) < half && std::abs(p.y()) < half) source.q[s] = {1, 1, 1};
    }
    const MonteCarloFluence mc = trace_fluence(volume.mesh, volume.connectivity, volume.materials, volume.surface,
                                               {source}, budget(photons));
    EXPECT_EQ(mc.lost_photons, 0);
    double top = 0;
    for (size_t f = 0; f < mc.face_exitance.size(); ++f) {
        const auto& v = volume.connectivity.boundary_faces[f].vertices;
        const auto& p = volume.mesh.positions;
        const Eigen::Vector3d n = (p[v[1]] - p[v[0]]).cross(p[v[2]] - p[v[0]]);
        if (n.z() > 0) top += mc.face_exitance[f][1] * 0.5 * n.norm();
    }
    return top / mc.injected[1];
}

TEST(MonteCarlo, SemiInfiniteReflectanceMatchesChandrasekhar) {
    for (const SemiInfiniteCase& k : kSemiInfinite) {
        const double reflectance = semi_infinite_reflectance(k.albedo, 1.0, 40000);
        // 40000 photons: the binomial standard deviation is at most 0.0025; 0.01 is four of them.
        std::printf("albedo %.2f: R = %.4f (reference %.4f)\n", k.albedo, reflectance, k.reflectance);
        EXPECT_NEAR(reflectance, k.reflectance, 0.01) << "albedo " << k.albedo;
    }
}

TEST(MonteCarlo, IndexMismatchTrapsLightInASemiInfiniteMedium) {
    // At eta = 1.4 the surface reflects diffuse light back in (F_dr = 0.53): each return is another
    // chance to be absorbed, so less of what entered comes out than at eta = 1. The dipole of Jensen et
    // al. 2001 (diffuse_reflectance) is printed as a comparison only: it is an approximation.
    for (const SemiInfiniteCase& k : kSemiInfinite) {
        const double reflectance = semi_infinite_reflectance(k.albedo, 1.4, 16000);
        const double dipole = diffuse_reflectance(uniform_material(1 - k.albedo, k.albedo, 1.4))[1];
        std::printf("albedo %.2f, eta 1.4: R = %.4f (eta 1: %.4f; dipole %.4f)\n", k.albedo, reflectance,
                    k.reflectance, dipole);
        EXPECT_LT(reflectance, k.reflectance - 0.02) << "albedo " << k.albedo;
    }
}

TEST(MonteCarlo, AgreesWithDiffusionDeepInsideALargeBall) {
    // Radius 10 mm at mu_s' = 1, mu_a = 0.01 per mm (reduced albedo 0.99): 10 transport mean free paths.
    // Under uniform diffuse light diffusion is accurate far from the boundary; the transport solution
    // and the diffusion series (analytic_ball.h) differ there only by how the boundary layer feeds the
    // interior. Compared over the tets within 5 mm of the centre (volume-weighted mean), where the
    // batch noise at 64000 photons is about 0.5%.
    constexpr double kRadius = 10, kMua = 0.01, kMusp = 1, kEta = 1.3;
    Volume volume(test::make_ball_mesh(3, 3000, kRadius), uniform_material(kMua, kMusp, kEta));
    PhotonSource source;
    source.entry = PhotonEntry::Diffuse;
    source.q.assign(volume.surface.positions.size(), {1, 1, 1});
    const MonteCarloFluence mc = trace_fluence(volume.mesh, volume.connectivity, volume.materials, volume.surface,
                                               {source}, budget(64000, 2000));
    const AnalyticBall exact(kRadius, kMua, kMusp, kEta, {1.0});
    double mc_sum = 0, exact_sum = 0, volume_sum = 0;
    for (size_t t = 0; t < volume.mesh.tet_count(); ++t) {
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (int32_t v : volume.mesh.tets[t]) centroid += volume.mesh.positions[v] / 4;
        if (centroid.norm() > 0.5 * kRadius) continue;
        const double v = signed_volume(volume.mesh, t);
        mc_sum += mc.tet_phi[t][0] * v;
        exact_sum += exact(centroid) * v;
        volume_sum += v;
    }
    const double ratio = mc_sum / exact_sum;
    std::printf("deep inside: MC %.4f, diffusion %.4f, ratio %.4f, boundary relative error %.4f\n",
                mc_sum / volume_sum, exact_sum / volume_sum, ratio, mc.relative_error[0]);
    EXPECT_NEAR(ratio, 1.0, 0.03);
}

TEST(MonteCarlo, AnisotropicScatteringKeepsTheReducedCoefficient) {
    // By the similarity relation the light deep inside depends on mu_s' = mu_s (1 - g) alone: with
    // g = 0.5 (mu_s doubled) the ball of the test above must still agree with the diffusion series.
    // This checks the Henyey-Greenstein sampling and the scaling of mu_s; 16000 photons, about 1% noise.
    constexpr double kRadius = 10, kMua = 0.01, kMusp = 1, kEta = 1.3;
    Volume volume(test::make_ball_mesh(3, 3000, kRadius), uniform_material(kMua, kMusp, kEta));
    PhotonSource source;
    source.entry = PhotonEntry::Diffuse;
    source.q.assign(volume.surface.positions.size(), {1, 1, 1});
    MonteCarloOptions options = budget(16000, 2000);
    options.anisotropy = 0.5;
    const MonteCarloFluence mc =
        trace_fluence(volume.mesh, volume.connectivity, volume.materials, volume.surface, {source}, options);
    const AnalyticBall exact(kRadius, kMua, kMusp, kEta, {1.0});
    double mc_sum = 0, exact_sum = 0;
    for (size_t t = 0; t < volume.mesh.tet_count(); ++t) {
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (int32_t v : volume.mesh.tets[t]) centroid += volume.mesh.positions[v] / 4;
        if (centroid.norm() > 0.5 * kRadius) continue;
        mc_sum += mc.tet_phi[t][0] * signed_volume(volume.mesh, t);
        exact_sum += exact(centroid) * signed_volume(volume.mesh, t);
    }
    std::printf("g = 0.5, deep inside: ratio %.4f\n", mc_sum / exact_sum);
    EXPECT_NEAR(mc_sum / exact_sum, 1.0, 0.04);
}

TEST(MonteCarlo, APieceTurnedWithItsLightTracesTheSame) {
    // Pieces are traced in their rest frame: turning a piece and its light together changes nothing
    // but rounding, so the power and where it is absorbed agree to the noise. A weakly scattering
    // medium (mean free path 1.4 mm in a 2 mm box) under oblique light, so that where the light goes
    // depends on the direction it enters with.
    const TetMaterial material = uniform_material(0.5, 0.2, 1.3);
    struct Result {
        MonteCarloFluence mc;
        Eigen::Vector3d centroid;  // of the absorbed power, rest frame
    };
    auto trace = [&](const Eigen::Matrix3d& rotation) {
        TetMesh mesh = make_box_mesh({4, 4, 4}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 2, 2));
        mesh.piece_transforms[0].rotation = rotation;
        mesh.piece_transforms[0].translation = Eigen::Vector3d(5, -3, 1);
        Volume volume(std::move(mesh), material);
        Lighting lighting;
        lighting.lights = {Light{LightType::Directional, rotation * Eigen::Vector3d(0.8, 0.3, -1), {1, 1, 1}}};
        lighting.shadows = false;
        Result r{trace_fluence(volume.mesh, volume.connectivity, volume.materials, volume.surface,
                               photon_sources(volume.surface, TriangleBvh(), lighting), budget(16000)),
                 Eigen::Vector3d::Zero()};
        double total = 0;
        for (size_t t = 0; t < volume.mesh.tet_count(); ++t) {
            Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
            for (int32_t v : volume.mesh.tets[t]) centroid += volume.mesh.positions[v] / 4;
            const double absorbed = r.mc.tet_phi[t][0] * signed_volume(volume.mesh, t);
            r.centroid += absorbed * centroid;
            total += absorbed;
        }
        r.centroid /= total;
        return r;
    };
    const Result rest = trace(Eigen::Matrix3d::Identity());
    const Result turned = trace(Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix());
    EXPECT_NEAR(turned.mc.injected[0] / rest.mc.injected[0], 1.0, 0.01);
    EXPECT_NEAR(turned.mc.absorbed[0] / rest.mc.absorbed[0], 1.0, 0.01);
    EXPECT_NEAR(turned.mc.escaped[0] / rest.mc.escaped[0], 1.0, 0.01);
    std::printf("absorbed centroid: rest %.4f %.4f %.4f, turned %.4f %.4f %.4f\n", rest.centroid.x(),
                rest.centroid.y(), rest.centroid.z(), turned.centroid.x(), turned.centroid.y(), turned.centroid.z());
    EXPECT_LT((turned.centroid - rest.centroid).norm(), 0.01);
}

TEST(MonteCarlo, DeterministicPerSeedOnAnyThreadCount) {
    Volume volume(make_box_mesh({2, 2, 2}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 2, 2)),
                  uniform_material(0.1, 1.0, 1.3));
    const auto sources = light_from_above(volume);
    auto run = [&](int threads, uint64_t seed) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        MonteCarloOptions options = budget(4000, 250);
        options.seed = seed;
        return trace_fluence(volume.mesh, volume.connectivity, volume.materials, volume.surface, sources, options);
    };
    const MonteCarloFluence one = run(1, 7), two = run(2, 7), other = run(2, 8);
    EXPECT_EQ(one.phi, two.phi);
    EXPECT_EQ(one.phi_error, two.phi_error);
    EXPECT_EQ(one.escaped, two.escaped);
    EXPECT_NE(one.phi, other.phi);
    // The standard error is that of the mean of independent batches: a different seed lands within a
    // few standard errors (boundary vertices, green channel).
    double chi2 = 0;
    int n = 0;
    for (int32_t v : volume.connectivity.boundary_vertices) {
        const double e = std::hypot(one.phi_error[v][1], other.phi_error[v][1]);
        if (e > 0) {
            chi2 += std::pow((one.phi[v][1] - other.phi[v][1]) / e, 2);
            ++n;
        }
    }
    ASSERT_GT(n, 0);
    EXPECT_LT(chi2 / n, 3.0);
}

TEST(MonteCarlo, StopsAtTheErrorTarget) {
    Volume volume(make_box_mesh({2, 2, 2}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 2, 2)),
                  uniform_material(0.1, 1.0, 1.3));
    MonteCarloOptions options;
    options.target_relative_error = 0.05;
    options.batch_photons = 200;
    int reports = 0;
    const MonteCarloFluence mc =
        trace_fluence(volume.mesh, volume.connectivity, volume.materials, volume.surface, light_from_above(volume),
                      options, [&](const MonteCarloProgress&) { ++reports; });
    EXPECT_EQ(mc.stop_reason, "error");
    EXPECT_LE(*std::max_element(mc.relative_error.begin(), mc.relative_error.end()), 0.05);
    EXPECT_EQ(reports, mc.batches / 8);
}

TEST(MonteCarlo, CancelStopsTheTrace) {
    Volume volume(make_box_mesh({2, 2, 2}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 2, 2)),
                  uniform_material(0.1, 1.0, 1.3));
    Progress progress;
    MonteCarloOptions options;
    options.max_seconds = 1000;
    options.batch_photons = 100;
    EXPECT_THROW(trace_fluence(volume.mesh, volume.connectivity, volume.materials, volume.surface,
                               light_from_above(volume), options,
                               [&](const MonteCarloProgress& p) {
                                   if (p.batches >= 16) progress.request_cancel();
                               },
                               &progress),
                 CancelledError);
}

TEST(MonteCarlo, RejectsBadOptions) {
    Volume volume(make_box_mesh({1, 1, 1}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1)),
                  uniform_material(0.1, 1.0, 1.3));
    const auto sources = light_from_above(volume);
    auto trace = [&](const MonteCarloOptions& options) {
        trace_fluence(volume.mesh, volume.connectivity, volume.materials, volume.surface, sources, options);
    };
    MonteCarloOptions none;
    EXPECT_THROW(trace(none), InvalidArgumentError);  // no budget at all
    MonteCarloOptions g = budget(100);
    g.anisotropy = 1.0;
    EXPECT_THROW(trace(g), InvalidArgumentError);
    MonteCarloOptions seconds = budget(0);
    seconds.max_seconds = std::nan("");
    EXPECT_THROW(trace(seconds), InvalidArgumentError);
    MonteCarloOptions error = budget(0);
    error.target_relative_error = -0.1;
    EXPECT_THROW(trace(error), InvalidArgumentError);
    std::vector<TetMaterial> few(volume.materials.begin(), volume.materials.end() - 1);
    EXPECT_THROW(trace_fluence(volume.mesh, volume.connectivity, few, volume.surface, sources, budget(100)),
                 InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
