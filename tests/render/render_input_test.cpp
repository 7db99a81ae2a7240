#include "solver/material.h"
#include "tetops/point_location.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>

namespace waxwork {
namespace {

// The name a comparison records (bench solvers) is that of the materials resolve_materials fills the
// tets with: the override (a preset by its name, other coefficients as "custom"), else the volume's
// own ("stored"), else the marble default.
TEST(ResolvedMaterials, AreNamedAsTheyAreChosen) {
    TetMesh mesh = testing::make_cube_mesh(2);
    const TetMaterial ketchup = material_preset("ketchup");
    EXPECT_EQ(resolve_materials(mesh, std::nullopt).front(), material_preset("marble"));
    EXPECT_EQ(resolved_materials_name(mesh, std::nullopt), "marble");
    EXPECT_EQ(resolved_materials_name(mesh, ketchup), "ketchup");
    TetMaterial custom = ketchup;
    custom.eta = 1.4;
    EXPECT_EQ(resolved_materials_name(mesh, custom), "custom");
    mesh.materials.assign(mesh.tet_count(), custom);
    EXPECT_EQ(resolve_materials(mesh, std::nullopt).front(), custom);
    EXPECT_EQ(resolved_materials_name(mesh, std::nullopt), "stored");
    EXPECT_EQ(resolve_materials(mesh, ketchup).front(), ketchup);
    EXPECT_EQ(resolved_materials_name(mesh, ketchup), "ketchup");
}

// Points inside, on the boundary and outside a unit cube, and far away along its diagonal, where the
// barycentric sub-volumes round to anything (a light at 1e8 used to count as inside).
TEST(PointInsideVolume, FarPointsAreOutsideWhateverTheRounding) {
    const TetMesh cube = testing::make_cube_mesh(3);
    EXPECT_TRUE(point_inside_volume(cube, Eigen::Vector3d(0.5, 0.5, 0.5)));
    EXPECT_TRUE(point_inside_volume(cube, Eigen::Vector3d(0.2, 0.9, 0.4)));
    EXPECT_TRUE(point_inside_volume(cube, Eigen::Vector3d(1.0, 0.5, 0.5)));  // on a face
    EXPECT_FALSE(point_inside_volume(cube, Eigen::Vector3d(1.01, 0.5, 0.5)));
    for (const double far : {3e7, 1e8, 1e15, 1e100})
        for (const Eigen::Vector3d& direction : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, -1, 1),
                                                Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1.1, 0.9)})
            EXPECT_FALSE(point_inside_volume(cube, far * direction)) << far << " " << direction.transpose();
}

}  // namespace
}  // namespace waxwork
