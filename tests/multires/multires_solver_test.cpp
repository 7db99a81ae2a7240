#include "base/error.h"
#include "multires/bicgstab.h"
#include "multires/multires_solver.h"
#include "multires_test_systems.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace waxwork {
namespace {

using testing::relative_error;
using testing::all_finite;

// This suite's references stop at 1e-11.
std::vector<double> reference_solution(const DiffusionMatrix& m, std::span<const double> b, int channel) {
    return testing::reference_solution(m, b, channel, 1e-11);
}

// A small non-symmetric CSR system with its diagonal slots.
struct SmallSystem {
    std::vector<int32_t> offsets{0}, columns, diagonal;
    std::vector<double> values;
    CsrMatrixView<double> view() const { return {diagonal.size(), offsets.data(), columns.data(), values.data()}; }
};

SmallSystem from_dense(const Eigen::MatrixXd& a) {
    SmallSystem s;
    for (Eigen::Index i = 0; i < a.rows(); ++i) {
        for (Eigen::Index j = 0; j < a.cols(); ++j) {
            if (a(i, j) == 0 && i != j) continue;
            if (i == j) s.diagonal.push_back(static_cast<int32_t>(s.columns.size()));
            s.columns.push_back(static_cast<int32_t>(j));
            s.values.push_back(a(i, j));
        }
        s.offsets.push_back(static_cast<int32_t>(s.columns.size()));
    }
    return s;
}

TEST(Bicgstab, SolvesANonSymmetricSystem) {
    const int n = 40;
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) {
        a(i, i) = 4 + 0.1 * i;
        if (i > 0) a(i, i - 1) = -1.5;
        if (i + 1 < n) a(i, i + 1) = -0.5;
        if (i + 7 < n) a(i, i + 7) = 0.3;
    }
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, 1, 2);
    const Eigen::VectorXd expected = a.partialPivLu().solve(b);
    const SmallSystem s = from_dense(a);
    std::vector<double> x(n, 0.0);
    std::vector<double> bv(b.data(), b.data() + n);
    const BicgstabResult r = solve_jacobi_bicgstab(s.view(), s.diagonal, bv, x, {});
    EXPECT_EQ(r.status, BicgstabStatus::Converged);
    EXPECT_LT(r.relative_residual, 1e-6);
    for (int i = 0; i < n; ++i) EXPECT_NEAR(x[static_cast<size_t>(i)], expected(i), 1e-5 * expected.cwiseAbs().maxCoeff());
}

TEST(Bicgstab, ZeroMatrixBreaksDownAndKeepsTheStartVector) {
    const SmallSystem s = from_dense(Eigen::MatrixXd::Zero(5, 5));
    std::vector<double> b(5, 1.0), x(5, 0.25);
    const BicgstabResult r = solve_jacobi_bicgstab(s.view(), s.diagonal, b, x, {});
    EXPECT_TRUE(r.failed());
    EXPECT_TRUE(r.reverted);
    for (double v : x) EXPECT_EQ(v, 0.25);
}

TEST(Bicgstab, NonFiniteMatrixIsReportedAndXStaysFinite) {
    Eigen::MatrixXd a = Eigen::MatrixXd::Identity(4, 4);
    a(2, 2) = std::numeric_limits<double>::quiet_NaN();
    const SmallSystem s = from_dense(a);
    std::vector<double> b(4, 1.0), x(4, 0.0);
    const BicgstabResult r = solve_jacobi_bicgstab(s.view(), s.diagonal, b, x, {});
    EXPECT_EQ(r.status, BicgstabStatus::NonFinite);
    EXPECT_TRUE(all_finite(x));
}

