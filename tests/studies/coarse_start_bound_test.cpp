#include "base/error.h"
#include "bench/studies/coarse_start_bound.h"
#include "multires/multires_test_systems.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace waxwork {
namespace {

struct BoundFixture {
    testing::TestSystem system = testing::make_test_system(9);
    MultiresHierarchy hierarchy;
    ChannelVectors reference;

    BoundFixture() {
        HierarchyOptions options;
        options.min_coarse_vertices = 50;
        hierarchy = build_multires_hierarchy(system.matrix, system.mesh.positions, options);
        for (int c = 0; c < 3; ++c)
            reference[static_cast<size_t>(c)] =
                testing::reference_solution(system.matrix, system.b[static_cast<size_t>(c)], c, 1e-13);
    }
};

// Combined relative error over the channels, written out here independently of the library's.
double combined_error(const ChannelVectors& x, const ChannelVectors& reference) {
    double e = 0, r = 0;
    for (size_t c = 0; c < 3; ++c)
        for (size_t i = 0; i < x[c].size(); ++i) {
            e += (x[c][i] - reference[c][i]) * (x[c][i] - reference[c][i]);
            r += reference[c][i] * reference[c][i];
        }
    return std::sqrt(e / r);
}

std::vector<double> multiply(const HierarchyLevel& level, int channel, const std::vector<double>& x) {
    std::vector<double> y(level.size(), 0.0);
    const std::vector<double>& values = level.values[static_cast<size_t>(channel)];
    for (size_t i = 0; i < level.size(); ++i)
        for (int32_t k = level.offsets[i]; k < level.offsets[i + 1]; ++k)
            y[i] += values[static_cast<size_t>(k)] * x[static_cast<size_t>(level.columns[static_cast<size_t>(k)])];
    return y;
}

std::vector<double> interpolated(const MultiresHierarchy& h, const std::vector<double>& coarse) {
    std::vector<double> fine(h.levels[0].size());
    interpolate(h.levels[0].interpolation, coarse, fine);
    return fine;
}

// P^T v (the transpose of Eq. 16's operator, applied by scattering its rows).
std::vector<double> restricted_transpose(const MultiresHierarchy& h, const std::vector<double>& fine) {
    const InterpolationOperator& p = h.levels[0].interpolation;
    std::vector<double> coarse(h.levels[1].size(), 0.0);
    for (size_t v = 0; v < p.rows(); ++v)
        for (int32_t k = p.offsets[v]; k < p.offsets[v + 1]; ++k)
            coarse[static_cast<size_t>(p.columns[static_cast<size_t>(k)])] += p.weights[static_cast<size_t>(k)] * fine[v];
    return coarse;
}

double energy_error(const HierarchyLevel& level, int channel, const std::vector<double>& x, const std::vector<double>& reference) {
    std::vector<double> e(x.size());
    for (size_t i = 0; i < x.size(); ++i) e[i] = x[i] - reference[i];
    const std::vector<double> me = multiply(level, channel, e);
    double energy = 0;
    for (size_t i = 0; i < e.size(); ++i) energy += e[i] * me[i];
    return std::sqrt(energy);
}

double max_abs(const std::vector<double>& v) {
    double m = 0;
    for (double x : v) m = std::max(m, std::abs(x));
    return m;
}

TEST(CoarseStartBound, Eq17SolutionSolvesLevelOnesSystem) {
    const BoundFixture f;
    ASSERT_GE(f.hierarchy.level_count(), 2u);
    const HierarchyLevel& coarse = f.hierarchy.levels[1];
    for (int c = 0; c < 3; ++c) {
        const std::vector<double>& b = f.system.b[static_cast<size_t>(c)];
        const std::vector<double> y = solve_level1_eq17(f.hierarchy, c, b);
        ASSERT_EQ(y.size(), coarse.size());
        const std::vector<double> my = multiply(coarse, c, y);
        std::vector<double> residual(coarse.size());
        std::vector<double> injected(coarse.size());
        for (size_t i = 0; i < coarse.size(); ++i) {
            injected[i] = b[static_cast<size_t>(coarse.parent_vertex[i])];
            residual[i] = injected[i] - my[i];
        }
        EXPECT_LT(max_abs(residual), 1e-10 * max_abs(injected)) << "channel " << c;
    }
}

TEST(CoarseStartBound, GalerkinStartIsTheClosestInterpolantInTheEnergyNorm) {
    const BoundFixture f;
    const HierarchyLevel& fine = f.hierarchy.levels[0];
    for (int c = 0; c < 3; ++c) {
        const auto sc = static_cast<size_t>(c);
        const std::vector<double> y = solve_level1_galerkin(f.hierarchy, c, f.system.b[sc]);
        const std::vector<double> start = interpolated(f.hierarchy, y);
        // Galerkin orthogonality: P^T (b - M P y) = 0.
        const std::vector<double> mx = multiply(fine, c, start);
        std::vector<double> residual(mx.size());
        for (size_t i = 0; i < mx.size(); ++i) residual[i] = f.system.b[sc][i] - mx[i];
        EXPECT_LT(max_abs(restricted_transpose(f.hierarchy, residual)),
                  1e-10 * max_abs(restricted_transpose(f.hierarchy, f.system.b[sc])));
        // Hence no other level-1 vector interpolates closer in the M-norm: not Eq. 17's solution, not the
        // exact solution's own coarse values, not a perturbation of y.
        const double best = energy_error(fine, c, start, f.reference[sc]);
        const std::vector<double> eq17 = interpolated(f.hierarchy, solve_level1_eq17(f.hierarchy, c, f.system.b[sc]));
        EXPECT_LE(best, energy_error(fine, c, eq17, f.reference[sc]) * (1 + 1e-9));
        std::vector<double> own(y.size()), perturbed = y;
        for (size_t i = 0; i < y.size(); ++i) own[i] = f.reference[sc][static_cast<size_t>(f.hierarchy.levels[1].parent_vertex[i])];
        EXPECT_LE(best, energy_error(fine, c, interpolated(f.hierarchy, own), f.reference[sc]) * (1 + 1e-9));
        perturbed[y.size() / 2] *= 1.01;
        EXPECT_LT(best, energy_error(fine, c, interpolated(f.hierarchy, perturbed), f.reference[sc]));
    }
}

TEST(CoarseStartBound, IterationCountIsTheSmallestThatReachesTheTarget) {
    const BoundFixture f;
    const CoarseStartBound bound = measure_coarse_start_bound(f.hierarchy, f.system.b, f.reference, 1e-3);
    const auto error_after = [&](const ChannelVectors& start, int iterations) {
        ChannelVectors x = start;
        for (int c = 0; c < 3; ++c) {
            ConjugateGradientOptions options;
            options.relative_tolerance = 1e-15;
            options.max_iterations = iterations;
            if (iterations > 0)
                solve_jacobi_cg<double>(f.hierarchy.levels[0].view(c), f.system.b[static_cast<size_t>(c)],
                                        x[static_cast<size_t>(c)], options);
        }
        return combined_error(x, f.reference);
    };
    ChannelVectors zero, eq17;
    for (size_t c = 0; c < 3; ++c) {
        zero[c].assign(f.system.b[c].size(), 0.0);
        eq17[c] = interpolated(f.hierarchy, solve_level1_eq17(f.hierarchy, static_cast<int>(c), f.system.b[c]));
    }
    ASSERT_GT(bound.iterations_from_zero, 1);
    EXPECT_LE(error_after(zero, bound.iterations_from_zero), 1e-3);
    EXPECT_GT(error_after(zero, bound.iterations_from_zero - 1), 1e-3);
    ASSERT_GT(bound.iterations_from_eq17, 1);
    EXPECT_LE(error_after(eq17, bound.iterations_from_eq17), 1e-3);
    EXPECT_GT(error_after(eq17, bound.iterations_from_eq17 - 1), 1e-3);
    EXPECT_NEAR(bound.eq17_start_error, error_after(eq17, 0), 1e-12);
    EXPECT_EQ(bound.fine_vertices, f.hierarchy.levels[0].size());
    EXPECT_EQ(bound.coarse_vertices, f.hierarchy.levels[1].size());
    // A start from the exact level-1 solution is better than none on this smooth problem, and the
    // Galerkin start is at least as good in iterations.
    EXPECT_LT(bound.iterations_from_eq17, bound.iterations_from_zero);
    EXPECT_LE(bound.iterations_from_galerkin, bound.iterations_from_eq17);
    // The interpolation error of the exact solution's own coarse values is computed from those values.
    ChannelVectors own;
    for (size_t c = 0; c < 3; ++c) {
        std::vector<double> coarse(f.hierarchy.levels[1].size());
        for (size_t i = 0; i < coarse.size(); ++i) coarse[i] = f.reference[c][static_cast<size_t>(f.hierarchy.levels[1].parent_vertex[i])];
        own[c] = interpolated(f.hierarchy, coarse);
    }
    EXPECT_NEAR(bound.interpolation_error, combined_error(own, f.reference), 1e-12);
    EXPECT_GT(bound.interpolation_error, 0);
}

TEST(CoarseStartBound, AnUnreachableTargetReportsMinusOne) {
    const BoundFixture f;
    EXPECT_EQ(measure_coarse_start_bound(f.hierarchy, f.system.b, f.reference, 1e-3, 1).iterations_from_zero, -1);
}

TEST(CoarseStartBound, BadInputIsRejected) {
    const BoundFixture f;
    EXPECT_THROW(measure_coarse_start_bound(f.hierarchy, f.system.b, f.reference, 0.0), InvalidArgumentError);
    EXPECT_THROW(measure_coarse_start_bound(f.hierarchy, f.system.b, f.reference, std::nan("")), InvalidArgumentError);
    EXPECT_THROW(measure_coarse_start_bound(f.hierarchy, f.system.b, f.reference, 1.5), InvalidArgumentError);
    ChannelVectors short_b = f.system.b;
    short_b[1].pop_back();
    EXPECT_THROW(measure_coarse_start_bound(f.hierarchy, short_b, f.reference), InvalidArgumentError);
    EXPECT_THROW(solve_level1_eq17(f.hierarchy, 3, f.system.b[0]), InvalidArgumentError);
    HierarchyOptions flat;
    flat.min_coarse_vertices = std::numeric_limits<int64_t>::max();
    const MultiresHierarchy single = build_multires_hierarchy(f.system.matrix, f.system.mesh.positions, flat);
    ASSERT_EQ(single.level_count(), 1u);
    EXPECT_THROW(solve_level1_galerkin(single, 0, f.system.b[0]), InvalidArgumentError);
    EXPECT_THROW(measure_coarse_start_bound(single, f.system.b, f.reference), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
