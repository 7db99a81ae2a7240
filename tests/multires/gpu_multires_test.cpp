// The GPU multires path (multires/gpu_bicgstab.h, multires/gpu_multires_solver.h) against the CPU
// one, on llvmpipe in CI: BiCGSTAB on a coarse level, interpolation, per-channel breakdown handling
// and the whole coarse-to-fine solve.
#include "multires/bicgstab.h"
#include "multires/gpu_bicgstab.h"
#include "multires/gpu_multires_solver.h"
#include "multires/hierarchy.h"
#include "multires/multires_solver.h"
#include "solver/gpu_test_context.h"
#include "multires_test_systems.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace waxwork {
namespace {

const testing::TestSystem& system16() {
    static const testing::TestSystem s = testing::make_test_system(16);  // 4913 vertices
    return s;
}

const MultiresHierarchy& hierarchy16() {
    static const MultiresHierarchy h = [] {
        HierarchyOptions options;
        options.min_coarse_vertices = 100;
        return build_multires_hierarchy(system16().matrix, system16().mesh.positions, options);
    }();
    return h;
}

RgbCsrView view(const HierarchyLevel& level) {
    return {level.offsets, level.columns, level.diagonal, {level.values[0], level.values[1], level.values[2]}};
}

std::vector<float> interleave(const std::array<std::vector<double>, 3>& v) {
    std::vector<float> out(3 * v[0].size());
    for (size_t i = 0; i < v[0].size(); ++i)
        for (int c = 0; c < 3; ++c) out[3 * i + c] = static_cast<float>(v[c][i]);
    return out;
}

double max_relative_difference(const std::vector<float>& gpu, const std::vector<double>& cpu, int c) {
    double diff = 0, peak = 0;
    for (size_t i = 0; i < cpu.size(); ++i) {
        diff = std::max(diff, std::abs(gpu[3 * i + c] - cpu[i]));
        peak = std::max(peak, std::abs(cpu[i]));
    }
    return diff / peak;
}

// b of a level by injection, per channel.
std::array<std::vector<double>, 3> level_rhs(const HierarchyLevel& level) {
    std::array<std::vector<double>, 3> b;
    for (int c = 0; c < 3; ++c) {
        b[c].resize(level.size());
        restrict_right_hand_side(level, system16().b[c], b[c]);
    }
    return b;
}

TEST(GpuBicgstab, MatchesTheCpuOnACoarseLevel) {
    WAXWORK_REQUIRE_GL(context);
    ASSERT_GE(hierarchy16().level_count(), 3u);
    const HierarchyLevel& level = hierarchy16().levels[1];
    GpuKernels kernels(context->gl(), {GpuMatrixFormat::SellCSigma});
    const GpuMatrix a(context->gl(), view(level), GpuMatrixFormat::SellCSigma);
    GpuBuffer diag = kernels.vector(level.size()), inv_diag = kernels.vector(level.size());
    kernels.extract_diagonal(a, diag, inv_diag);
    const auto b = level_rhs(level);
    const GpuBuffer bg = kernels.vector(level.size(), interleave(b).data());
    GpuBuffer x = kernels.vector(level.size());
    BicgstabOptions options;
    options.relative_tolerance = 1e-5;
    const auto results = solve_gpu_bicgstab(kernels, a, inv_diag, bg, x, options);
    const std::vector<float> xg = x.download<float>();
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(results[c].status, BicgstabStatus::Converged) << "channel " << c << ": " << to_string(results[c].status);
        EXPECT_LE(results[c].relative_residual, 1e-5);
        EXPECT_GT(results[c].iterations, 0);
        std::vector<double> reference(level.size(), 0.0);
        BicgstabOptions tight;
        tight.relative_tolerance = 1e-10;
        solve_jacobi_bicgstab(level.view(c), level.diagonal, b[c], reference, tight);
        EXPECT_LT(max_relative_difference(xg, reference, c), 1e-4) << "channel " << c;
    }
}

