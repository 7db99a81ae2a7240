#include "multires/hierarchy.h"
#include "multires_test_systems.h"
#include "tetops/error.h"

#include <tbb/global_control.h>

#include <Eigen/Dense>
#include <gtest/gtest.h>

namespace waxwork {
namespace {

Eigen::MatrixXd dense(const HierarchyLevel& level, int channel) {
    const auto n = static_cast<Eigen::Index>(level.size());
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n, n);
    for (Eigen::Index i = 0; i < n; ++i)
        for (int32_t k = level.offsets[static_cast<size_t>(i)]; k < level.offsets[static_cast<size_t>(i) + 1]; ++k)
            m(i, level.columns[static_cast<size_t>(k)]) += level.values[static_cast<size_t>(channel)][static_cast<size_t>(k)];
    return m;
}

// Eq. 16 rebuilt densely from the mesh graph: which level-l vertices survive is read from the coarse
// level's parent map, everything else (neighbours, weights) is recomputed here.
Eigen::MatrixXd dense_interpolation(const HierarchyLevel& fine, const HierarchyLevel& coarse,
                                    const std::vector<Eigen::Vector3d>& positions) {
    const auto nf = static_cast<Eigen::Index>(fine.size());
    const auto nc = static_cast<Eigen::Index>(coarse.size());
    std::vector<int32_t> coarse_of(fine.size(), -1);
    for (size_t c = 0; c < coarse.size(); ++c) coarse_of[static_cast<size_t>(coarse.parent_vertex[c])] = static_cast<int32_t>(c);
    Eigen::MatrixXd p = Eigen::MatrixXd::Zero(nf, nc);
    for (Eigen::Index v = 0; v < nf; ++v) {
        if (coarse_of[static_cast<size_t>(v)] >= 0) {
            p(v, coarse_of[static_cast<size_t>(v)]) = 1;
            continue;
        }
        const Eigen::Vector3d x = positions[static_cast<size_t>(fine.original_vertex[static_cast<size_t>(v)])];
        double total = 0;
        for (int32_t u : fine.graph.row(static_cast<size_t>(v))) {
            const int32_t c = coarse_of[static_cast<size_t>(u)];
            if (c < 0) continue;
            const double w = 1.0 / (positions[static_cast<size_t>(fine.original_vertex[static_cast<size_t>(u)])] - x).norm();
            p(v, c) += w;
            total += w;
        }
        EXPECT_GT(total, 0) << "dropped vertex " << v << " has no retained neighbour";
        p.row(v) /= total;
    }
    return p;
}

TEST(Hierarchy, CoarseOperatorsMatchDenseEq17) {
    const auto s = testing::make_test_system(4);  // 125 vertices
    HierarchyOptions options;
    options.min_coarse_vertices = 10;
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, options);
    ASSERT_GE(h.level_count(), 3u);
    for (size_t l = 0; l + 1 < h.level_count(); ++l) {
        const HierarchyLevel& fine = h.levels[l];
        const HierarchyLevel& coarse = h.levels[l + 1];
        const Eigen::MatrixXd p = dense_interpolation(fine, coarse, s.mesh.positions);
        // The stored operator is the same P.
        Eigen::MatrixXd stored = Eigen::MatrixXd::Zero(p.rows(), p.cols());
        for (Eigen::Index v = 0; v < p.rows(); ++v)
            for (int32_t q = fine.interpolation.offsets[static_cast<size_t>(v)]; q < fine.interpolation.offsets[static_cast<size_t>(v) + 1]; ++q)
                stored(v, fine.interpolation.columns[static_cast<size_t>(q)]) += fine.interpolation.weights[static_cast<size_t>(q)];
        EXPECT_LT((stored - p).cwiseAbs().maxCoeff(), 1e-14) << "level " << l;
        // Selection S of the retained rows; Eq. 17: M^{l+1} = S M^l P.
        Eigen::MatrixXd select = Eigen::MatrixXd::Zero(p.cols(), p.rows());
        for (size_t c = 0; c < coarse.size(); ++c) select(static_cast<Eigen::Index>(c), coarse.parent_vertex[c]) = 1;
        for (int channel = 0; channel < 3; ++channel) {
            const Eigen::MatrixXd expected = select * dense(fine, channel) * p;
            const Eigen::MatrixXd actual = dense(coarse, channel);
            const double scale = expected.cwiseAbs().maxCoeff();
            EXPECT_LT((expected - actual).cwiseAbs().maxCoeff(), 1e-12 * scale) << "level " << l + 1 << " channel " << channel;
            if (l == 0) {  // not symmetric
                EXPECT_GT((expected - expected.transpose()).cwiseAbs().maxCoeff(), 1e-6 * scale);
            }
        }
        // The right-hand side is injected: b^{l+1}_i = b^l_i.
        std::vector<double> b_coarse(coarse.size());
        restrict_right_hand_side(coarse, s.b[0], b_coarse);
        for (size_t c = 0; c < coarse.size(); ++c)
            EXPECT_EQ(b_coarse[c], s.b[0][static_cast<size_t>(coarse.original_vertex[c])]);
    }
}

