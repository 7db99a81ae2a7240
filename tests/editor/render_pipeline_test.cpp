#include "editor/render_pipeline.h"
#include "solver/material.h"
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

}  // namespace
}  // namespace waxwork
