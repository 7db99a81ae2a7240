#include "base/error.h"
#include "multires/multigrid_cg.h"
#include "multires/multigrid_preconditioner.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "solver/reference/reference_solvers.h"
#include "tetops/box_mesh.h"
#include "tetops/cut.h"
#include "tetops/relaxation.h"
#include "tetops/sliver_maker.h"
#include "multires_test_systems.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>

namespace waxwork {
namespace {

using testing::small_levels;

using testing::reference_solution;
using testing::relative_error;
using testing::dense;

std::vector<double> random_vector(size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<double> v(n);
    for (double& x : v) x = u(rng);
    return v;
}

double dot(const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
    return s;
}

TEST(MultigridPreconditioner, CoarseOperatorsAreGalerkinProducts) {
    const auto s = testing::make_test_system(6);
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(20));
    ASSERT_GE(h.level_count(), 3u);
    MultigridOptions exact;
    exact.drop_tolerance = 0;
    const MultigridPreconditioner mg(h, exact);
    ASSERT_EQ(mg.level_count(), h.level_count());
    for (int channel = 0; channel < 3; ++channel) {
        for (size_t l = 0; l + 1 < h.level_count(); ++l) {
            const Eigen::MatrixXd p = dense(h.levels[l].interpolation, static_cast<Eigen::Index>(h.levels[l + 1].size()));
            const Eigen::MatrixXd expected = p.transpose() * dense(mg.view(l, channel)) * p;
            const Eigen::MatrixXd actual = dense(mg.view(l + 1, channel));
            EXPECT_LT((actual - expected).norm(), 1e-12 * expected.norm()) << "level " << l + 1;
            EXPECT_LT((actual - actual.transpose()).norm(), 1e-12 * actual.norm());
        }
    }
}

// B assembled column by column from apply(): symmetric to rounding and positive definite.
void expect_symmetric_positive(bool single_precision, double symmetry_tolerance, double drop_tolerance,
                               DropLumping lumping) {
    const auto s = testing::make_test_system(5);  // 216 vertices
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(20));
    ASSERT_GE(h.level_count(), 3u);
    MultigridOptions options;
    options.single_precision = single_precision;
    options.drop_tolerance = drop_tolerance;
    options.lumping = lumping;
    MultigridPreconditioner mg(h, options);
    const size_t n = h.levels[0].size();
    for (int channel = 0; channel < 3; ++channel) {
        Eigen::MatrixXd b(n, n);
        std::vector<double> e(n, 0.0), z(n);
        for (size_t j = 0; j < n; ++j) {
            e[j] = 1;
            mg.apply(channel, e, z);
            e[j] = 0;
            for (size_t i = 0; i < n; ++i) b(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = z[i];
        }
        EXPECT_LT((b - b.transpose()).norm(), symmetry_tolerance * b.norm()) << "channel " << channel;
        const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (b + b.transpose()));
        EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0) << "channel " << channel;
        // x^T B y == y^T B x for random vectors.
        const auto x = random_vector(n, 1), y = random_vector(n, 2);
        std::vector<double> bx(n), by(n);
        mg.apply(channel, x, bx);
        mg.apply(channel, y, by);
        EXPECT_NEAR(dot(x, by), dot(y, bx), symmetry_tolerance * std::sqrt(dot(bx, bx) * dot(y, y)));
    }
}

TEST(MultigridPreconditioner, ExactGalerkinIsSymmetricPositiveDefiniteInDouble) {
    expect_symmetric_positive(false, 1e-12, 0.0, DropLumping::RowSum);
}
TEST(MultigridPreconditioner, DefaultIsSymmetricPositiveDefiniteInDouble) {
    const MultigridOptions defaults;
    expect_symmetric_positive(false, 1e-12, defaults.drop_tolerance, defaults.lumping);
}
TEST(MultigridPreconditioner, AbsoluteLumpingIsSymmetricPositiveDefinite) {
    expect_symmetric_positive(false, 1e-12, 0.1, DropLumping::Absolute);
}
TEST(MultigridPreconditioner, DefaultIsSymmetricToFloatRoundingInSingle) {
    const MultigridOptions defaults;
    expect_symmetric_positive(true, 1e-5, defaults.drop_tolerance, defaults.lumping);
}

