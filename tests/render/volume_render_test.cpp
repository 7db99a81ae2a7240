#include "base/error.h"
#include "render/volume_render.h"
#include "solver/material.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>

#include <string>

namespace waxwork {
namespace {

float luminance(const Image& image, int x, int y) {
    const uint8_t* p = image.pixel(x, y);
    return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
}

VolumeRenderSettings small_picture() {
    VolumeRenderSettings settings;
    Light key;
    key.type = LightType::Directional;
    key.vector = Eigen::Vector3d(1, -1, -1).normalized();
    settings.lighting.lights = {key};
    settings.diffusion.mm_per_unit = 10;
    settings.image.width = 64;
    settings.image.height = 48;
    return settings;
}

// The picture has the asked size, the object covers the centre and not the corners, the materials
// are the ones asked for, and a point light inside the volume is counted (it lights nothing).
TEST(VolumeRender, DrawsTheVolumeWithItsMaterialsAndCountsLightsInside) {
    const TetMesh cube = testing::make_cube_mesh(3);
    VolumeRenderSettings settings = small_picture();
    Light inside;
    inside.type = LightType::Point;
    inside.vector = Eigen::Vector3d(0.5, 0.5, 0.5);
    settings.lighting.lights.push_back(inside);
    settings.material = material_preset("skin1");
    const VolumeRender render = render_volume(cube, "cube.vtu", settings);
    EXPECT_EQ(render.image.width, 64);
    EXPECT_EQ(render.image.height, 48);
    EXPECT_EQ(render.lights_inside, 1u);
    ASSERT_EQ(render.materials.size(), cube.tet_count());
    EXPECT_EQ(render.materials.front(), material_preset("skin1"));
    EXPECT_GT(luminance(render.image, 32, 24), luminance(render.image, 0, 0) + 10);
    EXPECT_GT(render.exposure, 0);
    for (const int iterations : render.scene.diffusion.iterations) EXPECT_GT(iterations, 0);
    EXPECT_EQ(render.connectivity.component_count, 1);
}

// A different material gives a different picture (the solve is not skipped or cached across calls).
TEST(VolumeRender, TheMaterialChangesThePicture) {
    const TetMesh cube = testing::make_cube_mesh(3);
    VolumeRenderSettings settings = small_picture();
    settings.material = material_preset("marble");
    const Image marble = render_volume(cube, "cube.vtu", settings).image;
    settings.material = material_preset("ketchup");
    const Image ketchup = render_volume(cube, "cube.vtu", settings).image;
    EXPECT_NE(marble, ketchup);
}

// Errors about the volume's own data name the volume.
TEST(VolumeRender, EmptyVolumesAndUnusableStoredMaterialsNameTheVolume) {
    const VolumeRenderSettings settings = small_picture();
    try {
        render_volume(TetMesh{}, "empty.vtu", settings);
        FAIL() << "an empty volume was rendered";
    } catch (const InvalidArgumentError& error) {
        EXPECT_NE(std::string(error.what()).find("empty.vtu"), std::string::npos) << error.what();
    }
    TetMesh cube = testing::make_cube_mesh(2);
    cube.materials.assign(cube.tet_count(), material_preset("marble"));
    cube.materials[3].mua = {-1, 0.1, 0.1};
    try {
        render_volume(cube, "painted.vtu", settings);
        FAIL() << "a negative absorption was solved";
    } catch (const Error& error) {
        EXPECT_NE(std::string(error.what()).find("painted.vtu"), std::string::npos) << error.what();
        EXPECT_NE(std::string(error.what()).find("tet 3"), std::string::npos) << error.what();
    }
}

}  // namespace
}  // namespace waxwork
