// The device V-cycle (multires/gpu_multigrid_preconditioner.h) against the CPU float apply_rgb, on
// llvmpipe in CI: the same operator to float rounding, and a row update after painting equal to a
// rebuild.
#include "base/error.h"
#include "multires/gpu_multigrid_preconditioner.h"
#include "multires/hierarchy.h"
#include "multires/multigrid_preconditioner.h"
#include "solver/gpu_test_context.h"
#include "multires_test_systems.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

namespace waxwork {
namespace {

using testing::small_levels;

std::vector<double> random_rgb(size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<double> r(3 * n);
    for (double& v : r) v = u(rng);
    return r;
}

// z = B r on the device for a host r (rounded to float, as apply_rgb rounds it).
std::vector<float> device_apply(GpuKernels& kernels, GpuMultigridPreconditioner& gpu, const std::vector<double>& r) {
    const std::vector<float> rf(r.begin(), r.end());
    const GpuBuffer rb = kernels.vector(rf.size() / 3, rf.data());
    GpuBuffer zb = kernels.vector(rf.size() / 3);
    gpu.apply(rb, zb);
    return zb.download<float>();
}

// max_i |z_i - reference_i| / max_i |reference_i|.
double max_relative_difference(const std::vector<float>& z, const std::vector<double>& reference) {
    double diff = 0, peak = 0;
    for (size_t i = 0; i < reference.size(); ++i) {
        diff = std::max(diff, std::abs(static_cast<double>(z[i]) - reference[i]));
        peak = std::max(peak, std::abs(reference[i]));
    }
    return diff / peak;
}

// The bound of the device/CPU comparison. Both run the same float operations in the same order (the
// kernels' sums are `precise`: no fused multiply-add), so a conforming driver gives the same bits and
// llvmpipe does. A driver that fused anyway would round each multiply-add once instead of twice: a
// relative change of at most 2^-24 per operation, which the V-cycle (a bounded linear operator:
// smoothing polynomials of norm < 1 on [upper/8, upper], exact coarse solves) carries through its
// O(levels x smoothing steps x row length) operations; 1e-5 of the largest entry leaves an order of
// magnitude over that for the test cube's conditioning. The measured difference is printed.
constexpr double kFloatRoundingBound = 1e-5;

TEST(GpuMultigridPreconditioner, VcycleEqualsTheCpuFloatApplyRgb) {
    WAXWORK_REQUIRE_GL(context);
    const auto s = testing::make_test_system(12);  // 2197 vertices
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(60));
    ASSERT_GE(h.level_count(), 3u);
    const size_t n = h.levels[0].size();
    const GLubyte* renderer = context->gl().GetString(GL_RENDERER);
    const bool llvmpipe = renderer && std::string(reinterpret_cast<const char*>(renderer)).find("llvmpipe") != std::string::npos;
    for (int steps : {1, 2, 3}) {
        MultigridOptions options;
        options.smoothing_steps = steps;
        MultigridPreconditioner cpu(h, options);
        GpuKernels kernels(context->gl(), {GpuMatrixFormat::SellCSigma});
        GpuMultigridPreconditioner gpu(kernels, cpu);
        EXPECT_EQ(gpu.level_count(), cpu.level_count());
        const std::vector<double> r = random_rgb(n, 11);
        std::vector<double> z(3 * n);
        cpu.apply_rgb(r, z);
        const std::vector<float> zg = device_apply(kernels, gpu, r);
        const double difference = max_relative_difference(zg, z);
        EXPECT_LE(difference, kFloatRoundingBound) << steps << " smoothing steps";
        size_t differing = 0;
        for (size_t i = 0; i < z.size(); ++i) differing += static_cast<double>(zg[i]) != z[i] ? 1 : 0;
        // llvmpipe (CI) runs the very same float operations: the very same bits.
        if (llvmpipe) {
            EXPECT_EQ(differing, 0u) << steps << " smoothing steps";
        }
        std::printf("[ measured ] %d smoothing steps: max relative difference %.3g, %zu of %zu entries differ\n",
                    steps, difference, differing, z.size());
    }
}

TEST(GpuMultigridPreconditioner, CsrLayoutGivesTheSameVcycle) {
    WAXWORK_REQUIRE_GL(context);
    const auto s = testing::make_test_system(8);
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(30));
    MultigridPreconditioner cpu(h);
    GpuKernels kernels(context->gl(), {GpuMatrixFormat::Csr, GpuMatrixFormat::SellCSigma});
    GpuMultigridPreconditioner csr(kernels, cpu, GpuMatrixFormat::Csr), sell(kernels, cpu);
    const std::vector<double> r = random_rgb(h.levels[0].size(), 3);
    // The same entries in the same order per row, whatever the layout: the same float result.
    EXPECT_EQ(device_apply(kernels, csr, r), device_apply(kernels, sell, r));
}