TEST(GpuBicgstab, ASingularChannelIsRevertedWhileTheOthersConverge) {
    WAXWORK_REQUIRE_GL(context);
    HierarchyLevel level = hierarchy16().levels[1];
    std::fill(level.values[0].begin(), level.values[0].end(), 0.0);  // channel r: A = 0
    GpuKernels kernels(context->gl(), {GpuMatrixFormat::Csr});
    const GpuMatrix a(context->gl(), view(level), GpuMatrixFormat::Csr);
    GpuBuffer diag = kernels.vector(level.size()), inv_diag = kernels.vector(level.size());
    kernels.extract_diagonal(a, diag, inv_diag);
    const GpuBuffer bg = kernels.vector(level.size(), interleave(level_rhs(level)).data());
    std::vector<float> start(3 * level.size(), 0.5f);
    GpuBuffer x = kernels.vector(level.size(), start.data());
    BicgstabOptions options;
    options.relative_tolerance = 1e-5;
    const auto results = solve_gpu_bicgstab(kernels, a, inv_diag, bg, x, options);
    EXPECT_TRUE(results[0].failed()) << to_string(results[0].status);
    EXPECT_TRUE(results[0].reverted);
    EXPECT_EQ(results[1].status, BicgstabStatus::Converged);
    EXPECT_EQ(results[2].status, BicgstabStatus::Converged);
    const std::vector<float> xg = x.download<float>();
    for (size_t i = 0; i < level.size(); ++i) ASSERT_EQ(xg[3 * i], 0.5f) << "the reverted channel changed at " << i;
}

TEST(GpuMultiresReport, FallbackReasonsNameTheChannelLevelAndStatus) {
    GpuMultiresReport report;
    report.coarse_levels.resize(3);  // coarsest (level 3) first
    EXPECT_EQ(report.fallback_reasons(), "");
    report.coarse_levels[0][0] = {BicgstabStatus::RhoBreakdown, 2, 1, 1, true};
    report.coarse_levels[2][0] = {BicgstabStatus::Divergence, 4, 1, 10, true};
    report.coarse_levels[1][2] = {BicgstabStatus::NonFinite, 1, 1, 1, true};
    report.coarse_levels[1][1] = {BicgstabStatus::IterationLimit, 8, 1, 0.1, false};  // kept: not a fallback
    EXPECT_EQ(report.fallback_reasons(), std::string("red: level 3: ") + to_string(BicgstabStatus::RhoBreakdown) +
                                             ", start vector kept; level 1: " + to_string(BicgstabStatus::Divergence) +
                                             ", start vector kept; blue: level 2: " +
                                             to_string(BicgstabStatus::NonFinite) + ", start vector kept");
}

TEST(GpuMultires, InterpolationMatchesTheCpu) {
    WAXWORK_REQUIRE_GL(context);
    const HierarchyLevel& fine = hierarchy16().levels[0];
    const size_t coarse_size = hierarchy16().levels[1].size();
    GpuKernels kernels(context->gl(), {});
    const GpuInterpolation p(context->gl(), fine.interpolation.offsets, fine.interpolation.columns,
                             fine.interpolation.weights);
    std::array<std::vector<double>, 3> coarse;
    for (int c = 0; c < 3; ++c) {
        coarse[c].resize(coarse_size);
        for (size_t i = 0; i < coarse_size; ++i) coarse[c][i] = std::sin(0.01 * static_cast<double>(i) + c);
    }
    const GpuBuffer cg = kernels.vector(coarse_size, interleave(coarse).data());
    GpuBuffer fg = kernels.vector(fine.size());
    kernels.interpolate(p, cg, fg);
    const std::vector<float> f = fg.download<float>();
    for (int c = 0; c < 3; ++c) {
        std::vector<double> reference(fine.size());
        interpolate(fine.interpolation, coarse[c], reference);
        EXPECT_LT(max_relative_difference(f, reference, c), 1e-6) << "channel " << c;
    }
}

