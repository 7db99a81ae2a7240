// SceneCore's tick hands the front end what it shows; here, the warning for a view outside the regime
// where the live image can be trusted (solver/transport_validity.h), given with the geometry.
#include "scene/scene_core.h"
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