TEST(GpuMultigridPreconditioner, OneLevelIsTheExactSolve) {
    WAXWORK_REQUIRE_GL(context);
    const auto s = testing::make_test_system(3);
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions);  // too small to coarsen
    ASSERT_EQ(h.level_count(), 1u);
    MultigridPreconditioner cpu(h);
    GpuKernels kernels(context->gl(), {GpuMatrixFormat::SellCSigma});
    GpuMultigridPreconditioner gpu(kernels, cpu);
    const std::vector<double> r = random_rgb(h.levels[0].size(), 5);
    std::vector<double> z(r.size());
    cpu.apply_rgb(r, z);
    EXPECT_LE(max_relative_difference(device_apply(kernels, gpu, r), z), kFloatRoundingBound);
}

// Two checks of the row upload: with the default dropping (the kept pattern is chosen at build time and
// an update keeps it, so a rebuild could keep other entries) the device equals a fresh upload of the
// updated CPU preconditioner; with exact Galerkin products it equals a device V-cycle built on the
// painted system from scratch. Both bit for bit: the same host operators, uploaded by rows or whole.
TEST(GpuMultigridPreconditioner, RowUpdateAfterPaintingEqualsARebuild) {
    WAXWORK_REQUIRE_GL(context);
    for (double drop : {0.02, 0.0}) {
        auto s = testing::make_test_system(10);
        MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(40));
        ASSERT_GE(h.level_count(), 3u);
        MultigridOptions options;
        options.drop_tolerance = drop;
        MultigridPreconditioner updated_cpu(h, options);
        GpuKernels kernels(context->gl(), {GpuMatrixFormat::SellCSigma});
        GpuMultigridPreconditioner updated(kernels, updated_cpu);
        const std::vector<double> r = random_rgb(h.levels[0].size(), 9);
        const std::vector<float> before = device_apply(kernels, updated, r);
        const std::vector<int32_t> rows = testing::paint_test_system(s, 40, 7);
        ASSERT_LT(rows.size(), s.matrix.size() / 2);
        h.levels[0].values = s.matrix.values;
        updated.update_values(rows);
        const std::vector<float> after = device_apply(kernels, updated, r);
        EXPECT_NE(after, before) << "painting must change the preconditioner";
        MultigridPreconditioner rebuilt_cpu(h, options);
        GpuMultigridPreconditioner fresh(kernels, updated_cpu), rebuilt(kernels, rebuilt_cpu);
        EXPECT_EQ(after, device_apply(kernels, fresh, r)) << "drop " << drop;
        for (size_t l = 0; l < h.level_count(); ++l)
            EXPECT_EQ(updated.matrix(l).values.download<float>(), fresh.matrix(l).values.download<float>())
                << "level " << l << " drop " << drop;
        if (drop == 0) {
            EXPECT_EQ(after, device_apply(kernels, rebuilt, r));
        }
        EXPECT_THROW(updated.update_values(std::vector<int32_t>{static_cast<int32_t>(s.matrix.size())}),
                     InvalidArgumentError);
    }
}

TEST(GpuMultigridPreconditioner, RejectsMismatchedVectors) {
    WAXWORK_REQUIRE_GL(context);
    const auto s = testing::make_test_system(5);
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(20));
    MultigridPreconditioner cpu(h);
    GpuKernels kernels(context->gl(), {GpuMatrixFormat::SellCSigma});
    GpuMultigridPreconditioner gpu(kernels, cpu);
    const size_t n = h.levels[0].size();
    GpuBuffer r = kernels.vector(n), z = kernels.vector(n), short_z = kernels.vector(n - 1);
    EXPECT_THROW(gpu.apply(r, short_z), InvalidArgumentError);
    EXPECT_THROW(gpu.apply(r, r), InvalidArgumentError);
    EXPECT_NO_THROW(gpu.apply(r, z));
}

}  // namespace
}  // namespace waxwork
