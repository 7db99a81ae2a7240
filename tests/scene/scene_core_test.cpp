// SceneCore's tick hands the front end what it shows; here, the warning for a view outside the regime
// where the live image can be trusted (solver/transport_validity.h), given with the geometry.
#include "scene/scene_core.h"
#include "io/image_io.h"
#include "io/volume_file.h"
#include "scene/session.h"
#include "support/scratch_dir.h"
#include "scene/live_test_scene.h"
#include "solver/material.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>

namespace waxwork {
namespace {

SceneTickRequest first_tick() {
    SceneTickRequest request;
    request.first = true;
    request.image.width = 32;
    request.image.height = 24;
    return request;
}

TEST(SceneCore, TickWarnsWhenAMaterialIsOutsideTheTrustedRegime) {
    Session setup;
    setup.material = material_preset("marble");
    setup.scale = 10;
    SceneCore core(testing::make_cube_mesh(4), setup, LiveSceneOptions{});
    const SceneTickResult first = core.tick(first_tick());
    ASSERT_TRUE(first.trust_warning);
    EXPECT_EQ(*first.trust_warning, "");
    // Nothing changed: no new verdict.
    EXPECT_FALSE(core.tick(SceneTickRequest{}).trust_warning);
    // A ketchup dab (blended into marble at its rim) is below the threshold, and undoing it clears the
    // warning.
    SceneTickRequest paint;
    paint.jobs.emplace_back("paint", [](SceneCore& c) {
        c.apply(testing::paint_at({0.5, 0.5, 0.5}, "ketchup"));
        return std::string("painted");
    });
    const SceneTickResult painted = core.tick(paint);
    ASSERT_TRUE(painted.trust_warning);
    EXPECT_NE(painted.trust_warning->find("outside the trusted regime"), std::string::npos) << *painted.trust_warning;
    SceneTickRequest undo;
    undo.jobs.emplace_back("undo", [](SceneCore& c) {
        c.undo();
        return std::string("undone");
    });
    const SceneTickResult undone = core.tick(undo);
    ASSERT_TRUE(undone.trust_warning);
    EXPECT_EQ(*undone.trust_warning, "");
}

}  // namespace
}  // namespace waxwork

namespace waxwork {
namespace {

// Snapshots become, at their point of the history, the camera, the lights and a render; the final
// render returns to the head's view. `waxwork run` replays the saved session to every picture.
TEST(SceneCore, SavedSessionRendersEachSnapshotWhereItWasTaken) {
    const std::filesystem::path dir = testing::scratch_dir("snapshot_session");
    write_volume(testing::make_cube_mesh(4), dir / "cube.vtu");
    Session setup;
    setup.input.volume = dir / "cube.vtu";
    setup.material = material_preset("marble");
    setup.scale = 10;
    setup.lighting = testing::key_lighting();
    setup.width = 64;
    setup.height = 48;
    SceneCore core(testing::make_cube_mesh(4), setup, LiveSceneOptions{});
    PlaneCutOp cut;
    cut.plane.normal = Eigen::Vector3d::UnitX();
    cut.plane.offset = 0.5;
    core.apply(cut);
    SessionSnapshot after_cut;
    after_cut.history = 1;
    after_cut.camera.eye_direction = Eigen::Vector3d(1, 0.3, 0.2);  // looking at the cut
    after_cut.lighting = testing::key_lighting();
    SessionSnapshot at_start = after_cut;
    at_start.history = 0;
    core.apply(testing::paint_at({0.3, 0.5, 0.5}));
    Session head = setup;
    head.camera.eye_direction = Eigen::Vector3d(-1, 0.2, 0.4);
    core.save_session(dir / "edit.json", head, {at_start, after_cut});

    const Session saved = read_session(dir / "edit.json");
    ASSERT_EQ(saved.steps.size(), 2u + 2 * 3 + 4);
    const auto render_name = [&](size_t i) {
        const auto* step = std::get_if<RenderStep>(&saved.steps[i]);
        return step ? step->file : std::string();
    };
    EXPECT_TRUE(std::holds_alternative<CameraStep>(saved.steps[0]));
    EXPECT_EQ(render_name(2), "edit_snapshot_1.png");
    EXPECT_TRUE(std::holds_alternative<EditOperation>(saved.steps[3]));  // the cut
    ASSERT_TRUE(std::holds_alternative<CameraStep>(saved.steps[4]));
    EXPECT_NEAR(std::get<CameraStep>(saved.steps[4]).camera.eye_direction.x(), 1.0, 1e-12);
    EXPECT_EQ(render_name(6), "edit_snapshot_2.png");
    EXPECT_TRUE(std::holds_alternative<EditOperation>(saved.steps[7]));  // the paint
    ASSERT_TRUE(std::holds_alternative<CameraStep>(saved.steps[8]));       // back to the head's view
    EXPECT_NEAR(std::get<CameraStep>(saved.steps[8]).camera.eye_direction.x(), -1.0, 1e-12);
    EXPECT_EQ(render_name(10), "edit.png");

    run_session(saved, dir / "out");
    const Image whole = read_png(dir / "out" / "edit_snapshot_1.png"), cut_view = read_png(dir / "out" / "edit_snapshot_2.png");
    const Image final_view = read_png(dir / "out" / "edit.png");
    EXPECT_EQ(whole.width, 64);
    EXPECT_FALSE(whole == cut_view);
    EXPECT_FALSE(cut_view == final_view);
    EXPECT_TRUE(read_volume(dir / "out" / "edit.vtu") == core.document().mesh());
}

}  // namespace
}  // namespace waxwork