// Slivers (testing::make_sliver_system): the row-sum lumped coarse operators lose definiteness, so the
// setup is redone with absolute lumping, and MG-CG still converges to the direct solution.
TEST(MultigridPreconditioner, SliversFallBackToAbsoluteLumpingAndStillConverge) {
    const testing::SliverSystem s = testing::make_sliver_system();
    const DiffusionMatrix& matrix = s.matrix;
    const std::vector<double>& b = s.b;
    const MultiresHierarchy& h = s.hierarchy;
    ASSERT_GE(h.level_count(), 2u);

    MultigridOptions strict;
    strict.fall_back_to_absolute = false;
    EXPECT_THROW(MultigridPreconditioner(h, strict), AlgorithmError);

    MultigridPreconditioner mg(h);
    EXPECT_EQ(mg.lumping(), DropLumping::Absolute);
    EXPECT_NE(mg.lumping_fallback_reason().find("not positive"), std::string::npos) << mg.lumping_fallback_reason();
    const Eigen::VectorXd exact =
        refined_direct_solution(to_eigen_sparse(matrix, 0), Eigen::Map<const Eigen::VectorXd>(b.data(), static_cast<Eigen::Index>(b.size())));
    std::vector<double> x(b.size(), 0.0);
    ConjugateGradientOptions cg;
    cg.relative_tolerance = 1e-9;
    cg.max_iterations = 2000;
    EXPECT_TRUE(solve_multigrid_cg(mg, 0, b, x, cg).converged);
    EXPECT_LT(relative_error(x, std::vector<double>(exact.data(), exact.data() + exact.size())), 1e-6);
}

TEST(MultigridCg, ConvergesToTheLevel0Solution) {
    const auto s = testing::make_test_system(12);  // 2197 vertices
    for (const InterpolationWeights weights : {InterpolationWeights::InverseEdgeLength, InterpolationWeights::LinearExact})
    for (bool single : {true, false}) {
        HierarchyOptions hierarchy_options = small_levels(100);
        hierarchy_options.weights = weights;
        const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, hierarchy_options);
        ASSERT_GE(h.level_count(), 3u);
        MultigridOptions options;
        options.single_precision = single;
        MultigridPreconditioner mg(h, options);
        EXPECT_EQ(mg.lumping(), DropLumping::RowSum);  // no fallback on a well-shaped mesh
        EXPECT_EQ(mg.lumping_fallback_reason(), "");
        for (int channel = 0; channel < 3; ++channel) {
            const auto& b = s.b[static_cast<size_t>(channel)];
            const auto reference = reference_solution(s.matrix, b, channel);
            std::vector<double> x(b.size(), 0.0);
            ConjugateGradientOptions cg;
            cg.relative_tolerance = 1e-9;
            const ConjugateGradientResult result = solve_multigrid_cg(mg, channel, b, x, cg);
            EXPECT_TRUE(result.converged);
            EXPECT_LT(relative_error(x, reference), 1e-7)
                << "channel " << channel << " single " << single << " linear-exact " << (weights == InterpolationWeights::LinearExact);
            EXPECT_GT(result.smallest_eigenvalue_estimate, 0.0);
        }
    }
}

TEST(MultigridCg, NeedsFarFewerIterationsThanJacobiCg) {
    const auto s = testing::make_test_system(16);  // 4913 vertices
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(100));
    MultigridPreconditioner mg(h);
    const auto& b = s.b[0];  // the weakest absorption: the slowest channel
    const CsrMatrixView<double> view{s.matrix.size(), s.matrix.offsets.data(), s.matrix.columns.data(),
                                     s.matrix.values[0].data()};
    const auto reference = reference_solution(s.matrix, b, 0);
    ConjugateGradientOptions options;
    options.relative_tolerance = 1e-6;
    std::vector<double> xj(b.size(), 0.0), xm(b.size(), 0.0);
    const int jacobi = solve_jacobi_cg<double>(view, b, xj, options).iterations;
    const ConjugateGradientResult mgcg = solve_multigrid_cg(mg, 0, b, xm, options);
    EXPECT_TRUE(mgcg.converged);
    EXPECT_LT(relative_error(xm, reference), 1e-5);
    EXPECT_LT(4 * mgcg.iterations, jacobi) << "MG-CG " << mgcg.iterations << ", Jacobi CG " << jacobi;
}