TEST(MultiresSolver, ConvergesToTheFineSolution) {
    const auto s = testing::make_test_system(14);  // 3375 vertices
    const HierarchyOptions h = testing::small_levels(100);
    MultiresSolver solver(s.matrix, s.mesh.positions, h);
    ASSERT_GE(solver.hierarchy().level_count(), 3u);
    for (int channel = 0; channel < 3; ++channel) {
        const auto reference = reference_solution(s.matrix, s.b[static_cast<size_t>(channel)], channel);
        std::vector<double> x(reference.size());
        MultiresSolveOptions options;
        // Only the coarse-to-fine pass: its start vector must already be a useful approximation.
        options.max_iterations = 0;
        MultiresSolveReport report = solver.solve(s.b[static_cast<size_t>(channel)], channel, x, options);
        EXPECT_EQ(report.fallbacks(), 0);
        const double start_error = relative_error(x, reference);
        EXPECT_LT(start_error, 0.5) << "channel " << channel;
        options.max_iterations = 10000;
        options.relative_tolerance = 1e-7;
        report = solver.solve(s.b[static_cast<size_t>(channel)], channel, x, options);
        EXPECT_TRUE(report.fine.converged);
        EXPECT_LT(relative_error(x, reference), 1e-4) << "channel " << channel;
        EXPECT_EQ(report.coarse_levels.size(), solver.hierarchy().level_count() - 1);
        EXPECT_EQ(report.coarse_levels.front().status, BicgstabStatus::Converged);
        EXPECT_EQ(report.fallback_reasons(), "");
    }
}

TEST(MultiresSolver, SingularCoarsestLevelFallsBackAndStaysFinite) {
    const auto s = testing::make_test_system(10);
    const HierarchyOptions h = testing::small_levels(100);
    MultiresSolver solver(s.matrix, s.mesh.positions, h);
    ASSERT_GE(solver.hierarchy().level_count(), 3u);
    HierarchyLevel& coarsest = solver.hierarchy().levels.back();
    for (auto& v : coarsest.values[0]) v = 0;  // a singular (zero) coarsest matrix
    const auto reference = reference_solution(s.matrix, s.b[0], 0);
    std::vector<double> x(reference.size());
    MultiresSolveOptions options;
    options.relative_tolerance = 1e-7;
    const MultiresSolveReport report = solver.solve(s.b[0], 0, x, options);
    ASSERT_FALSE(report.coarse_levels.empty());
    EXPECT_TRUE(report.coarse_levels.front().skipped);
    EXPECT_FALSE(report.coarse_levels.front().reason.empty());
    EXPECT_GE(report.fallbacks(), 1);
    // What the live editor shows: the coarsest level, named, and why it was skipped.
    const std::string reasons = report.fallback_reasons();
    EXPECT_EQ(reasons.rfind("level " + std::to_string(solver.hierarchy().level_count() - 1) + ": " +
                                report.coarse_levels.front().reason,
                            0),
              0u)
        << reasons;
    EXPECT_TRUE(all_finite(x));
    EXPECT_LT(relative_error(x, reference), 1e-4);
}

TEST(MultiresSolver, ZeroRowOnACoarseLevelStaysFinite) {
    const auto s = testing::make_test_system(10);
    const HierarchyOptions h = testing::small_levels(100);
    MultiresSolver solver(s.matrix, s.mesh.positions, h);
    ASSERT_GE(solver.hierarchy().level_count(), 3u);
    HierarchyLevel& level = solver.hierarchy().levels[1];
    // Zero the row of a lit (boundary, b != 0) vertex: the coarse system becomes inconsistent.
    std::vector<double> b1(level.size());
    restrict_right_hand_side(level, s.b[1], b1);
    size_t row = 0;
    while (row < b1.size() && b1[row] == 0) ++row;
    ASSERT_LT(row, b1.size());
    for (int32_t k = level.offsets[row]; k < level.offsets[row + 1]; ++k) level.values[1][static_cast<size_t>(k)] = 0;
    const auto reference = reference_solution(s.matrix, s.b[1], 1);
    std::vector<double> x(reference.size());
    MultiresSolveOptions options;
    options.relative_tolerance = 1e-7;
    const MultiresSolveReport report = solver.solve(s.b[1], 1, x, options);
    EXPECT_TRUE(all_finite(x));
    EXPECT_TRUE(report.fine.converged);
    EXPECT_LT(relative_error(x, reference), 1e-4);
}