TEST(Hierarchy, StopsAtTheSizeRuleAndShrinks) {
    const auto s = testing::make_test_system(12);  // 2197 vertices
    HierarchyOptions options;
    options.min_coarse_vertices = 200;
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh.positions, options);
    ASSERT_GE(h.level_count(), 2u);
    for (size_t l = 1; l < h.level_count(); ++l) {
        EXPECT_LE(static_cast<double>(h.levels[l].size()), options.max_keep_ratio * static_cast<double>(h.levels[l - 1].size()));
        EXPECT_GE(static_cast<int64_t>(h.levels[l - 1].size()), options.min_coarse_vertices);
    }
    EXPECT_TRUE(h.levels.back().interpolation.columns.empty());
}

TEST(Hierarchy, DeterministicAcrossRunsAndThreadCounts) {
    const auto s = testing::make_test_system(10);
    HierarchyOptions options;
    options.min_coarse_vertices = 50;
    const MultiresHierarchy a = build_multires_hierarchy(s.matrix, s.mesh.positions, options);
    MultiresHierarchy b;
    {
        tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
        b = build_multires_hierarchy(s.matrix, s.mesh.positions, options);
    }
    ASSERT_EQ(a.level_count(), b.level_count());
    for (size_t l = 0; l < a.level_count(); ++l) {
        EXPECT_EQ(a.levels[l].original_vertex, b.levels[l].original_vertex);
        EXPECT_EQ(a.levels[l].graph.indices, b.levels[l].graph.indices);
        EXPECT_EQ(a.levels[l].columns, b.levels[l].columns);
        EXPECT_EQ(a.levels[l].values, b.levels[l].values);
        EXPECT_EQ(a.levels[l].interpolation.weights, b.levels[l].interpolation.weights);
    }
}

// The selection-only build (for views) keeps the same vertices on every level as the full build, for
// several stopping rules (size floor, level cap, keep ratio).
TEST(Hierarchy, LevelVerticesWithoutOperatorsEqualTheFullBuild) {
    const auto s = testing::make_test_system(9);
    std::vector<HierarchyOptions> variants(4);
    variants[0].min_coarse_vertices = 30;
    variants[1].min_coarse_vertices = 300;
    variants[2].min_coarse_vertices = 30;
    variants[2].max_levels = 3;
    variants[3].min_coarse_vertices = 30;
    variants[3].max_keep_ratio = 0.3;  // stops where a level keeps more than 30%
    variants[3].seed = 7;
    for (const HierarchyOptions& options : variants) {
        const MultiresHierarchy full = build_multires_hierarchy(s.matrix, s.mesh.positions, options);
        const std::vector<std::vector<int32_t>> levels = hierarchy_level_vertices(s.connectivity.vertex_vertices, options);
        ASSERT_EQ(levels.size() + 1, full.level_count());
        for (size_t l = 0; l < levels.size(); ++l) EXPECT_EQ(levels[l], full.levels[l + 1].original_vertex) << "level " << l + 1;
    }
    EXPECT_GE(build_multires_hierarchy(s.matrix, s.mesh.positions, variants[0]).level_count(), 3u);
}

TEST(Hierarchy, RejectsMismatchedPositions) {
    const auto s = testing::make_test_system(2);
    std::vector<Eigen::Vector3d> too_few(3);
    EXPECT_THROW(build_multires_hierarchy(s.matrix, too_few), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
