// The reference beside the live image (scene/reference_render.h): a snapshot that later edits leave
// alone, a trace through the given camera compared with the live image pixel for pixel, the strip and
// numbers it saves, cancellation and bad options.
#include "scene/reference_render.h"

#include "base/error.h"
#include "base/progress.h"
#include "render/camera.h"
#include "scene/live_test_scene.h"
#include "scene/scene_core.h"
#include "solver/material.h"
#include "support/scratch_dir.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace waxwork {
namespace {

std::unique_ptr<SceneCore> lit_cube() {
    Session setup;
    setup.material = material_preset("marble");
    setup.scale = 10;
    setup.lighting = testing::key_lighting();
    return std::make_unique<SceneCore>(testing::make_cube_mesh(4), setup, LiveSceneOptions{});
}

PixelCamera camera_for(const ReferenceScene& scene, int width, int height) {
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3d& p : scene.solved.surface.positions) box.extend(p);
    CameraSettings settings;
    settings.eye_direction = Eigen::Vector3d(0.7, 0.5, 1.0);
    const CameraFrame frame = frame_camera(box, settings, static_cast<double>(width) / height);
    return pixel_camera(frame.eye, frame.view, frame.projection, width, height);
}

ReferenceOptions short_trace() {
    ReferenceOptions options;
    options.max_seconds = 0.5;
    options.target_error = 0;
    options.threads = 1;
    return options;
}

TEST(ReferenceRender, SnapshotIsAConvergedCopyLaterEditsLeaveAlone) {
    auto core = lit_cube();
    const ReferenceScene scene = snapshot_reference_scene(*core);
    EXPECT_TRUE(core->live().converged());
    EXPECT_EQ(scene.mesh.tet_count(), core->document().mesh().tet_count());
    EXPECT_EQ(scene.mesh.materials.size(), scene.mesh.tet_count());
    EXPECT_EQ(scene.solved.radiance_factor.size(), scene.solved.shading.surface_vertex.size());
    EXPECT_DOUBLE_EQ(scene.mm_per_unit, 10);
    ASSERT_EQ(scene.lighting.lights.size(), 1u);
    const size_t tets = scene.mesh.tet_count();
    const TetMaterial before = scene.mesh.materials[0];
    PlaneCutOp cut;
    cut.plane.normal = Eigen::Vector3d::UnitX();
    cut.plane.offset = 0.5;  // the cube is [0, 1]^3: half of it goes
    core->apply(cut);
    PaintOp everywhere = testing::paint_at({0.2, 0.5, 0.5});
    everywhere.sigma = 5;
    core->apply(everywhere);
    EXPECT_LT(core->document().mesh().tet_count(), tets);
    EXPECT_EQ(scene.mesh.tet_count(), tets);
    EXPECT_EQ(scene.connectivity.tet_neighbors.size(), tets);
    EXPECT_EQ(scene.mesh.materials[0], before);
}

TEST(ReferenceRender, TracesTheCamerasPixelsAndComparesThemWithTheLiveImage) {
    auto core = lit_cube();
    const ReferenceScene scene = snapshot_reference_scene(*core);
    const PixelCamera camera = camera_for(scene, 32, 24);
    Progress progress;
    const ReferenceComparison r = render_reference(scene, camera, short_trace(), &progress);
    EXPECT_EQ(r.traced.stop_reason, "seconds");
    EXPECT_GT(r.traced.passes, 0);
    EXPECT_NE(progress.stage().find("noise"), std::string::npos) << progress.stage();
    for (const Image* image : {&r.live_image, &r.traced_at_live_exposure, &r.traced_at_own_exposure, &r.difference_image,
                               &r.scaled_difference_image}) {
        EXPECT_EQ(image->width, 32);
        EXPECT_EQ(image->height, 24);
    }
    // The cube fills the middle of the view in both images, and both are lit there.
    const size_t centre = 12 * 32 + 16;
    EXPECT_EQ(r.live.coverage[centre], 1.0f);
    EXPECT_GT(r.traced.image.coverage[centre], 0.0f);
    EXPECT_GT(r.live.radiance[centre][1], 0);
    EXPECT_GT(r.traced.image.radiance[centre][1], 0);
    EXPECT_GT(r.difference.pixels, 100);
    EXPECT_TRUE(std::isfinite(r.difference.relative_l2));
    EXPECT_GT(r.difference.scale, 0);
    // The traced image at the live exposure differs from its own exactly as far as the exposures do.
    EXPECT_EQ(r.traced_at_live_exposure == r.traced_at_own_exposure, r.live_exposure == r.traced_exposure);
    // Corners are background in every picture.
    EXPECT_EQ(r.difference_image.pixel(0, 0)[0], kViewBackground[0]);
}

TEST(ReferenceRender, SavesTheStripAndItsNumbersBesideIt) {
    auto core = lit_cube();
    const ReferenceScene scene = snapshot_reference_scene(*core);
    const ReferenceComparison r = render_reference(scene, camera_for(scene, 20, 16), short_trace());
    const Image strip = comparison_strip(r, false, 4);
    EXPECT_EQ(strip.width, 3 * 20 + 2 * 4);
    EXPECT_EQ(strip.height, 16);
    // Left third: the live image; the gap: background.
    EXPECT_TRUE(std::equal(r.live_image.pixel(0, 8), r.live_image.pixel(0, 8) + 4 * 20, strip.pixel(0, 8)));
    EXPECT_EQ(strip.pixel(21, 8)[1], kViewBackground[1]);

    const std::filesystem::path dir = testing::scratch_dir("reference_render");
    save_reference_comparison(r, true, dir / "cube.png");
    EXPECT_EQ(read_png(dir / "cube.png"), comparison_strip(r, true));
    nlohmann::json numbers;
    std::ifstream(dir / "cube.json") >> numbers;
    EXPECT_EQ(numbers["passes"], r.traced.passes);
    EXPECT_DOUBLE_EQ(numbers["relative_l2"].get<double>(), r.difference.relative_l2);
    EXPECT_DOUBLE_EQ(numbers["traced_over_live"].get<double>(), r.difference.scale);
    EXPECT_EQ(numbers["stop_reason"], "seconds");
    // Only .png: the numbers' name is derived from it and must not overwrite the picture.
    EXPECT_THROW(save_reference_comparison(r, false, dir / "cube.json"), InvalidArgumentError);
}

TEST(ReferenceRender, CancelStopsTheTraceAndBadOptionsAreRefused) {
    auto core = lit_cube();
    const ReferenceScene scene = snapshot_reference_scene(*core);
    const PixelCamera camera = camera_for(scene, 16, 12);
    Progress cancelled;
    cancelled.request_cancel();
    ReferenceOptions long_trace;
    long_trace.max_seconds = 600;
    long_trace.target_error = 0;
    EXPECT_THROW(render_reference(scene, camera, long_trace, &cancelled), CancelledError);

    const auto refused = [&](auto change) {
        ReferenceOptions o = short_trace();
        change(o);
        EXPECT_THROW(render_reference(scene, camera, o), InvalidArgumentError);
    };
    refused([](ReferenceOptions& o) { o.max_seconds = -1; });
    refused([](ReferenceOptions& o) { o.max_seconds = std::nan(""); });
    refused([](ReferenceOptions& o) { o.target_error = 1; });
    refused([](ReferenceOptions& o) { o.target_error = -0.1; });
    refused([](ReferenceOptions& o) { o.max_seconds = 0, o.target_error = 0; });
    refused([](ReferenceOptions& o) { o.threads = -2; });
}

}  // namespace
}  // namespace waxwork
