// Volumetric painting (TransCut Sec. 5): Gaussian weights from the nearest stroke point, compared with
// a brute-force evaluation over every tet and every stroke point.
#include "base/error.h"
#include "tetops/cut.h"
#include "tetops/paint.h"
#include "tetops/test_meshes.h"
#include "tetops/tet_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>

namespace waxwork {
namespace {

using testing::make_cube_mesh;

TetMaterial base_material() {
    TetMaterial m;
    m.mua = {0.002, 0.003, 0.004};
    m.musp = {2.0, 2.5, 3.0};
    m.eta = 1.4;
    return m;
}

PaintBrush red_brush(double sigma) {
    PaintBrush brush;
    brush.material.mua = {0.5, 0.01, 0.01};
    brush.material.musp = {1.0, 1.0, 1.0};
    brush.material.eta = 1.3;
    brush.sigma = sigma;
    return brush;
}

TetMaterial blend(const TetMaterial& a, const TetMaterial& b, double w) {
    TetMaterial m;
    for (int c = 0; c < 3; ++c) {
        m.mua[c] = (1 - w) * a.mua[c] + w * b.mua[c];
        m.musp[c] = (1 - w) * a.musp[c] + w * b.musp[c];
    }
    m.eta = (1 - w) * a.eta + w * b.eta;
    return m;
}

void expect_material_near(const TetMaterial& a, const TetMaterial& b, double tolerance) {
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(a.mua[c], b.mua[c], tolerance);
        EXPECT_NEAR(a.musp[c], b.musp[c], tolerance);
    }
    EXPECT_NEAR(a.eta, b.eta, tolerance);
}

// Brute force: the weight of every tet from its world-space centroid and every stroke point.
std::vector<double> brute_force_weights(const TetMesh& mesh, const std::vector<Eigen::Vector3d>& stroke, double sigma) {
    std::vector<double> weights(mesh.tet_count());
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (int32_t v : mesh.tets[t]) c += mesh.positions[v];
        c /= 4;
        const RigidTransform& m = mesh.piece_transforms[mesh.piece_ids[t]];
        c = m.rotation * c + m.translation;
        double nearest = std::numeric_limits<double>::infinity();
        for (const Eigen::Vector3d& p : stroke) nearest = std::min(nearest, (c - p).squaredNorm());
        weights[t] = std::exp(-nearest / (2 * sigma * sigma));
    }
    return weights;
}

TEST(Paint, ChangesExactlyTheTetsWithinTheCutoffWithGaussianWeights) {
    TetMesh mesh = make_cube_mesh(10);
    mesh.materials.assign(mesh.tet_count(), base_material());
    const TetMesh before = mesh;
    const std::vector<Eigen::Vector3d> stroke = {{0.3, 0.3, 0.5}, {0.35, 0.32, 0.5}, {0.4, 0.36, 0.52}};
    const PaintBrush brush = red_brush(0.05);
    const PaintResult result = paint_stroke(mesh, stroke, brush);

    const std::vector<double> expected = brute_force_weights(before, stroke, brush.sigma);
    std::vector<int32_t> expected_changed;
    for (size_t t = 0; t < expected.size(); ++t)
        if (expected[t] >= brush.cutoff_weight) expected_changed.push_back(static_cast<int32_t>(t));
    ASSERT_FALSE(expected_changed.empty());
    ASSERT_LT(expected_changed.size(), before.tet_count());  // a local brush
    EXPECT_EQ(result.changed_tets, expected_changed);
    ASSERT_EQ(result.weights.size(), result.changed_tets.size());
    std::vector<bool> changed(mesh.tet_count(), false);
    for (size_t i = 0; i < result.changed_tets.size(); ++i) {
        const int32_t t = result.changed_tets[i];
        changed[t] = true;
        EXPECT_NEAR(result.weights[i], expected[t], 1e-12);
        expect_material_near(mesh.materials[t], blend(base_material(), brush.material, expected[t]), 1e-12);
    }
    for (size_t t = 0; t < mesh.tet_count(); ++t)
        if (!changed[t]) { EXPECT_EQ(mesh.materials[t], base_material()) << "tet " << t << " touched"; }
    EXPECT_EQ(mesh.tets, before.tets);
    EXPECT_EQ(mesh.positions, before.positions);
}

TEST(Paint, UsesWorldSpaceCentroidsOfMovedPieces) {
    TetMesh mesh = make_cube_mesh(6);
    mesh.piece_transforms[0].rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
    mesh.piece_transforms[0].translation = Eigen::Vector3d(5, -2, 1);
    const TetMesh before = mesh;
    const std::vector<Eigen::Vector3d> stroke = {mesh.piece_transforms[0].rotation * Eigen::Vector3d(0.5, 0.5, 0.5) +
                                                 mesh.piece_transforms[0].translation};
    const PaintResult result = paint_stroke(mesh, stroke, red_brush(0.08), base_material());
    const std::vector<double> expected = brute_force_weights(before, stroke, 0.08);
    size_t expected_count = 0;
    for (double w : expected) expected_count += w >= 1e-3;
    EXPECT_GT(expected_count, 0u);
    EXPECT_EQ(result.changed_tets.size(), expected_count);
    for (size_t i = 0; i < result.changed_tets.size(); ++i)
        EXPECT_NEAR(result.weights[i], expected[result.changed_tets[i]], 1e-12);
}