TEST(MultigridCg, IsDeterministicAcrossThreadCounts) {
    const auto s = testing::make_test_system(10);
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(50));
    std::vector<double> xa(s.b[1].size(), 0.0), xb(s.b[1].size(), 0.0);
    {
        MultigridPreconditioner mg(h);
        solve_multigrid_cg(mg, 1, s.b[1], xa);
    }
    {
        const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
        MultigridPreconditioner mg(h);
        solve_multigrid_cg(mg, 1, s.b[1], xb);
    }
    EXPECT_EQ(xa, xb);
}

TEST(MultigridCg, WarmStartFromTheSolutionStopsAtOnce) {
    const auto s = testing::make_test_system(10);
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(50));
    MultigridPreconditioner mg(h);
    std::vector<double> x(s.b[2].size(), 0.0);
    ConjugateGradientOptions options;
    options.relative_tolerance = 1e-8;
    const ConjugateGradientResult first = solve_multigrid_cg(mg, 2, s.b[2], x, options);
    options.relative_tolerance = 1e-6;
    options.smallest_eigenvalue_hint = first.smallest_eigenvalue_estimate;
    const ConjugateGradientResult again = solve_multigrid_cg(mg, 2, s.b[2], x, options);
    EXPECT_TRUE(again.converged);
    EXPECT_EQ(again.iterations, 0);
}

TEST(MultigridCg, RejectsBadInput) {
    const auto s = testing::make_test_system(4);
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(20));
    MultigridPreconditioner mg(h);
    std::vector<double> x(s.b[0].size(), 0.0), wrong(3);
    EXPECT_THROW(solve_multigrid_cg(mg, 3, s.b[0], x), InvalidArgumentError);
    EXPECT_THROW(solve_multigrid_cg(mg, 0, wrong, x), InvalidArgumentError);
    std::vector<double> nan_b = s.b[0];
    nan_b[0] = std::nan("");
    EXPECT_THROW(solve_multigrid_cg(mg, 0, nan_b, x), AlgorithmError);
    std::vector<double> zero(s.b[0].size(), 0.0);
    x.assign(x.size(), 1.0);
    EXPECT_TRUE(solve_multigrid_cg(mg, 0, zero, x).converged);
    for (double v : x) EXPECT_EQ(v, 0.0);
}

TEST(MultigridPreconditioner, PartialUpdateAfterPaintingEqualsARebuild) {
    auto s = testing::make_test_system(8);
    MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(30));
    ASSERT_GE(h.level_count(), 3u);
    // Exact products: with dropping, the kept pattern is chosen at build time and an update keeps it.
    MultigridOptions exact;
    exact.drop_tolerance = 0;
    MultigridPreconditioner updated(h, exact);
    const std::vector<int32_t> rows = testing::paint_test_system(s, 40, 7);
    ASSERT_LT(rows.size(), s.matrix.size() / 2);
    h.levels[0].values = s.matrix.values;
    updated.update_values(rows);
    MultigridPreconditioner rebuilt(h, exact);
    for (size_t l = 0; l < h.level_count(); ++l)
        for (int channel = 0; channel < 3; ++channel) {
            const auto a = updated.view(l, channel), b = rebuilt.view(l, channel);
            ASSERT_EQ(a.rows, b.rows);
            const size_t nnz = static_cast<size_t>(a.offsets[a.rows]);
            EXPECT_TRUE(std::equal(a.values, a.values + nnz, b.values)) << "level " << l << " channel " << channel;
        }
    std::vector<double> xa(s.b[0].size(), 0.0), xb(s.b[0].size(), 0.0);
    updated.apply(0, s.b[0], xa);
    rebuilt.apply(0, s.b[0], xb);
    EXPECT_EQ(xa, xb);
}