TEST(MultiresSolver, FrameModeWarmStartsFromTheLastSolution) {
    const auto s = testing::make_test_system(10);
    const HierarchyOptions h = testing::small_levels(100);
    MultiresSolver solver(s.matrix, s.mesh.positions, h);
    MultiresSolveOptions options;
    options.relative_tolerance = 1e-6;
    MultiresSolveReport first, second;
    const auto reference = reference_solution(s.matrix, s.b[2], 2);
    solver.solve_frame(s.b[2], 2, 500, &first, options);
    EXPECT_FALSE(first.coarse_levels.empty());  // the first frame runs the coarse-to-fine pass
    // The light dims by 10%: the previous solution is a close start.
    std::vector<double> dimmer = s.b[2];
    for (double& v : dimmer) v *= 0.9;
    const std::span<const double> x = solver.solve_frame(dimmer, 2, 500, &second, options);
    EXPECT_TRUE(second.coarse_levels.empty());
    EXPECT_TRUE(second.fine.converged);
    std::vector<double> scaled = reference;
    for (double& v : scaled) v *= 0.9;
    EXPECT_LT(relative_error(x, scaled), 1e-4);
    // A budget of 2 iterations is respected.
    MultiresSolveReport third;
    solver.solve_frame(s.b[2], 2, 2, &third, options);
    EXPECT_LE(third.fine.iterations, 2);
}

TEST(MultiresSolver, SolveIsDeterministic) {
    const auto s = testing::make_test_system(8);
    const HierarchyOptions h = testing::small_levels(50);
    MultiresSolver a(s.matrix, s.mesh.positions, h), b(s.matrix, s.mesh.positions, h);
    std::vector<double> xa(s.b[0].size()), xb(s.b[0].size());
    a.solve(s.b[0], 0, xa);
    b.solve(s.b[0], 0, xb);
    EXPECT_EQ(xa, xb);
}


TEST(MultiresSolver, UpdateValuesEqualsARebuild) {
    auto s = testing::make_test_system(6);
    const HierarchyOptions h = testing::small_levels(30);
    MultiresSolver updated(s.matrix, s.mesh.positions, h);
    const std::vector<TetMaterial> painted(s.mesh.tet_count(), TetMaterial{{0.3, 0.02, 0.1}, {2, 1, 0.5}, 1.4});
    assemble_diffusion_values(s.matrix, s.connectivity, painted);
    updated.update_values(s.matrix);
    const MultiresSolver rebuilt(s.matrix, s.mesh.positions, h);
    ASSERT_EQ(updated.hierarchy().level_count(), rebuilt.hierarchy().level_count());
    for (size_t l = 0; l < rebuilt.hierarchy().level_count(); ++l)
        EXPECT_EQ(updated.hierarchy().levels[l].values, rebuilt.hierarchy().levels[l].values) << "level " << l;
    DiffusionMatrix other = testing::make_test_system(5).matrix;
    EXPECT_THROW(updated.update_values(other), InvalidArgumentError);
}


TEST(MultiresSolver, SingleLevelMeshSolvesWithCgAlone) {
    const auto s = testing::make_test_system(2);  // 27 vertices: below min_coarse_vertices
    MultiresSolver solver(s.matrix, s.mesh.positions);
    EXPECT_EQ(solver.hierarchy().level_count(), 1u);
    std::vector<double> x(s.b[0].size(), 123.0);  // content ignored
    MultiresSolveOptions options;
    options.relative_tolerance = 1e-8;
    const MultiresSolveReport report = solver.solve(s.b[0], 0, x, options);
    EXPECT_TRUE(report.coarse_levels.empty());
    EXPECT_TRUE(report.fine.converged);
    EXPECT_LT(relative_error(x, reference_solution(s.matrix, s.b[0], 0)), 1e-6);
    std::vector<double> wrong(3);
    EXPECT_THROW(solver.solve(wrong, 0, x), InvalidArgumentError);
    EXPECT_THROW(solver.solve(s.b[0], 3, x), InvalidArgumentError);
}