TEST(GpuMultires, CoarseToFineSolveMatchesTheCpu) {
    WAXWORK_REQUIRE_GL(context);
    const testing::TestSystem& s = system16();
    GpuMultiresSolver gpu(context->gl(), s.matrix, hierarchy16());
    gpu.set_right_hand_side(s.b);
    MultiresSolveOptions options;
    // Only the coarse-to-fine pass first: its start vector must already be a useful approximation.
    options.max_iterations = 0;
    gpu.solve(options);
    std::vector<float> start;
    for (const auto& v : gpu.solution())
        for (double x : v) start.push_back(static_cast<float>(x));
    options.max_iterations = 10000;
    options.relative_tolerance = 1e-5;
    const GpuMultiresReport report = gpu.solve(options);
    ASSERT_EQ(report.coarse_levels.size(), hierarchy16().level_count() - 1);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(report.coarse_levels.front()[c].status, BicgstabStatus::Converged) << "channel " << c;
        EXPECT_TRUE(report.fine[c].converged);
    }
    std::vector<float> phi;
    for (const auto& v : gpu.solution())
        for (double x : v) phi.push_back(static_cast<float>(x));
    MultiresSolver cpu(s.matrix, s.mesh.positions);
    for (int c = 0; c < 3; ++c) {
        std::vector<double> reference(s.matrix.size());
        MultiresSolveOptions tight;
        tight.relative_tolerance = 1e-9;
        cpu.solve(s.b[c], c, reference, tight);
        EXPECT_LT(max_relative_difference(phi, reference, c), 1e-4) << "channel " << c;
        EXPECT_LT(max_relative_difference(start, reference, c), 0.5) << "channel " << c;
    }
}

}  // namespace
}  // namespace waxwork

namespace waxwork {
namespace {

// Painting on the device: only the changed rows of every level are uploaded, and the solver then
// solves exactly (bit for bit) as one built afresh on the updated hierarchy.
TEST(GpuMultiresSolver, RowUpdateAfterPaintingEqualsARebuild) {
    WAXWORK_REQUIRE_GL(context);
    auto s = testing::make_test_system(8);
    HierarchyOptions h;
    h.min_coarse_vertices = 30;
    MultiresSolver cpu(s.matrix, s.mesh.positions, h);
    ASSERT_GE(cpu.hierarchy().level_count(), 3u);
    GpuMultiresSolver updated(context->gl(), s.matrix, cpu.hierarchy());
    GpuMultiresSolver stale(context->gl(), s.matrix, cpu.hierarchy());

    const std::vector<int32_t> rows = testing::paint_test_system(s, 30, 11);
    ASSERT_LT(rows.size(), s.matrix.size() / 2);
    const std::vector<std::vector<int32_t>> level_rows = cpu.update_values(s.matrix, rows);
    ASSERT_EQ(level_rows.size(), cpu.hierarchy().level_count());
    std::vector<int32_t> sorted = rows;
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    EXPECT_EQ(level_rows[0], sorted);
    size_t coarse_rows = 0;
    for (size_t l = 1; l < level_rows.size(); ++l) {
        coarse_rows += level_rows[l].size();
        EXPECT_LT(level_rows[l].size(), cpu.hierarchy().levels[l].size()) << "level " << l << ": not local";
    }
    EXPECT_GT(coarse_rows, 0u);
    updated.update_rows(s.matrix, cpu.hierarchy(), level_rows);
    GpuMultiresSolver rebuilt(context->gl(), s.matrix, cpu.hierarchy());

    MultiresSolveOptions options;
    options.relative_tolerance = 1e-5;
    std::vector<std::vector<std::array<double, 3>>> solutions;
    for (GpuMultiresSolver* solver : {&updated, &rebuilt, &stale}) {
        solver->set_right_hand_side(s.b);
        const GpuMultiresReport report = solver->solve(options);
        for (int c = 0; c < 3; ++c) EXPECT_TRUE(report.fine[c].converged);
        solutions.push_back(solver->solution());
    }
    EXPECT_EQ(solutions[0], solutions[1]);  // bit for bit
    EXPECT_NE(solutions[2], solutions[1]);  // the stale device matrix solves another system

    const std::vector<std::vector<int32_t>> bad = {{static_cast<int32_t>(s.matrix.size())}};
    EXPECT_THROW(updated.update_rows(s.matrix, cpu.hierarchy(), bad), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