// Every level's operator of `a` equals `b`'s bit for bit: pattern, diagonal positions and values.
void expect_same_operators(const MultigridPreconditioner& a, const MultigridPreconditioner& b, const std::string& what) {
    ASSERT_EQ(a.level_count(), b.level_count()) << what;
    for (size_t l = 0; l < a.level_count(); ++l) {
        EXPECT_TRUE(std::ranges::equal(a.diagonal(l), b.diagonal(l))) << what << ", level " << l;
        for (int channel = 0; channel < 3; ++channel) {
            const auto x = a.view(l, channel), y = b.view(l, channel);
            ASSERT_EQ(x.rows, y.rows) << what;
            const auto nnz = static_cast<size_t>(x.offsets[x.rows]);
            ASSERT_TRUE(std::equal(x.offsets, x.offsets + x.rows + 1, y.offsets)) << what << ", level " << l;
            EXPECT_TRUE(std::equal(x.columns, x.columns + nnz, y.columns)) << what << ", level " << l;
            EXPECT_TRUE(std::equal(x.values, x.values + nnz, y.values)) << what << ", level " << l << " channel " << channel;
        }
    }
}

// After a cut with relaxation, the preconditioner rebuilt from the uncut one copies the rows of A P
// and of the Galerkin operators away from the cut and equals a fresh build on the rebuilt hierarchy
// bit for bit, with either lumping and with exact products. Rebuilt once more after a relaxation
// alone (the identity map, moved vertices) it still does. From a build with other options it copies
// nothing and still equals the fresh build.
TEST(MultigridPreconditioner, RebuiltAfterACutEqualsAFreshBuild) {
    const auto s = testing::make_test_system(14);  // 3375 vertices
    const HierarchyOptions levels = small_levels(30);
    const MultiresHierarchy before = build_multires_hierarchy(s.matrix, s.mesh.positions, levels);
    const testing::CutSystem cut = testing::cut_system(s.mesh, Eigen::Vector3d(1, 0.2, 0.1), 2.7, 3);
    const MultiresHierarchy after = rebuild_multires_hierarchy(before, cut.new_of_old, cut.matrix, cut.mesh.positions, levels);
    ASSERT_GE(after.level_count(), 3u);
    // The cut volume relaxed once more towards the same plane: same graph, moved vertices.
    TetMesh relaxed = cut.mesh;
    RelaxationOptions relax;
    relax.max_iterations = 3;
    relax.step = 0.3;
    ASSERT_GT(relax_cut_vertices(relaxed, cut.connectivity, PlaneCut(Eigen::Vector3d(1, 0.2, 0.1), 2.7), relax).vertices_moved, 0u);
    const std::vector<TetMaterial> materials(relaxed.tet_count(), testing::test_material());
    const DiffusionMatrix relaxed_matrix = assemble_diffusion_matrix(relaxed, cut.connectivity, materials);
    std::vector<int32_t> identity(relaxed.vertex_count());
    std::iota(identity.begin(), identity.end(), 0);
    const MultiresHierarchy again = rebuild_multires_hierarchy(after, identity, relaxed_matrix, relaxed.positions, levels);

    MultigridOptions absolute;
    absolute.lumping = DropLumping::Absolute;
    absolute.drop_tolerance = 0.05;
    MultigridOptions exact;
    exact.drop_tolerance = 0;
    for (const MultigridOptions& options : {MultigridOptions{}, absolute, exact}) {
        const std::string what = "drop " + std::to_string(options.drop_tolerance) +
                                 (options.lumping == DropLumping::Absolute ? " absolute" : " row sum");
        const MultigridPreconditioner uncut(before, options);
        MultigridPreconditioner rebuilt(after, uncut, cut.new_of_old, options);
        MultigridPreconditioner fresh(after, options);
        expect_same_operators(rebuilt, fresh, what);
        // Most fine rows lie away from the cut; the rows next to it are computed. A Galerkin row reaches
        // three fine hops, so on this small cube fewer of level 1's rows escape the cut (101 of 744).
        const size_t n = after.levels[0].size();
        EXPECT_GT(rebuilt.copied_product_rows(0), n / 2) << what;
        EXPECT_LT(rebuilt.copied_product_rows(0), n) << what;
        EXPECT_GT(rebuilt.copied_operator_rows(1), 0u) << what;
        EXPECT_LT(rebuilt.copied_operator_rows(1), after.levels[1].size()) << what;
        EXPECT_EQ(fresh.copied_product_rows(0), 0u);
        std::vector<double> xa(n, 0.0), xb(n, 0.0);
        const std::vector<double> r = random_vector(n, 3);
        rebuilt.apply(1, r, xa);
        fresh.apply(1, r, xb);
        EXPECT_EQ(xa, xb) << what;

        const MultigridPreconditioner moved(again, rebuilt, identity, options);
        expect_same_operators(moved, MultigridPreconditioner(again, options), what + ", relaxed");
        EXPECT_GT(moved.copied_product_rows(0), n / 2) << what;
        EXPECT_LT(moved.copied_product_rows(0), n) << what;

        MultigridOptions other = options;
        other.smoothing_steps = 3;
        const MultigridPreconditioner unrelated(after, MultigridPreconditioner(before, other), cut.new_of_old, options);
        expect_same_operators(unrelated, fresh, what + ", from other options");
        for (size_t l = 0; l < after.level_count(); ++l) {
            EXPECT_EQ(unrelated.copied_product_rows(l) + unrelated.copied_operator_rows(l), 0u) << what;
        }
    }
    const std::vector<int32_t> too_short(3, 0);
    const MultigridPreconditioner uncut(before);
    EXPECT_THROW(MultigridPreconditioner(after, uncut, too_short), InvalidArgumentError);
}