TEST(MultiresSolver, UpdateOfChangedRowsEqualsARebuild) {
    auto s = testing::make_test_system(8);
    const HierarchyOptions h = testing::small_levels(30);
    MultiresSolver updated(s.matrix, s.mesh.positions, h);
    ASSERT_GE(updated.hierarchy().level_count(), 3u);
    const std::vector<int32_t> rows = testing::paint_test_system(s, 30, 11);
    ASSERT_LT(rows.size(), s.matrix.size() / 2);
    updated.update_values(s.matrix, rows);
    const MultiresSolver rebuilt(s.matrix, s.mesh.positions, h);
    ASSERT_EQ(updated.hierarchy().level_count(), rebuilt.hierarchy().level_count());
    size_t changed_coarse = 0;
    const MultiresSolver original(testing::make_test_system(8).matrix, s.mesh.positions, h);
    for (size_t l = 0; l < rebuilt.hierarchy().level_count(); ++l) {
        EXPECT_EQ(updated.hierarchy().levels[l].values, rebuilt.hierarchy().levels[l].values) << "level " << l;
        if (l > 0 && original.hierarchy().levels[l].values != rebuilt.hierarchy().levels[l].values) ++changed_coarse;
    }
    EXPECT_GT(changed_coarse, 0u);  // the paint reached the coarse levels
    const std::vector<int32_t> bad = {static_cast<int32_t>(s.matrix.size())};
    EXPECT_THROW(updated.update_values(s.matrix, bad), InvalidArgumentError);
}


// sqrt((x - x*)^T M (x - x*)): the error norm that level-0 CG minimises and the corrected start's step
// is chosen in.
double energy_error(const DiffusionMatrix& m, int channel, std::span<const double> x, std::span<const double> exact) {
    std::vector<double> e(x.size()), me(x.size());
    for (size_t i = 0; i < x.size(); ++i) e[i] = x[i] - exact[i];
    const CsrMatrixView<double> view{m.size(), m.offsets.data(), m.columns.data(),
                                     m.values[static_cast<size_t>(channel)].data()};
    multiply<double>(view, e, me);
    double sum = 0;
    for (size_t i = 0; i < x.size(); ++i) sum += e[i] * me[i];
    return std::sqrt(sum);
}

// The start of a frame of no level-0 iterations: what set_warm_start (or the cold pass) hands level 0.
std::vector<double> frame_start(MultiresSolver& solver, std::span<const double> b, int channel,
                                 MultiresSolveReport* report = nullptr) {
    const std::span<const double> x = solver.solve_frame(b, channel, 0, report);
    return {x.begin(), x.end()};
}

TEST(MultiresSolver, CorrectedWarmStartIsCloserThanTheStartOrTheColdPass) {
    const auto s = testing::make_test_system(14);
    const HierarchyOptions h = testing::small_levels(100);
    const auto turned = testing::light_rhs(s, 0);
    const auto lit = testing::light_rhs(s, 25);  // the light turned by 25 degrees since `turned`
    for (int channel = 0; channel < 3; ++channel) {
        const auto c = static_cast<size_t>(channel);
        const auto exact = reference_solution(s.matrix, lit[c], channel);
        const auto stale = reference_solution(s.matrix, turned[c], channel);  // the last frame's solution
        MultiresSolver solver(s.matrix, s.mesh.positions, h);
        const std::vector<double> cold = frame_start(solver, lit[c], channel);
        solver.set_warm_start(channel, stale);
        MultiresSolveReport report;
        const std::vector<double> corrected = frame_start(solver, lit[c], channel, &report);
        ASSERT_TRUE(report.start_correction.has_value());
        EXPECT_GT(*report.start_correction, 0.0);
        EXPECT_EQ(report.coarse_levels.size(), solver.hierarchy().level_count() - 1);
        const double e_stale = energy_error(s.matrix, channel, stale, exact);
        const double e_cold = energy_error(s.matrix, channel, cold, exact);
        const double e_corrected = energy_error(s.matrix, channel, corrected, exact);
        EXPECT_LT(e_corrected, e_stale) << "channel " << channel;
        EXPECT_LT(e_corrected, e_cold) << "channel " << channel;
        // The next frame warm-starts from the corrected one, without another coarse pass.
        MultiresSolveReport next;
        solver.solve_frame(lit[c], channel, 5, &next);
        EXPECT_TRUE(next.coarse_levels.empty());
        EXPECT_FALSE(next.start_correction.has_value());
    }
}

