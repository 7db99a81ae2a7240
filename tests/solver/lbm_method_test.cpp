// The `lbm` method: the lattice-Boltzmann core on a slab whose steady state is known in closed form, its
// stable and positive ranges built on purpose, and the full method on the analytic ball.
#include "base/error.h"
#include "solver/material.h"
#include "solver/methods/lbm.h"
#include "solver/methods/voxel_grid.h"
#include "io/surface_reader.h"
#include "solver/reference/analytic_ball.h"
#include "tetops/tetrahedralize.h"
#include "solver_test_meshes.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
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
    bool curvature_correction = true;

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
            const double g = lbm_boundary_curvature_gain(r, k_cells, w == 0 ? fraction_left : fraction_right);
            if (curvature_correction) l.curvature_gain.push_back({g, g, g});
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
    for (double tau : {1.0, 0.8}) {
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

TEST(LbmMethod, SlabWallsOffTheHalfCellNeedTheCurvatureCorrection) {
    // With absorption phi curves between the last cell centre and the wall; without the correction the
    // boundary flux is off by mu_a phi (fraction - 1/2) dx: first order.
    double with_errors[2], without_errors[2];
    for (int k = 0; k < 2; ++k) {
        Slab slab;
        slab.n = k == 0 ? 20 : 40;
        slab.dx = 10.0 / slab.n;
        slab.kappa = 1.0 / (3 * 1.1);
        slab.mua = 0.1;
        slab.fraction_left = 0.2;
        slab.fraction_right = 0.9;
        with_errors[k] = slab.max_relative_error(run(slab));
        slab.curvature_correction = false;
        without_errors[k] = slab.max_relative_error(run(slab));
        std::printf("n %d: max relative error %.3e with the curvature correction, %.3e without\n", slab.n, with_errors[k],
                    without_errors[k]);
    }
    EXPECT_LT(with_errors[1], 1e-3);
    EXPECT_LT(with_errors[1], 0.1 * without_errors[1]);
    EXPECT_LT(std::log2(without_errors[0] / without_errors[1]), 1.2);  // the first order it removes
}

// Two layers of a slab, kappa 3:1 and different mu_a: one dt for both (lbm_units.h), so the stiffer
// layer gets a smaller tau, and the steady state must carry the flux kappa dphi/dx across the interface.
TEST(LbmMethod, TwoMaterialSlabConvergesWithOneTimeStep) {
    const double kappa[2] = {1.0 / (3 * 1.1), 1.0 / (3 * 3.3)}, mua[2] = {0.1, 0.3}, a_param = 2.0, thickness = 10.0;
    double previous = 0;
    for (int n : {20, 40, 80}) {
        const double dx = thickness / n;
        const double dt = lbm_time_step(kappa[0], dx, 1.0);
        LbmLattice l;
        l.cell_count = static_cast<size_t>(n);
        for (auto& next : l.next) next.resize(l.cell_count);
        std::array<double, 2> tau{};
        for (int c = 0; c < n; ++c) {
            const int m = c < n / 2 ? 0 : 1;
            const LbmRelaxation r = lbm_relaxation(kappa[m], mua[m], dt, dx);
            tau[m] = r.tau;
            const auto coll = lbm_collision(r, false);
            l.keep.push_back({coll[0], coll[0], coll[0]});
            l.equilibrium.push_back({coll[1], coll[1], coll[1]});
            l.next[0][c] = c + 1 < n ? c + 1 : -2;
            l.next[1][c] = c > 0 ? c - 1 : -1;
            for (int i = 2; i < kLbmDirections; ++i) l.next[i][c] = c;
        }
        for (int w = 0; w < 2; ++w) {  // light S = 1 enters at the left wall (layer 0) only
            const double r = lbm_boundary_reflection(2 * a_param * kappa[w] / dx, 0.5, tau[w]);
            const double src = lbm_boundary_source(r, w == 0 ? 0.25 : 0.0, 0.0);
            l.reflection.push_back({r, r, r});
            l.source.push_back({src, src, src});
        }
        LbmIterationOptions options;
        options.tolerance = 1e-12;
        options.max_iterations = 1000000;
        const LbmRun run = run_lattice_boltzmann(l, options);
        ASSERT_TRUE(run.converged);
        // Exact: phi_m = alpha_m cosh(s_m y) + beta_m sinh(s_m y), y from the interface at thickness / 2;
        // Robin at both walls, phi and kappa phi' continuous at the interface.
        const double s0 = std::sqrt(mua[0] / kappa[0]), s1 = std::sqrt(mua[1] / kappa[1]), h = thickness / 2;
        const double k0 = 2 * a_param * kappa[0], k1 = 2 * a_param * kappa[1];
        Eigen::Matrix4d m;
        Eigen::Vector4d rhs(1, 0, 0, 0);
        // left wall y = -h, outward -x: phi - k0 phi' = 1
        m.row(0) << std::cosh(-s0 * h) - k0 * s0 * std::sinh(-s0 * h), std::sinh(-s0 * h) - k0 * s0 * std::cosh(-s0 * h), 0, 0;
        // right wall y = h: phi + k1 phi' = 0
        m.row(1) << 0, 0, std::cosh(s1 * h) + k1 * s1 * std::sinh(s1 * h), std::sinh(s1 * h) + k1 * s1 * std::cosh(s1 * h);
        m.row(2) << 1, 0, -1, 0;                                   // phi continuous
        m.row(3) << 0, kappa[0] * s0, 0, -kappa[1] * s1;           // kappa phi' continuous
        const Eigen::Vector4d c = m.fullPivLu().solve(rhs);
        double err = 0, scale = 0;
        for (int cell = 0; cell < n; ++cell) {
            const double y = (cell + 0.5) * dx - h;
            const double exact = cell < n / 2 ? c[0] * std::cosh(s0 * y) + c[1] * std::sinh(s0 * y)
                                              : c[2] * std::cosh(s1 * y) + c[3] * std::sinh(s1 * y);
            err = std::max(err, std::abs(run.rho[cell][0] - exact));
            scale = std::max(scale, std::abs(exact));
        }
        err /= scale;
        std::printf("two layers, n %d: tau %.3f / %.3f, %d steps, max relative error %.3e", n, tau[0], tau[1], run.iterations, err);
        if (previous > 0) std::printf("  order %.2f", std::log2(previous / err));
        std::printf("\n");
        if (n == 80) {
            EXPECT_LT(err, 0.005);
            EXPECT_GT(std::log2(previous / err), 1.5);
        }
        previous = err;
    }
}

TEST(LbmMethod, BallErrorBoundsAndSecondOrder) {
    const Ball& ball = shared_ball();
    struct Bound {
        BallLight light;
        double coarse, fine;  // error bounds at 2 mm and 1 mm cells
    };
    for (const Bound& b : {Bound{BallLight::Uniform, 0.03, 0.004}, Bound{BallLight::Directional, 0.04, 0.01}}) {
        std::vector<double> errors;
        for (double dx : {2.0, 1.0}) {
            LbmOptions options;
            options.cell_size_mm = dx;
            const BallRun r = solve_ball(ball, b.light, options);
            std::printf("%s dx %.2f mm: %zu cells, %d steps, error %.4f%%\n", name(b.light), dx, r.solution.unknowns,
                        r.solution.iterations[0], 100 * r.error);
            for (const auto& w : r.solution.warnings) std::printf("  warning: %s\n", w.c_str());
            // At 2 mm the cells are coarser than the Robin length 2 A kappa = 1.7 mm on a few links.
            if (dx < 1.5) {
                EXPECT_TRUE(r.solution.warnings.empty());
            }
            errors.push_back(r.error);
        }
        EXPECT_LT(errors[0], b.coarse);
        EXPECT_LT(errors[1], b.fine);
        const double order = std::log2(errors[0] / errors[1]);
        std::printf("%s observed order %.2f\n", name(b.light), order);
        EXPECT_GT(order, 1.5);
    }
}

TEST(LbmMethod, TangentialCorrectionMakesObliqueLinksAccurate) {
    // Without it each link imposes the Robin condition on the derivative along itself: first order
    // where phi varies along the boundary (the directional light).
    const Ball& ball = shared_ball();
    LbmOptions options;
    options.cell_size_mm = 1.0;
    const double with = solve_ball(ball, BallLight::Directional, options).error;
    options.tangential_correction = false;
    const double without = solve_ball(ball, BallLight::Directional, options).error;
    std::printf("directional, 1 mm: error %.3f%% with the tangential correction, %.3f%% without\n", 100 * with, 100 * without);
    EXPECT_LT(with, 0.6 * without);
}

TEST(LbmMethod, BadOptionsAreRejected) {
    const Ball& ball = shared_ball();
    auto expect_rejected = [&](LbmOptions options, const std::string& what) {
        try {
            solve_ball(ball, BallLight::Uniform, options);
            ADD_FAILURE() << "accepted " << what;
        } catch (const InvalidArgumentError& e) {
            EXPECT_EQ(std::string(e.what()).rfind("lbm: ", 0), 0u) << e.what();
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    };
    LbmOptions o;
    o.cell_size_mm = 0;
    expect_rejected(o, "cell_size_mm");
    o = {};
    o.cell_size_mm = std::nan("");
    expect_rejected(o, "cell_size_mm");
    o = {};
    o.tau = 0.5;
    expect_rejected(o, "tau");
    o = {};
    o.tolerance = 0;
    expect_rejected(o, "tolerance");
    o = {};
    o.max_iterations = 0;
    expect_rejected(o, "max_iterations");
}

class CancelWhenIterating : public Progress {
    void on_stage(const std::string& stage) override {
        if (stage.find("iterating") != std::string::npos) request_cancel();
    }
};

TEST(LbmMethod, CancellationStopsTheIteration) {
    CancelWhenIterating progress;
    LbmOptions options;
    options.cell_size_mm = 1.0;
    EXPECT_THROW(solve_ball(shared_ball(), BallLight::Uniform, options, &progress), CancelledError);
}

// The stable and positive ranges of lbm_units.h, built on purpose on the slab.
Slab absorbing_slab(double tau) {
    Slab s;
    s.n = 20;
    s.dx = 0.5;
    s.kappa = 1.0 / (3 * 1.1);
    s.mua = 0.1;
    s.tau = tau;
    return s;
}

TEST(LbmMethod, TauAtOrBelowOneHalfDiverges) {
    const LbmRun r = run(absorbing_slab(0.45), 1e-10, 100000);
    EXPECT_TRUE(r.diverged);
    EXPECT_FALSE(r.converged);
}

TEST(LbmMethod, TauNearOneHalfOscillatesNegativeAndConvergesSlowly) {
    const LbmRun one = run(absorbing_slab(1.0), 1e-10);
    const LbmRun near = run(absorbing_slab(0.51), 1e-10);
    std::printf("tau 1: %d steps, min population %.2e; tau 0.51: %d steps, min population %.2e, min rho %.2e\n",
                one.iterations, one.min_population, near.iterations, near.min_population, near.min_rho);
    ASSERT_TRUE(one.converged && near.converged);
    EXPECT_GT(one.min_population, -1e-12);  // tau >= 1: every coefficient is non-negative (round-off only)
    EXPECT_LT(near.min_population, 0.0);
    EXPECT_LT(near.min_rho, 0.0);        // phi itself goes negative while iterating
    EXPECT_GT(near.iterations, 20 * one.iterations);
    // The steady state is still right: only the way there is bad.
    EXPECT_LT(absorbing_slab(0.51).max_relative_error(near), 0.02);
}

TEST(LbmMethod, LargeTauConvergesFasterButLessAccurately) {
    const Slab s1 = absorbing_slab(1.0), s8 = absorbing_slab(8.0);
    const LbmRun one = run(s1, 1e-10), eight = run(s8, 1e-10);
    std::printf("tau 1: %d steps, error %.3e; tau 8: %d steps, error %.3e\n", one.iterations, s1.max_relative_error(one),
                eight.iterations, s8.max_relative_error(eight));
    EXPECT_LT(eight.iterations, one.iterations / 3);
    EXPECT_GT(s8.max_relative_error(eight), 5 * s1.max_relative_error(one));
    // solve_lbm warns about it.
    LbmOptions options;
    options.cell_size_mm = 1.0;
    options.tau = 3.0;
    const BallRun r = solve_ball(shared_ball(), BallLight::Uniform, options);
    bool warned = false;
    for (const auto& w : r.solution.warnings) warned |= w.find("tau 3 > 2") != std::string::npos;
    EXPECT_TRUE(warned);
}

TEST(LbmMethod, ExplicitAbsorptionPerStepTooLargeGoesNegativeThenDiverges) {
    // A strongly absorbing slab on 1 mm cells: sigma_tr dx = 1.5 and 4.2.
    Slab s = absorbing_slab(1.0);
    s.n = 10;
    s.dx = 1.0;
    s.explicit_absorption = true;
    s.mua = 0.5;
    s.kappa = 1.0 / (3 * 1.5);
    const double a = lbm_relaxation(s.kappa, s.mua, lbm_time_step(s.kappa, s.dx, 1.0), s.dx).absorption;
    const LbmRun negative = run(s, 1e-10);
    std::printf("explicit a = %.2f: min rho %.2e\n", a, negative.min_rho);
    EXPECT_GT(a, 0.0);  // above 1 - 1/tau = 0
    EXPECT_LT(negative.min_rho, 0.0);
    s.mua = 2.0;
    s.kappa = 1.0 / (3 * 3.0);
    EXPECT_TRUE(run(s, 1e-10).diverged);  // a = 3 > 2 - 1/tau
    // The implicit absorption Waxwork uses stays positive at the same settings.
    s.explicit_absorption = false;
    const LbmRun implicit = run(s, 1e-10);
    EXPECT_TRUE(implicit.converged);
    EXPECT_GT(implicit.min_population, -1e-12);
}

TEST(LbmMethod, SolveRejectsUnstableExplicitAbsorptionAndWarnsOnCoarseCells) {
    Ball ball(2, 2000);
    const TetMaterial skin{{2.0, 2.0, 2.0}, {1.0, 1.0, 1.0}, 1.3};
    ball.materials.assign(ball.mesh.tet_count(), skin);
    LbmOptions options;
    options.cell_size_mm = 2.0;
    options.explicit_absorption = true;
    EXPECT_THROW(solve_ball(ball, BallLight::Uniform, options), InvalidArgumentError);
    options.explicit_absorption = false;
    const BallRun r = solve_ball(ball, BallLight::Uniform, options);
    bool coarse = false;
    for (const auto& w : r.solution.warnings) coarse |= w.find("diffusion length") != std::string::npos;
    EXPECT_TRUE(coarse);
}

// Where the error at the vertices comes from: the lattice's own error at the cell centres (relative L2,
// equal weights) and the error of sampling the exact cell-centre values back to the vertices.
struct ErrorSplit {
    double cells = 0, sampling = 0;
};

ErrorSplit split_error(const Ball& ball, BallLight light, double dx) {
    const auto q = ball_light(ball.mesh, ball.conn, light, kEta);
    const MethodProblem problem{ball.mesh, ball.conn, ball.materials, q, 1.0, nullptr};
    const std::vector<double> ql =
        light == BallLight::Uniform ? std::vector<double>{1.0} : directional_ball_light_coefficients(60, kEta);
    const AnalyticBall exact(kRadius, kMua, kMusp, kEta, ql);
    const VoxelGrid grid = voxelize(problem, dx);
    LbmOptions options;
    options.cell_size_mm = dx;
    LbmIterationOptions iteration;
    iteration.tolerance = options.tolerance;
    const LbmRun run = run_lattice_boltzmann(build_lbm_setup(grid, problem, options).lattice, iteration);
    double e2 = 0, n2 = 0;
    std::vector<std::array<double, 3>> cell_exact(grid.cell_count());
    for (size_t c = 0; c < grid.cell_count(); ++c) {
        const double value = exact(grid.cell_centre(static_cast<int32_t>(c)));
        e2 += (run.rho[c][0] - value) * (run.rho[c][0] - value);
        n2 += value * value;
        cell_exact[c] = {value, value, value};
    }
    return {std::sqrt(e2 / n2), ball_relative_error(ball.mesh, ball.conn, ball.material, kRadius, light, 1.0,
                                                    sample_at_vertices(grid, problem, cell_exact))};
}

// The table of docs/method_lbm.md: WAXWORK_PRINT_TABLES=1 build/tests/waxwork_solver_tests
// --gtest_filter=LbmMethod.PrintBallTable
TEST(LbmMethod, PrintBallTable) {
    if (!std::getenv("WAXWORK_PRINT_TABLES")) GTEST_SKIP() << "set WAXWORK_PRINT_TABLES=1 to print the table";
    const Ball ball(5, 128000);
    std::printf("| cell mm | cells | setup ms | solve ms | steps | uniform error | directional error | at cells u / d |"
                " sampling exact u / d |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|\n");
    for (double dx : {2.0, 1.4, 1.0, 0.7, 0.5, 0.35}) {
        LbmOptions options;
        options.cell_size_mm = dx;
        const BallRun u = solve_ball(ball, BallLight::Uniform, options);
        const BallRun d = solve_ball(ball, BallLight::Directional, options);
        const ErrorSplit su = split_error(ball, BallLight::Uniform, dx), sd = split_error(ball, BallLight::Directional, dx);
        std::printf("| %.2f | %zu | %.0f | %.0f | %d | %.3f%% | %.3f%% | %.3f%% / %.3f%% | %.3f%% / %.3f%% |\n", dx,
                    u.solution.unknowns, d.solution.setup_ms, d.solution.solve_ms, d.solution.iterations[0], 100 * u.error,
                    100 * d.error, 100 * su.cells, 100 * sd.cells, 100 * su.sampling, 100 * sd.sampling);
        std::fflush(stdout);
    }
}

// The tau table of docs/method_lbm.md: WAXWORK_PRINT_TABLES=1 build/tests/waxwork_solver_tests
// --gtest_filter=LbmMethod.PrintTauTable
TEST(LbmMethod, PrintTauTable) {
    if (!std::getenv("WAXWORK_PRINT_TABLES")) GTEST_SKIP() << "set WAXWORK_PRINT_TABLES=1 to print the table";
    const Ball& ball = shared_ball();
    std::printf("| tau | steps | solve ms | directional error | warnings |\n");
    std::printf("|---|---|---|---|---|\n");
    for (double tau : {0.51, 0.55, 0.7, 1.0, 1.5, 2.0, 4.0, 8.0}) {
        LbmOptions options;
        options.cell_size_mm = 1.0;
        options.tau = tau;
        const BallRun d = solve_ball(ball, BallLight::Directional, options);
        std::printf("| %.2f | %d | %.0f | %.3f%% |", tau, d.solution.iterations[0], d.solution.solve_ms, 100 * d.error);
        for (const auto& w : d.solution.warnings) std::printf(" %s;", w.substr(0, w.find(':', 5)).c_str());
        std::printf(" |\n");
        std::fflush(stdout);
    }
}

// The stability table of docs/method_lbm.md: WAXWORK_PRINT_TABLES=1 build/tests/waxwork_solver_tests
// --gtest_filter=LbmMethod.PrintStabilityTable
TEST(LbmMethod, PrintStabilityTable) {
    if (!std::getenv("WAXWORK_PRINT_TABLES")) GTEST_SKIP() << "set WAXWORK_PRINT_TABLES=1 to print the table";
    std::printf("| case (slab, 10 mm, mu_a 0.1, 0.5 mm cells) | steps | converged | diverged | min rho | min population | max error |\n");
    std::printf("|---|---|---|---|---|---|---|\n");
    auto row = [](const char* what, const Slab& s) {
        const LbmRun r = run(s, 1e-10, 200000);
        std::printf("| %s | %d | %s | %s | %.2e | %.2e | %s |\n", what, r.iterations, r.converged ? "yes" : "no",
                    r.diverged ? "yes" : "no", r.min_rho, r.min_population,
                    r.diverged ? "-" : (std::to_string(100 * s.max_relative_error(r)).substr(0, 5) + "%").c_str());
    };
    for (double tau : {0.45, 0.501, 0.51, 0.55, 0.7, 1.0, 2.0, 4.0, 8.0}) {
        char what[64];
        std::snprintf(what, sizeof what, "tau %.3g", tau);
        row(what, absorbing_slab(tau));
    }
    for (double mua : {0.5, 2.0})
        for (bool ex : {true, false}) {
            Slab s = absorbing_slab(1.0);
            s.n = 10;
            s.dx = 1.0;
            s.mua = mua;
            s.kappa = 1.0 / (3 * (mua + 1.0));
            s.explicit_absorption = ex;
            const double a = lbm_relaxation(s.kappa, s.mua, lbm_time_step(s.kappa, s.dx, 1.0), s.dx).absorption;
            char what[96];
            std::snprintf(what, sizeof what, "mu_a %.1f, 1 mm cells (sigma_tr dx %.1f), %s absorption a = %.2f", mua,
                          std::sqrt(mua / s.kappa), ex ? "explicit" : "implicit", a);
            row(what, s);
        }
}

// Setup and solve cost on spot (50K tets, 10 cm long): WAXWORK_PRINT_TABLES=1
// build/tests/waxwork_solver_tests --gtest_filter=LbmMethod.PrintSpotCost
TEST(LbmMethod, PrintSpotCost) {
    if (!std::getenv("WAXWORK_PRINT_TABLES")) GTEST_SKIP() << "set WAXWORK_PRINT_TABLES=1 to print the table";
    MeshingOptions meshing;
    meshing.sizing.target_tets = 50'000;
    const TetMesh mesh =
        tetrahedralize(load_closed_surface(std::string(WAXWORK_ASSET_DIR) + "/meshes/spot.obj").surface, meshing).mesh;
    const TetConnectivity conn = build_connectivity(mesh);
    Eigen::AlignedBox3d box;
    for (const auto& p : mesh.positions) box.extend(p);
    const double mm_per_unit = 100.0 / box.sizes().maxCoeff();
    const std::vector<TetMaterial> materials(mesh.tet_count(), material_preset("marble"));
    std::vector<std::array<double, 3>> q(mesh.vertex_count(), {0, 0, 0});
    for (int32_t v : conn.boundary_vertices) q[v] = {1, 1, 1};
    std::printf("| cell mm | cells | setup ms | solve ms | steps |\n|---|---|---|---|---|\n");
    for (double dx : {4.0, 2.0, 1.0}) {
        LbmOptions options;
        options.cell_size_mm = dx;
        const MethodSolution s = solve_lbm({mesh, conn, materials, q, mm_per_unit, nullptr}, options);
        std::printf("| %.1f | %zu | %.0f | %.0f | %d |\n", dx, s.unknowns, s.setup_ms, s.solve_ms, s.iterations[0]);
        for (const auto& w : s.warnings) std::printf("  warning: %s\n", w.c_str());
        std::fflush(stdout);
    }
}

}  // namespace
}  // namespace waxwork
