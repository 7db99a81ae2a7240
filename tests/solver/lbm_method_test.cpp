// The `lbm` method: the lattice-Boltzmann core on a slab whose steady state is known in closed form, its
// stable and positive ranges built on purpose, and the full method on the analytic ball.
#include "base/error.h"
#include "solver/material.h"
#include "solver/methods/lbm.h"
#include "solver/reference/analytic_ball.h"
#include "solver_test_meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace waxwork {
namespace {

// A slab of n cells along x, infinite in y and z: the transverse populations stream back into their
// own cell, so the lattice is the 1D problem. The walls sit fraction_left / fraction_right cells beyond
// the first and last cell centres; light S = 4 q / (1 - F_dr) enters at the left wall only.
struct Slab {
    int n = 20;
    double dx = 1;                      // mm
    double kappa = 1.0 / 3.0, mua = 0;  // mm, 1/mm
    double a_param = 2.0;               // A of the Robin condition
    double fraction_left = 0.5, fraction_right = 0.5;
    double tau = 1;
    double s_left = 1, s_right = 0;     // 4 q / (1 - F_dr) at each wall
    bool explicit_absorption = false;

    LbmLattice lattice() const {
        LbmLattice l;
        l.cell_count = static_cast<size_t>(n);
        const double dt = lbm_time_step(kappa, dx, tau);
        const auto coll = lbm_collision(lbm_relaxation(kappa, mua, dt, dx), explicit_absorption);
        l.keep.assign(l.cell_count, {coll[0], coll[0], coll[0]});
        l.equilibrium.assign(l.cell_count, {coll[1], coll[1], coll[1]});
        const double k_cells = 2 * a_param * kappa / dx;
        for (int w = 0; w < 2; ++w) {
            const double r = lbm_boundary_reflection(k_cells, w == 0 ? fraction_left : fraction_right, tau);
            // q with F_dr = 0 so that the source is (1 - r) S / 6.
            const double s = lbm_boundary_source(r, (w == 0 ? s_left : s_right) / 4.0, 0.0);
            l.reflection.push_back({r, r, r});
            l.source.push_back({s, s, s});
        }
        for (auto& next : l.next) next.resize(l.cell_count);
        for (int c = 0; c < n; ++c) {
            l.next[0][c] = c + 1 < n ? c + 1 : -2;  // +x: the right wall is link 1
            l.next[1][c] = c > 0 ? c - 1 : -1;      // -x: the left wall is link 0
            for (int i = 2; i < kLbmDirections; ++i) l.next[i][c] = c;
        }
        return l;
    }

    // The exact phi at cell c: phi'' = sigma^2 phi between the walls with
    // phi - K phi' = s_left at the left wall and phi + K phi' = s_right at the right one.
    double exact(int c) const {
        const double k = 2 * a_param * kappa;
        const double xl = -fraction_left * dx, xr = ((n - 1) + fraction_right) * dx, x = c * dx;
        const double sigma = std::sqrt(mua / kappa);
        // phi = alpha u(x) + beta v(x): u, v = cosh, sinh (sigma x) or 1, x when sigma = 0.
        auto u = [&](double t) { return sigma > 0 ? std::cosh(sigma * t) : 1.0; };
        auto du = [&](double t) { return sigma > 0 ? sigma * std::sinh(sigma * t) : 0.0; };
        auto v = [&](double t) { return sigma > 0 ? std::sinh(sigma * t) : t; };
        auto dv = [&](double t) { return sigma > 0 ? sigma * std::cosh(sigma * t) : 1.0; };
        const double m00 = u(xl) - k * du(xl), m01 = v(xl) - k * dv(xl);
        const double m10 = u(xr) + k * du(xr), m11 = v(xr) + k * dv(xr);
        const double det = m00 * m11 - m01 * m10;
        const double alpha = (s_left * m11 - m01 * s_right) / det, beta = (m00 * s_right - m10 * s_left) / det;
        return alpha * u(x) + beta * v(x);
    }

