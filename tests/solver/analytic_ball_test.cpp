// The accuracy test: the exact fluence in a homogeneous ball (seeds README) against solve_diffusion.
#include "base/error.h"
#include "solver/diffusion_matrix.h"
#include "solver/diffusion_solve.h"
#include "solver/material.h"
#include "solver/reference/analytic_ball.h"
#include "solver_test_meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

namespace waxwork {
namespace {

constexpr double kRadius = 10.0;  // mm
constexpr double kMua = 0.01, kMusp = 1.0, kEta = 1.3;
constexpr int kLegendreTerms = 60;

enum class Light { Uniform, Directional };

struct BallResult {
    size_t tets = 0;
    double h = 0;            // (volume / tets)^(1/3), mm
    double error = 0;        // relative L2 error of phi, weighted by lumped vertex volume
    std::vector<std::array<double, 3>> phi;
};

struct Ball {
    TetMesh mesh;
    TetConnectivity conn;
    std::vector<TetMaterial> materials;
    Ball(int level, size_t tets, double scale = 1.0) : mesh(test::make_ball_mesh(level, tets, kRadius / scale)) {
        conn = build_connectivity(mesh);
        TetMaterial m{{kMua, kMua, kMua}, {kMusp, kMusp, kMusp}, kEta};
        materials.assign(mesh.tet_count(), m);
    }
};

BallResult solve_ball(const Ball& ball, Light light, Discretization disc, double mm_per_unit = 1.0) {
    DiffusionOptions options;
    options.discretization = disc;
    options.relative_tolerance = 1e-7;
    options.mm_per_unit = mm_per_unit;
    const TetMaterial material{{kMua, kMua, kMua}, {kMusp, kMusp, kMusp}, kEta};
    BallComparison comparison = compare_with_analytic_ball(
        ball.mesh, ball.conn, material, kRadius, light == Light::Uniform ? BallLight::Uniform : BallLight::Directional,
        options);
    BallResult r;
    r.tets = ball.mesh.tet_count();
    r.h = std::cbrt(4.0 / 3.0 * std::numbers::pi * std::pow(kRadius, 3) / static_cast<double>(r.tets));
    r.error = comparison.relative_error;
    r.phi = std::move(comparison.solution.phi);
    return r;
}

TEST(AnalyticBall, SeriesSatisfiesTheRobinBoundary) {
    // phi + 2 A kappa dphi/dr = 4 q / (1 - F_dr) at r = R, checked numerically on the series itself.
    const auto ql = directional_ball_light_coefficients(kLegendreTerms, kEta);
    const AnalyticBall exact(kRadius, kMua, kMusp, kEta, ql);
    const double a = boundary_reflection_parameter(kEta), fdr = diffuse_fresnel_reflectance(kEta);
    for (double mu : {0.9, 0.5, -0.5}) {
        const Eigen::Vector3d dir(std::sqrt(1 - mu * mu), 0, mu);
        const double h = 1e-5;
        const double dphi = (exact(dir * kRadius) - exact(dir * (kRadius - h))) / h;
        double q = 0;
        const auto p = legendre_polynomials(kLegendreTerms, mu);
        for (int l = 0; l <= kLegendreTerms; ++l) q += ql[l] * p[l];
        EXPECT_NEAR(q, std::max(mu, 0.0) * fresnel_transmittance(mu, kEta), 2e-3);
        EXPECT_NEAR(exact(dir * kRadius) + 2 * a * diffusion_coefficient(kMua, kMusp) * dphi, 4 * q / (1 - fdr), 1e-3);
    }
}

TEST(AnalyticBall, UnderOnePercentAt16KTets) {
    const Ball ball(4, 16000);
    std::printf("ball: %zu tets, %zu vertices\n", ball.mesh.tet_count(), ball.mesh.vertex_count());
    for (Light light : {Light::Uniform, Light::Directional}) {
        const BallResult r = solve_ball(ball, light, Discretization::TransCut);
        std::printf("%s light: relative L2 error of phi %.4f%%\n", light == Light::Uniform ? "uniform" : "directional",
                    100 * r.error);
        EXPECT_LT(r.error, 0.01);
    }
}

TEST(AnalyticBall, ErrorFallsUnderRefinement) {
    struct Level {
        int surface;
        size_t tets;
    };
    const Level levels[] = {{2, 2000}, {3, 16000}, {4, 128000}};
    for (Light light : {Light::Uniform, Light::Directional}) {
        std::vector<BallResult> results;
        for (const Level& level : levels) results.push_back(solve_ball(Ball(level.surface, level.tets), light, Discretization::TransCut));
        for (size_t k = 0; k < results.size(); ++k) {
            std::printf("%s: %7zu tets h %.2f mm  error %.4f%%", light == Light::Uniform ? "uniform" : "directional",
                        results[k].tets, results[k].h, 100 * results[k].error);
            if (k > 0)
                std::printf("  observed order %.2f",
                            std::log(results[k - 1].error / results[k].error) / std::log(results[k - 1].h / results[k].h));
            std::printf("\n");
        }
        for (size_t k = 1; k < results.size(); ++k) EXPECT_LT(results[k].error, results[k - 1].error);
        // At least first order overall (linear elements converge at second order in L2).
        EXPECT_GT(std::log(results.front().error / results.back().error) / std::log(results.front().h / results.back().h), 1.0);
    }
}

TEST(AnalyticBall, TransCutAgreesWithFem) {
    const Ball ball(4, 16000);
    for (Light light : {Light::Uniform, Light::Directional}) {
        const BallResult tc = solve_ball(ball, light, Discretization::TransCut);
        const BallResult fem = solve_ball(ball, light, Discretization::Fem);
        double max_rel = 0, sum2 = 0, norm2 = 0, scale = 0;
        for (size_t v = 0; v < tc.phi.size(); ++v) scale = std::max(scale, std::abs(fem.phi[v][0]));
        for (size_t v = 0; v < tc.phi.size(); ++v) {
            const double d = tc.phi[v][0] - fem.phi[v][0];
            // Relative to the local value, floored at 1% of the peak (shadowed vertices are near zero).
            max_rel = std::max(max_rel, std::abs(d) / std::max(std::abs(fem.phi[v][0]), 0.01 * scale));
            sum2 += d * d;
            norm2 += fem.phi[v][0] * fem.phi[v][0];
        }
        const double rms = std::sqrt(sum2 / norm2);
        std::printf("%s: transcut vs fem max relative difference %.3f%%, RMS %.3f%%; errors vs exact %.4f%% / %.4f%%\n",
                    light == Light::Uniform ? "uniform" : "directional", 100 * max_rel, 100 * rms, 100 * tc.error,
                    100 * fem.error);
        EXPECT_LT(rms, 0.05);
        EXPECT_LT(fem.error, 0.02);
    }
}

TEST(AnalyticBall, ModelUnitsAreScaledToMillimetres) {
    // The same ball modelled in centimetres (radius 1 unit, 10 mm per unit) gives the same answer.
    const Ball ball(2, 2000, 10.0);
    const BallResult r = solve_ball(ball, Light::Directional, Discretization::TransCut, 10.0);
    std::printf("ball in cm: %zu tets, error %.4f%%\n", r.tets, 100 * r.error);
    EXPECT_LT(r.error, 0.03);
}

TEST(AnalyticBall, FloatSolveMatchesDouble) {
    const Ball ball(3, 16000);
    std::vector<std::array<double, 3>> q(ball.mesh.vertex_count(), {0, 0, 0});
    for (int32_t v : ball.conn.boundary_vertices) {
        const double value = directional_ball_light(ball.mesh.positions[v], kEta);
        q[v] = {value, 0.5 * value, 0.25 * value};
    }
    DiffusionOptions options;
    options.relative_tolerance = 1e-5;
    const auto d = solve_diffusion(ball.mesh, ball.conn, ball.materials, q, options);
    options.precision = SolverPrecision::Float;
    const auto f = solve_diffusion(ball.mesh, ball.conn, ball.materials, q, options);
    double diff = 0, scale = 0;
    for (size_t v = 0; v < q.size(); ++v)
        for (int c = 0; c < 3; ++c) {
            diff = std::max(diff, std::abs(d.phi[v][c] - f.phi[v][c]));
            scale = std::max(scale, std::abs(d.phi[v][c]));
        }
    std::printf("ball float vs double: max diff / max phi %.2e; iterations %d/%d, assembly %.1f ms, solve %.1f/%.1f ms\n",
                diff / scale, f.iterations[0], d.iterations[0], d.assembly_ms, f.solve_ms, d.solve_ms);
    EXPECT_LT(diff / scale, 1e-4);
}

TEST(SolveDiffusion, RejectsBadInput) {
    const Ball ball(2, 2000);
    std::vector<std::array<double, 3>> q(ball.mesh.vertex_count(), {1, 1, 1});
    DiffusionOptions options;
    auto mats = ball.materials;
    mats[0].musp[0] = -1;
    EXPECT_THROW(solve_diffusion(ball.mesh, ball.conn, mats, q, options), InvalidArgumentError);
    q.pop_back();
    EXPECT_THROW(solve_diffusion(ball.mesh, ball.conn, ball.materials, q, options), InvalidArgumentError);
    q.assign(ball.mesh.vertex_count(), {1, 1, std::nan("")});
    EXPECT_THROW(solve_diffusion(ball.mesh, ball.conn, ball.materials, q, options), InvalidArgumentError);
    // Spectralon (mu_a = 0) is solvable: the Robin term keeps the matrix definite. With no absorption
    // and uniform light the exact fluence is the constant 4 q / (1 - F_dr).
    q.assign(ball.mesh.vertex_count(), {1, 1, 1});
    mats.assign(ball.mesh.tet_count(), material_preset("spectralon"));
    options.relative_tolerance = 1e-8;
    const auto sol = solve_diffusion(ball.mesh, ball.conn, mats, q, options);
    const double expected = 4.0 / (1.0 - diffuse_fresnel_reflectance(1.3));
    for (const auto& p : sol.phi)
        for (double v : p) EXPECT_NEAR(v, expected, 1e-5 * expected);
}

}  // namespace
}  // namespace waxwork
