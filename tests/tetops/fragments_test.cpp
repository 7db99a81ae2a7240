// Dropping small detached parts (tetops/fragments.h): which parts go, that the largest always stays,
// and that per-tet data follow the tets that remain.
#include "base/error.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/fragments.h"
#include "tetops/test_meshes.h"
#include "tetops/tet_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace waxwork {
namespace {
using testing::make_cell_mesh;
using testing::make_cube_mesh;

// A unit cube of 4^3 cells (384 tets) and, apart from it, a cube 0.1 across (6 tets, volume 0.001).
TetMesh body_and_speck() {
    TetMesh mesh = join_meshes(make_cube_mesh(4), make_cube_mesh(1, Eigen::Vector3d(3, 0, 0), 0.1));
    mesh.materials.resize(mesh.tet_count());
    for (size_t t = 0; t < mesh.tet_count(); ++t) mesh.materials[t] = TetMaterial{{0.1, 0.1, 0.1}, {1, 1, 1}, 1.0 + 0.001 * static_cast<double>(t)};
    return mesh;
}

TEST(RemoveSmallFragments, DropsAPartUnderTheFractionAndKeepsTheRestWithTheirData) {
    TetMesh mesh = body_and_speck();
    const TetMesh before = mesh;
    // The survey tells what the removal then drops, and changes nothing.
    const FragmentSurvey survey = survey_fragments(mesh, build_connectivity(mesh), 0.01);
    EXPECT_EQ(survey.parts, 2u);
    EXPECT_EQ(survey.small_parts, 1u);
    EXPECT_EQ(survey.small_part_tets, 6u);
    EXPECT_NEAR(survey.small_part_volume, 0.001, 1e-12);
    EXPECT_EQ(mesh, before);
    EXPECT_THROW(survey_fragments(mesh, build_connectivity(make_cube_mesh(1)), 0.01), InvalidArgumentError);
    const FragmentRemoval result = remove_small_fragments(mesh, 0.01);
    EXPECT_EQ(result.fragments_removed, 1u);
    EXPECT_EQ(result.parts_kept, 1u);
    EXPECT_NEAR(result.volume_removed, 0.001, 1e-12);
    EXPECT_EQ(result.removed.tets_removed, 6u);
    EXPECT_EQ(result.removed.vertices_removed, 8u);
    ASSERT_EQ(mesh.tet_count(), 384u);
    EXPECT_TRUE(find_invariant_violations(mesh).empty());
    EXPECT_NEAR(total_volume(mesh), 1.0, 1e-12);
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const int32_t old = result.removed.new_to_old_tet[t];
        EXPECT_EQ(mesh.original_ids[t], before.original_ids[old]);
        EXPECT_EQ(mesh.materials[t], before.materials[old]);
        for (int k = 0; k < 4; ++k)
            EXPECT_EQ(mesh.positions[mesh.tets[t][k]], before.positions[before.tets[old][k]]);
    }
}

TEST(RemoveSmallFragments, KeepsPartsAtOrAboveTheFraction) {
    TetMesh mesh = body_and_speck();
    const TetMesh before = mesh;
    // The speck is 0.001 / 1.001 of the volume: just above 0.0009.
    const FragmentRemoval result = remove_small_fragments(mesh, 0.0009);
    EXPECT_EQ(result.fragments_removed, 0u);
    EXPECT_EQ(result.parts_kept, 2u);
    EXPECT_EQ(mesh, before);
    EXPECT_EQ(remove_small_fragments(mesh, 0.0).fragments_removed, 0u);
    EXPECT_EQ(mesh, before);
}

TEST(RemoveSmallFragments, AlwaysKeepsTheLargestPart) {
    // Three parts of 6, 48 and 6 tets: a fraction no part reaches still keeps the middle one.
    TetMesh mesh = join_meshes(join_meshes(make_cube_mesh(1, Eigen::Vector3d(-3, 0, 0)), make_cube_mesh(2, Eigen::Vector3d::Zero(), 2.0)),
                               make_cube_mesh(1, Eigen::Vector3d(5, 0, 0)));
    const FragmentRemoval result = remove_small_fragments(mesh, 0.99);
    EXPECT_EQ(result.fragments_removed, 2u);
    ASSERT_EQ(mesh.tet_count(), 48u);
    EXPECT_NEAR(total_volume(mesh), 8.0, 1e-12);
    // Equal parts: the lowest-numbered stays.
    TetMesh twins = join_meshes(make_cube_mesh(1), make_cube_mesh(1, Eigen::Vector3d(3, 0, 0)));
    remove_small_fragments(twins, 0.9);
    ASSERT_EQ(twins.tet_count(), 6u);
    EXPECT_LT(twins.positions[twins.tets[0][0]].x(), 2.0);
}

TEST(RemoveSmallFragments, DropsTheShortArmAPlaneCutLeftOfAU) {
    // A U of 7 x 6 cells: a bridge along j = 0 and arms at i = 0 (5 cells up) and i = 6 (1 cell up).
    // Cutting the bridge away (y < 1.5 removes the tets wholly below) leaves the arms apart: 5 cells and 1.
    TetMesh mesh = make_cell_mesh(7, 6, 1, [](int i, int j, int) { return j == 0 || i == 0 || (i == 6 && j <= 1); });
    remove_cut_away_tets(mesh, PlaneCut(-Eigen::Vector3d::UnitY(), -1.5));
    ASSERT_EQ(build_connectivity(mesh).component_count, 2);
    const FragmentRemoval result = remove_small_fragments(mesh, 0.2);  // the short arm is 1/6
    EXPECT_EQ(result.fragments_removed, 1u);
    EXPECT_EQ(mesh.tet_count(), 5u * 6u);
    for (const Eigen::Vector3d& p : mesh.positions) EXPECT_LE(p.x(), 1.0);
    EXPECT_EQ(build_connectivity(mesh).component_count, 1);
}

TEST(RemoveSmallFragments, DropsASmallPieceWholeAndKeepsThePieceTable) {
    TetMesh mesh = body_and_speck();
    // The speck is its own piece, moved away.
    mesh.piece_transforms.push_back(RigidTransform{Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 5, 0)});
    for (size_t t = 384; t < mesh.tet_count(); ++t) mesh.piece_ids[t] = 1;
    remove_small_fragments(mesh, 0.01);
    EXPECT_EQ(mesh.tet_count(), 384u);
    EXPECT_EQ(mesh.piece_transforms.size(), 2u);  // piece 1 is empty, as after a cut
    for (int32_t piece : mesh.piece_ids) EXPECT_EQ(piece, 0);
}

TEST(RemoveSmallFragments, RefusesFractionsOutsideZeroToOne) {
    TetMesh mesh = body_and_speck();
    for (double bad : {-0.1, 1.0, 2.0, std::numeric_limits<double>::quiet_NaN(),
                       std::numeric_limits<double>::infinity()})
        EXPECT_THROW(remove_small_fragments(mesh, bad), InvalidArgumentError) << bad;
    TetMesh empty;
    EXPECT_EQ(remove_small_fragments(empty, 0.5).fragments_removed, 0u);
}

}  // namespace
}  // namespace waxwork