// Painting updates a preconditioner's rows on the kept pattern of its build (update_values), which a
// fresh build on the painted values might not choose: a rebuild after painting and a cut copies none
// of those rows and still equals a fresh build.
TEST(MultigridPreconditioner, RebuiltAfterPaintingAndACutEqualsAFreshBuild) {
    auto s = testing::make_test_system(14);
    const HierarchyOptions levels = small_levels(30);
    MultiresHierarchy before = build_multires_hierarchy(s.matrix, s.mesh.positions, levels);
    MultigridOptions options;
    options.drop_tolerance = 0.05;  // drops on every coarse level, so painting can move the pattern
    MultigridPreconditioner painted(before, options);
    const std::vector<int32_t> rows = testing::paint_test_system(s, 300, 7);
    before.levels[0].values = s.matrix.values;
    painted.update_values(rows);
    // The painted materials, cut.
    testing::CutSystem cut = testing::cut_system(s.mesh, Eigen::Vector3d(1, 0.2, 0.1), 2.7);
    std::vector<TetMaterial> materials(s.mesh.tet_count(), testing::test_material());
    for (size_t t = 0; t < 300; ++t) materials[7 * t] = TetMaterial{{0.3, 0.02, 0.1}, {2, 1, 0.5}, 1.4};  // as painted
    TetMesh cut_mesh = s.mesh;
    cut_mesh.materials = materials;
    remove_cut_away_tets(cut_mesh, PlaneCut(Eigen::Vector3d(1, 0.2, 0.1), 2.7));
    cut.matrix = assemble_diffusion_matrix(cut_mesh, cut.connectivity, cut_mesh.materials);
    const MultiresHierarchy after = rebuild_multires_hierarchy(before, cut.new_of_old, cut.matrix, cut.mesh.positions, levels);
    const MultigridPreconditioner rebuilt(after, painted, cut.new_of_old, options);
    expect_same_operators(rebuilt, MultigridPreconditioner(after, options), "painted, then cut");
    EXPECT_GT(rebuilt.copied_product_rows(0), 0u);
}