    double max_relative_error(const LbmRun& run) const {
        double err = 0, scale = 0;
        for (int c = 0; c < n; ++c) {
            err = std::max(err, std::abs(run.rho[c][0] - exact(c)));
            scale = std::max(scale, std::abs(exact(c)));
        }
        return err / scale;
    }
};

LbmRun run(const Slab& slab, double tolerance = 1e-12, int max_iterations = 400000) {
    LbmIterationOptions options;
    options.tolerance = tolerance;
    options.max_iterations = max_iterations;
    return run_lattice_boltzmann(slab.lattice(), options);
}

TEST(LbmMethod, SlabWithoutAbsorptionIsExactForAnyTauAndWallPosition) {
    // phi is linear between the walls; the boundary links reproduce it to round-off.
    for (double tau : {0.7, 1.0, 2.5})
        for (double fl : {0.5, 0.2, 1.0}) {
            Slab slab;
            slab.tau = tau;
            slab.fraction_left = fl;
            slab.fraction_right = 0.8;
            const LbmRun r = run(slab);
            ASSERT_TRUE(r.converged);
            std::printf("tau %.2f fraction %.2f: %d steps, max relative error %.2e\n", tau, fl, r.iterations,
                        slab.max_relative_error(r));
            EXPECT_LT(slab.max_relative_error(r), 1e-9);
        }
}

TEST(LbmMethod, SlabWithAbsorptionConvergesAtSecondOrder) {
    for (double tau : {1.0, 0.8, 2.0}) {
        double previous = 0;
        for (int n : {10, 20, 40}) {
            Slab slab;
            slab.n = n;
            slab.dx = 10.0 / n;  // a 10 mm slab, walls half a cell out
            slab.kappa = 1.0 / (3 * 1.1);
            slab.mua = 0.1;
            slab.tau = tau;
            const LbmRun r = run(slab);
            ASSERT_TRUE(r.converged);
            const double e = slab.max_relative_error(r);
            std::printf("tau %.1f n %d: %d steps, max relative error %.3e", tau, n, r.iterations, e);
            if (previous > 0) std::printf("  order %.2f", std::log2(previous / e));
            std::printf("\n");
            if (previous > 0) {
                EXPECT_GT(std::log2(previous / e), 1.8);
            }
            previous = e;
        }
    }
}

}  // namespace
}  // namespace waxwork
namespace waxwork {
namespace {

constexpr double kRadius = 10.0;  // mm
constexpr double kMua = 0.01, kMusp = 1.0, kEta = 1.3;

struct Ball {
    TetMesh mesh;
    TetConnectivity conn;
    std::vector<TetMaterial> materials;
    TetMaterial material{{kMua, kMua, kMua}, {kMusp, kMusp, kMusp}, kEta};
    explicit Ball(int level = 4, size_t tets = 16000) : mesh(test::make_ball_mesh(level, tets, kRadius)) {
        conn = build_connectivity(mesh);
        materials.assign(mesh.tet_count(), material);
    }
};

const Ball& shared_ball() {
    static const Ball ball;
    return ball;
}

struct BallRun {
    MethodSolution solution;
    double error = 0;
};

BallRun solve_ball(const Ball& ball, BallLight light, const LbmOptions& options, Progress* progress = nullptr) {
    const auto q = ball_light(ball.mesh, ball.conn, light, kEta);
    MethodProblem problem{ball.mesh, ball.conn, ball.materials, q, 1.0, progress};
    BallRun r;
    r.solution = solve_lbm(problem, options);
    r.error = ball_relative_error(ball.mesh, ball.conn, ball.material, kRadius, light, 1.0, r.solution.phi);
    return r;
}

const char* name(BallLight light) { return light == BallLight::Uniform ? "uniform" : "directional"; }

TEST(LbmMethod, BallErrorBoundsAndOrder) {
    const Ball& ball = shared_ball();
    for (BallLight light : {BallLight::Uniform, BallLight::Directional}) {
        std::vector<double> errors;
        const std::vector<double> sizes = {2.0, 1.0};
        for (double dx : sizes) {
            LbmOptions options;
            options.cell_size_mm = dx;
            const BallRun r = solve_ball(ball, light, options);
            std::printf("%s dx %.2f mm: %zu cells, %d steps, setup %.0f ms, solve %.0f ms, error %.4f%%\n", name(light), dx,
                        r.solution.unknowns, r.solution.iterations[0], r.solution.setup_ms, r.solution.solve_ms, 100 * r.error);
            for (const auto& w : r.solution.warnings) std::printf("  warning: %s\n", w.c_str());
            EXPECT_TRUE(r.solution.warnings.empty());
            errors.push_back(r.error);
        }
        std::printf("%s observed order %.2f\n", name(light), std::log(errors[0] / errors[1]) / std::log(sizes[0] / sizes[1]));
    }
}

}  // namespace
}  // namespace waxwork