TEST(MultiresSolver, CorrectedStartIsNeverWorseEvenWithBrokenCoarseLevels) {
    const auto s = testing::make_test_system(10);
    const HierarchyOptions h = testing::small_levels(100);
    MultiresSolver solver(s.matrix, s.mesh.positions, h);
    ASSERT_GE(solver.hierarchy().level_count(), 3u);
    // Level 1's matrix negated: its coarse correction points the wrong way (BiCGSTAB still converges
    // on it), so a plain x0 + e would move away from the solution.
    for (auto& v : solver.hierarchy().levels[1].values[1]) v = -v;
    const auto exact = reference_solution(s.matrix, s.b[1], 1);
    std::vector<double> start = exact;
    for (size_t i = 0; i < start.size(); ++i) start[i] *= 1.0 + 0.3 * std::sin(s.mesh.positions[i].x());
    solver.set_warm_start(1, start);
    MultiresSolveReport report;
    const std::vector<double> corrected = frame_start(solver, s.b[1], 1, &report);
    ASSERT_TRUE(report.start_correction.has_value());
    EXPECT_TRUE(all_finite(corrected));
    EXPECT_LE(energy_error(s.matrix, 1, corrected, exact), energy_error(s.matrix, 1, start, exact));
}

TEST(MultiresSolver, ZeroWarmStartIsTheColdPassAndBadStartsAreRejected) {
    const auto s = testing::make_test_system(8);
    const HierarchyOptions h = testing::small_levels(50);
    MultiresSolver a(s.matrix, s.mesh.positions, h), b(s.matrix, s.mesh.positions, h);
    const std::vector<double> zero(s.b[0].size(), 0.0);
    b.set_warm_start(0, zero);
    MultiresSolveReport ra, rb;
    const std::vector<double> xa = frame_start(a, s.b[0], 0, &ra);
    const std::vector<double> xb = frame_start(b, s.b[0], 0, &rb);
    EXPECT_EQ(xa, xb);  // bit for bit: the paper's pass, not a corrected zero
    EXPECT_FALSE(rb.start_correction.has_value());
    EXPECT_EQ(ra.coarse_levels.size(), rb.coarse_levels.size());

    EXPECT_THROW(b.set_warm_start(0, std::vector<double>(zero.size() + 1, 1.0)), InvalidArgumentError);
    std::vector<double> nan_start(zero.size(), 1.0);
    nan_start[3] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(b.set_warm_start(0, nan_start), InvalidArgumentError);
    EXPECT_THROW(b.set_warm_start(3, zero), InvalidArgumentError);
}

TEST(MultiresSolver, WithOneLevelTheWarmStartIsKeptAsItIs) {
    const auto s = testing::make_test_system(2);  // 27 vertices: below min_coarse_vertices
    MultiresSolver solver(s.matrix, s.mesh.positions);
    ASSERT_EQ(solver.hierarchy().level_count(), 1u);
    const std::vector<double> start(s.b[0].size(), 0.5);
    solver.set_warm_start(0, start);
    MultiresSolveReport report;
    EXPECT_EQ(frame_start(solver, s.b[0], 0, &report), start);  // no coarse level: nothing to correct with
    ASSERT_TRUE(report.start_correction.has_value());
    EXPECT_EQ(*report.start_correction, 0.0);
    EXPECT_TRUE(report.coarse_levels.empty());
}

}  // namespace
}  // namespace waxwork