// The build fills the Galerkin values in the pass that chooses the kept pattern (and takes the drop
// test's diagonals from single columns); recomputing every row the way an update does must give the
// same operators bit for bit, for both lumpings.
TEST(MultigridPreconditioner, BuildEqualsARowByRowRecomputation) {
    const auto s = testing::make_test_system(8);
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(30));
    ASSERT_GE(h.level_count(), 3u);
    std::vector<int32_t> all(s.matrix.size());
    std::iota(all.begin(), all.end(), 0);
    MultigridOptions exact_options;
    exact_options.drop_tolerance = 0;
    const MultigridPreconditioner exact(h, exact_options);
    for (const DropLumping lumping : {DropLumping::RowSum, DropLumping::Absolute}) {
        MultigridOptions options;
        options.lumping = lumping;
        options.drop_tolerance = 0.05;  // drops entries on every coarse level of this small system
        const MultigridPreconditioner built(h, options);
        MultigridPreconditioner recomputed(h, options);
        recomputed.update_values(all);
        size_t dropped_levels = 0;
        for (size_t l = 1; l < h.level_count(); ++l) {
            dropped_levels += built.nonzeros(l) < exact.nonzeros(l) ? 1 : 0;
            for (int channel = 0; channel < 3; ++channel) {
                const auto a = built.view(l, channel), b = recomputed.view(l, channel);
                ASSERT_EQ(a.rows, b.rows);
                const auto nnz = static_cast<size_t>(a.offsets[a.rows]);
                EXPECT_TRUE(std::equal(a.offsets, a.offsets + a.rows + 1, b.offsets));
                EXPECT_TRUE(std::equal(a.columns, a.columns + nnz, b.columns));
                EXPECT_TRUE(std::equal(a.values, a.values + nnz, b.values)) << "level " << l << " channel " << channel;
            }
        }
        EXPECT_GT(dropped_levels, 0u);
    }
}

// A system too small to coarsen is one level, solved exactly by its factorisation: painting must
// refactorise it, so the V-cycle stays the exact inverse of the painted matrix.
TEST(MultigridPreconditioner, PartialUpdateOfAOneLevelHierarchyRefactorisesIt) {
    auto s = testing::make_test_system(3);
    MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(100000));
    ASSERT_EQ(h.level_count(), 1u);
    MultigridPreconditioner updated(h);
    const std::vector<int32_t> rows = testing::paint_test_system(s, 10, 5);
    ASSERT_FALSE(rows.empty());
    ASSERT_LT(rows.size(), s.matrix.size());
    h.levels[0].values = s.matrix.values;
    updated.update_values(rows);
    MultigridPreconditioner rebuilt(h);
    for (int channel = 0; channel < 3; ++channel) {
        std::vector<double> xa(s.b[0].size(), 0.0), xb(s.b[0].size(), 0.0);
        updated.apply(channel, s.b[static_cast<size_t>(channel)], xa);
        rebuilt.apply(channel, s.b[static_cast<size_t>(channel)], xb);
        EXPECT_EQ(xa, xb) << "channel " << channel;
        // The exact solve of the painted system.
        EXPECT_LT(relative_error(xa, reference_solution(s.matrix, s.b[static_cast<size_t>(channel)], channel)), 1e-6)
            << "channel " << channel;
    }
}

}  // namespace
}  // namespace waxwork

namespace waxwork {
namespace {

// Per-frame relighting: after the light turns by 10 degrees, MG-CG warm-started from the previous
// light's solution and stopped on its own estimate at 1e-2 is within 1% of the new solution in a few
// iterations (bench/multires_bench.cpp, BM_LightTurn10Degrees, times it on spot).
TEST(MultigridCg, LightTurnOfTenDegreesConvergesWithinAFewWarmIterations) {
    const auto s = testing::make_test_system(12);
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, small_levels(100));
    MultigridPreconditioner mg(h);
    const auto lit_before = testing::light_rhs(s, 0), lit_after = testing::light_rhs(s, 10);
    for (int channel = 0; channel < 3; ++channel) {
        const auto& before = lit_before[static_cast<size_t>(channel)];
        const auto& after = lit_after[static_cast<size_t>(channel)];
        std::vector<double> x(before.size(), 0.0);
        ConjugateGradientOptions tight;
        tight.relative_tolerance = 1e-8;
        const ConjugateGradientResult previous = solve_multigrid_cg(mg, channel, before, x, tight);
        const auto reference = reference_solution(s.matrix, after, channel);
        ASSERT_GT(relative_error(x, reference), 1e-2) << "the turn must change the solution";
        ConjugateGradientOptions frame;
        frame.relative_tolerance = 1e-2;
        frame.smallest_eigenvalue_hint = previous.smallest_eigenvalue_estimate;
        const ConjugateGradientResult warm = solve_multigrid_cg(mg, channel, after, x, frame);
        EXPECT_TRUE(warm.converged);
        EXPECT_LE(warm.iterations, 4) << "channel " << channel;
        EXPECT_LT(relative_error(x, reference), 1e-2) << "channel " << channel;
    }
}

}  // namespace
}  // namespace waxwork