TEST(Paint, RepeatedStrokesConvergeTowardTheBrush) {
    TetMesh mesh = make_cube_mesh(6);
    const std::vector<Eigen::Vector3d> stroke = {{0.5, 0.5, 0.5}};
    const PaintBrush brush = red_brush(0.1);
    const PaintIndex index(mesh);
    PaintResult first = paint_stroke(mesh, index, stroke, brush, base_material());
    ASSERT_FALSE(first.changed_tets.empty());
    for (int stroke_count = 2; stroke_count <= 4; ++stroke_count) {
        const PaintResult again = paint_stroke(mesh, index, stroke, brush);
        EXPECT_EQ(again.changed_tets, first.changed_tets);
        for (size_t i = 0; i < again.changed_tets.size(); ++i) {
            // After k strokes the remaining difference to the brush is (1 - w)^k of the initial one.
            const double remaining = std::pow(1 - again.weights[i], stroke_count);
            expect_material_near(mesh.materials[again.changed_tets[i]],
                                 blend(brush.material, base_material(), remaining), 1e-12);
        }
    }
    // Many more strokes: the tet nearest the stroke point becomes pure brush.
    for (int i = 0; i < 30; ++i) paint_stroke(mesh, index, stroke, brush);
    const auto best = std::max_element(first.weights.begin(), first.weights.end()) - first.weights.begin();
    expect_material_near(mesh.materials[first.changed_tets[best]], brush.material, 1e-6);
}

TEST(Paint, PaintSurvivesACutOnTheSameOriginalTets) {
    TetMesh mesh = make_cube_mesh(8);
    paint_stroke(mesh, std::vector<Eigen::Vector3d>{{0.2, 0.5, 0.5}, {0.8, 0.5, 0.5}}, red_brush(0.1), base_material());
    std::map<int32_t, TetMaterial> painted;
    for (size_t t = 0; t < mesh.tet_count(); ++t) painted[mesh.original_ids[t]] = mesh.materials[t];
    remove_cut_away_tets(mesh, PlaneCut(Eigen::Vector3d(1, 0, 0), 0.5));
    ASSERT_GT(mesh.tet_count(), 0u);
    size_t still_painted = 0;
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        EXPECT_EQ(mesh.materials[t], painted.at(mesh.original_ids[t]));
        still_painted += !(mesh.materials[t] == base_material());
    }
    EXPECT_GT(still_painted, 0u);
    // A fresh index after the cut paints the surviving tets.
    const PaintIndex index(mesh);
    EXPECT_NO_THROW(paint_stroke(mesh, index, std::vector<Eigen::Vector3d>{{0.3, 0.5, 0.5}}, red_brush(0.1)));
}

TEST(Paint, RejectsBadInput) {
    TetMesh mesh = make_cube_mesh(3);
    const std::vector<Eigen::Vector3d> stroke = {{0.5, 0.5, 0.5}};
    // No materials and no base material.
    EXPECT_THROW(paint_stroke(mesh, stroke, red_brush(0.1)), InvalidArgumentError);
    EXPECT_THROW(paint_stroke(mesh, stroke, red_brush(0.0), base_material()), InvalidArgumentError);
    EXPECT_THROW(paint_stroke(mesh, stroke, red_brush(-1.0), base_material()), InvalidArgumentError);
    EXPECT_THROW(paint_stroke(mesh, std::vector<Eigen::Vector3d>{}, red_brush(0.1), base_material()),
                 InvalidArgumentError);
    EXPECT_THROW(paint_stroke(mesh, std::vector<Eigen::Vector3d>{{std::nan(""), 0, 0}}, red_brush(0.1), base_material()),
                 InvalidArgumentError);
    PaintBrush bad_cutoff = red_brush(0.1);
    bad_cutoff.cutoff_weight = 1.0;
    EXPECT_THROW(paint_stroke(mesh, stroke, bad_cutoff, base_material()), InvalidArgumentError);
    // An index from before a cut is stale.
    const PaintIndex stale(mesh);
    remove_cut_away_tets(mesh, PlaneCut(Eigen::Vector3d(1, 0, 0), 0.5));
    EXPECT_THROW(paint_stroke(mesh, stale, stroke, red_brush(0.1), base_material()), InvalidArgumentError);
}

TEST(Paint, EmptyMeshAndFarStrokeChangeNothing) {
    TetMesh mesh = make_cube_mesh(3);
    const PaintResult far = paint_stroke(mesh, std::vector<Eigen::Vector3d>{{10, 10, 10}}, red_brush(0.1), base_material());
    EXPECT_TRUE(far.changed_tets.empty());
    for (const TetMaterial& m : mesh.materials) EXPECT_EQ(m, base_material());
    remove_cut_away_tets(mesh, PlaneCut(Eigen::Vector3d(1, 0, 0), -1.0));
    ASSERT_EQ(mesh.tet_count(), 0u);
    EXPECT_TRUE(paint_stroke(mesh, std::vector<Eigen::Vector3d>{{0, 0, 0}}, red_brush(0.1)).changed_tets.empty());
}

}  // namespace
}  // namespace waxwork
