#include "base/error.h"
#include "scene/live_scene.h"
#include "scene/live_test_scene.h"
#include "solver/material.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>

#include <limits>
#include <set>

namespace waxwork {
namespace {

using testing::key_lighting;
using testing::paint_at;

constexpr double kTolerance = 1e-9;

LiveSceneOptions options() {
    LiveSceneOptions o;
    o.mm_per_unit = 10;  // a 1 cm marble cube: phi varies strongly across it
    o.relative_tolerance = kTolerance;
    return o;
}

// The live scene, converged, against a from-scratch solve_scene of the same mesh and lights.
void expect_matches_fresh_solve(LiveScene& scene, const TetMesh& mesh, const Lighting& lighting,
                                const std::string& what, double crease_angle = kDefaultCreaseAngleDegrees) {
    scene.converge();
    const TetConnectivity connectivity = build_connectivity(mesh);
    DiffusionOptions diffusion;
    diffusion.mm_per_unit = options().mm_per_unit;
    diffusion.relative_tolerance = kTolerance;
    const SolvedScene fresh = solve_scene(mesh, connectivity, mesh.materials, lighting, diffusion, crease_angle);
    const auto live = scene.phi();
    ASSERT_EQ(live.size(), fresh.diffusion.phi.size()) << what;
    double largest = 0, difference = 0;
    for (size_t v = 0; v < live.size(); ++v)
        for (int c = 0; c < 3; ++c) {
            largest = std::max(largest, std::abs(fresh.diffusion.phi[v][c]));
            difference = std::max(difference, std::abs(live[v][c] - fresh.diffusion.phi[v][c]));
        }
    EXPECT_GT(largest, 0) << what;
    EXPECT_LT(difference, 1e-6 * largest) << what;
    // The radiance the renderer gets follows phi.
    const SolvedScene snapshot = scene.solved_scene();
    ASSERT_EQ(snapshot.shading.surface_vertex, fresh.shading.surface_vertex) << what;
    ASSERT_EQ(snapshot.radiance_factor.size(), fresh.radiance_factor.size());
    EXPECT_EQ(scene.radiance_factors(), snapshot.radiance_factor);
    for (size_t v = 0; v < fresh.radiance_factor.size(); ++v)
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(snapshot.radiance_factor[v][c], fresh.radiance_factor[v][c],
                        1e-4 * std::abs(fresh.radiance_factor[v][c]) + 1e-6)
                << what;
}

TEST(LiveScene, FollowsEveryKindOfChangeToTheFreshSolution) {
    Document doc(testing::make_cube_mesh(7), material_preset("marble"));
    Lighting lighting = key_lighting();
    LiveScene scene(doc.mesh(), lighting, options());
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "initial");

    // Paint inside (eta unchanged for the rows) and at the surface with a different eta.
    auto update = scene.apply_change(doc.mesh(), doc.apply(paint_at({0.5, 0.5, 0.5})));
    EXPECT_FALSE(update.reassembled_matrix);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "paint inside");
    update = scene.apply_change(doc.mesh(), doc.apply(paint_at({0.0, 0.5, 0.5}, "skin1")));
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "paint at the surface");

    PaintOp glassy = paint_at({1.0, 0.3, 0.5});
    glassy.material.eta = 1.9;  // unlike marble (1.5) and the other presets (1.3): q changes at the surface
    update = scene.apply_change(doc.mesh(), doc.apply(glassy));
    EXPECT_TRUE(update.recomputed_light);
    EXPECT_FALSE(update.rebuilt_surface);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "paint with another eta");

    update = scene.apply_change(doc.mesh(), doc.apply(SetMaterialOp{material_preset("skin2"), std::nullopt}));
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "set material");

    PlaneCutOp cut;
    cut.plane = {Eigen::Vector3d(1, 0.3, 0.2), 0.6};
    update = scene.apply_change(doc.mesh(), doc.apply(cut));
    EXPECT_TRUE(update.reassembled_matrix);
    EXPECT_FALSE(update.rebuilt_connectivity);  // reused from the cut
    EXPECT_TRUE(update.warm_start);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "cut");

    update = scene.apply_change(doc.mesh(), doc.apply(RelaxOp{cut.plane, RelaxSettings{5, 0.3, 0.5}}));
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "relax");

    lighting.lights[0].vector = Eigen::Vector3d(-1, -0.2, 0.4).normalized();
    lighting.lights.push_back(Light{LightType::Point, Eigen::Vector3d(0.5, 2, 0.5), {0.5, 0.4, 0.3}});
    update = scene.set_lighting(lighting);
    EXPECT_TRUE(update.recomputed_light);
    EXPECT_FALSE(update.reassembled_matrix);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "relight");

    while (doc.can_undo()) {
        const auto report = doc.undo();
        scene.apply_change(doc.mesh(), *report);
        expect_matches_fresh_solve(scene, doc.mesh(), lighting, report->name);
    }
}

// A refinement appends vertices at edge midpoints and splits tets: every method carries phi through the
// new vertices' origins and rebuilds around the change, and the solve after it, and after its undo, is
// the fresh solve of the mesh.
TEST(LiveScene, FollowsARefinementToTheFreshSolutionWithEveryMethod) {
    for (const LiveMethod method : {LiveMethod::JacobiCg, LiveMethod::MultigridCg, LiveMethod::Multires}) {
        const std::string what = live_method_name(method);
        Document doc(testing::make_cube_mesh(6), material_preset("marble"));
        doc.apply(paint_at({0.3, 0.5, 0.5}));
        const Lighting lighting = key_lighting();
        LiveSceneOptions o = options();
        o.method = method;
        LiveScene scene(doc.mesh(), lighting, o);
        expect_matches_fresh_solve(scene, doc.mesh(), lighting, what + ": before");
        RefineOp refine;
        for (int32_t t = 0; t < 400; t += 3) refine.tets.push_back(t);
        const ChangeReport report = doc.apply(refine);
        ASSERT_GT(doc.mesh().tet_count(), report.tets_before) << what;
        const SceneUpdate update = scene.apply_change(doc.mesh(), report);
        EXPECT_TRUE(update.reassembled_matrix) << what;
        EXPECT_TRUE(update.warm_start) << what;
        expect_matches_fresh_solve(scene, doc.mesh(), lighting, what + ": refined");
        scene.apply_change(doc.mesh(), *doc.undo());
        expect_matches_fresh_solve(scene, doc.mesh(), lighting, what + ": undone");
    }
}

// A deformation keeps the tets: only the rows of the moved vertices' tets are rewritten on the kept
// pattern (the other piece's rows are not touched), every method's hierarchy keeps its graph, and the
// solve after the deformation, and after its undo, is the fresh solve of the deformed mesh, under a key
// light and under the sky.
TEST(LiveScene, FollowsADeformationOnTheKeptPatternWithEveryMethod) {
    for (const LiveMethod method : {LiveMethod::JacobiCg, LiveMethod::MultigridCg, LiveMethod::Multires}) {
        for (const bool sky : {false, true}) {
            if (sky && method != LiveMethod::JacobiCg) continue;
            const std::string what = std::string(live_method_name(method)) + (sky ? " under the sky" : "");
            Document doc(testing::make_cube_mesh(7), material_preset("marble"));
            FractureOp fracture;
            fracture.seeds = {Eigen::Vector3d(0.25, 0.5, 0.5), Eigen::Vector3d(0.75, 0.5, 0.5)};
            doc.apply(fracture);
            doc.apply(paint_at({0.2, 0.5, 0.5}));
            Lighting lighting = key_lighting();
            if (sky) lighting.environment = sky_environment_light(SkySettings{30, 40, 3});
            LiveSceneOptions o = options();
            o.method = method;
            LiveScene scene(doc.mesh(), lighting, o);
            expect_matches_fresh_solve(scene, doc.mesh(), lighting, what + ": before");

            DeformOp bend;
            bend.grab = Eigen::Vector3d(0, 0.5, 0.5);
            bend.radius = 0.4;
            bend.motion = HandleMotion::bend(Eigen::Vector3d(0.4, 0.5, 0.5), Eigen::Vector3d(0, 0, 1), 0.5);
            bend.pins = {PinSphere{Eigen::Vector3d(0.45, 0.5, 0.5), 0.1}};
            const ChangeReport report = doc.apply(bend);
            const SceneUpdate update = scene.apply_change(doc.mesh(), report);
            EXPECT_FALSE(update.reassembled_matrix) << what;
            EXPECT_FALSE(update.rebuilt_connectivity) << what;
            EXPECT_TRUE(update.rebuilt_surface) << what;
            ASSERT_FALSE(update.updated_rows.empty()) << what;
            EXPECT_LT(update.updated_rows.size(), doc.mesh().vertex_count()) << what << ": the other piece stays";
            expect_matches_fresh_solve(scene, doc.mesh(), lighting, what + ": bent");

            scene.apply_change(doc.mesh(), *doc.undo());
            expect_matches_fresh_solve(scene, doc.mesh(), lighting, what + ": undone");
        }
    }
}

// Under an environment the scene keeps one transfer per surface vertex: a turn of the environment
// relights it without casting rays, a paint that changes eta at the surface updates the transfer of
// those vertices only, and a cut rebuilds it; each time the solution is the fresh one.
TEST(LiveScene, FollowsTheEnvironmentThroughEditsAndTurns) {
    Document doc(testing::make_cube_mesh(5), material_preset("marble"));
    Lighting lighting;
    lighting.environment = sky_environment_light(SkySettings{30, 40, 3});
    LiveScene scene(doc.mesh(), lighting, options());
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "sky");

    PaintOp glassy = paint_at({1.0, 0.3, 0.5});
    glassy.material.eta = 1.9;
    SceneUpdate update = scene.apply_change(doc.mesh(), doc.apply(glassy));
    EXPECT_TRUE(update.recomputed_light);
    EXPECT_FALSE(update.rebuilt_surface);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "paint with another eta under the sky");

    PlaneCutOp cut;
    cut.plane = {Eigen::Vector3d(1, 0.3, 0.2), 0.6};
    update = scene.apply_change(doc.mesh(), doc.apply(cut));
    // Only the vertices that can see the cut are sampled again (none of a convex body's old faces can).
    EXPECT_GT(update.resampled_transfer, 0u);
    EXPECT_LT(update.resampled_transfer, scene.solved_scene().surface.positions.size());
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "cut under the sky");

    // A piece pulled away: the other piece's crack face now sees sky where it saw the piece. Those
    // vertices stay in place, so they keep their old transfer and wait for the next steps; the scene is
    // not converged until they are sampled.
    FractureOp fracture;
    fracture.seeds = {Eigen::Vector3d(0.3, 0.5, 0.5), Eigen::Vector3d(0.7, 0.5, 0.5)};
    scene.apply_change(doc.mesh(), doc.apply(fracture));
    scene.converge();
    MovePieceOp pull;
    pull.piece = 1;
    pull.transform.translation = Eigen::Vector3d(0.4, 0.3, 0);
    update = scene.apply_change(doc.mesh(), doc.apply(pull));
    EXPECT_GT(update.deferred_transfer, 0u);
    EXPECT_EQ(scene.deferred_transfer(), update.deferred_transfer);
    EXPECT_LT(update.resampled_transfer, scene.solved_scene().surface.positions.size());
    EXPECT_FALSE(scene.converged());
    for (int step = 0; step < 20 && scene.deferred_transfer() > 0; ++step) {
        const size_t waiting = scene.deferred_transfer();
        scene.step(1);
        EXPECT_LT(scene.deferred_transfer(), waiting) << "every step samples some";
    }
    EXPECT_EQ(scene.deferred_transfer(), 0u);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "piece pulled away under the sky");
    // Moved back and again before any step: the vertices still waiting keep waiting, and the end is
    // the same as a fresh scene's.
    update = scene.apply_change(doc.mesh(), *doc.undo());
    EXPECT_GT(scene.deferred_transfer(), 0u);
    // Turned by 35 degrees: the piece's normals turned too far for its old vectors to stand in, so it
    // is sampled at once.
    pull.transform.rotation = Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pull.transform.translation = Eigen::Vector3d(0.2, -0.3, 0.1);
    update = scene.apply_change(doc.mesh(), doc.apply(pull));
    EXPECT_GT(update.resampled_transfer, 0u);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "moved twice without a step between");

    lighting.environment->rotation_degrees = 120;
    lighting.environment->intensity = 1.5;
    update = scene.set_lighting(lighting);
    EXPECT_TRUE(update.recomputed_light);
    EXPECT_FALSE(update.rebuilt_surface);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "turned sky");

    lighting.environment.reset();
    lighting.lights = key_lighting().lights;
    scene.set_lighting(lighting);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "sky removed");
}

// The crease angle decides which sides of a fold are shaded and lit as themselves: changing it
// re-splits the shading and the solve's source (source_light) and leaves the matrix alone; the solve
// goes on warm to the fresh solution at that angle, and the angle holds through later edits.
TEST(LiveScene, TheCreaseAngleReachesTheShadingAndTheSource) {
    Document doc(testing::make_cube_mesh(7), material_preset("marble"));
    const Lighting lighting = key_lighting();
    LiveScene scene(doc.mesh(), lighting, options());
    scene.converge();
    const auto phi = scene.phi();
    const size_t surface_vertices = scene.solved_scene().surface.vertices.size();
    EXPECT_GT(scene.solved_scene().shading.size(), surface_vertices);  // a cube's edges split

    const SceneUpdate update = scene.set_crease_angle(180.0);
    EXPECT_TRUE(update.recomputed_light);
    EXPECT_FALSE(update.reassembled_matrix);
    EXPECT_FALSE(scene.converged());
    EXPECT_EQ(scene.phi(), phi);  // warm: the next steps start from it
    EXPECT_EQ(scene.options().crease_angle_degrees, 180.0);
    EXPECT_EQ(scene.solved_scene().shading.size(), surface_vertices);
    EXPECT_EQ(scene.radiance_factors().size(), surface_vertices);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "unsplit", 180.0);
    EXPECT_NE(scene.phi(), phi);  // the averaged normals light the cube's rims differently
    EXPECT_FALSE(scene.set_crease_angle(180.0).recomputed_light);  // the same angle: nothing to do

    PlaneCutOp cut;
    cut.plane = {Eigen::Vector3d(1, 0.3, 0.2), 0.6};
    scene.apply_change(doc.mesh(), doc.apply(cut));
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "cut, unsplit", 180.0);
    scene.set_crease_angle(30.0);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "cut, split at 30 degrees", 30.0);

    for (const double bad : {-1.0, 180.5, std::numeric_limits<double>::quiet_NaN()})
        EXPECT_THROW(scene.set_crease_angle(bad), InvalidArgumentError) << bad;
    EXPECT_EQ(scene.options().crease_angle_degrees, 30.0);
    LiveSceneOptions bad_options = options();
    bad_options.crease_angle_degrees = 200;
    EXPECT_THROW(LiveScene(doc.mesh(), lighting, bad_options), InvalidArgumentError);
    for (const double tolerance : {0.0, 1.0}) {
        LiveSceneOptions bad_tolerance = options();
        bad_tolerance.relative_tolerance = tolerance;
        EXPECT_THROW(LiveScene(doc.mesh(), lighting, bad_tolerance), InvalidArgumentError) << tolerance;
    }
}

TEST(LiveScene, FollowsFracturesMovesWeldsAndExactCuts) {
    Document doc(testing::make_cube_mesh(7), material_preset("marble"));
    const Lighting lighting = key_lighting();
    LiveScene scene(doc.mesh(), lighting, options());
    scene.converge();

    FractureOp fracture;
    fracture.seeds = {Eigen::Vector3d(0.3, 0.5, 0.5), Eigen::Vector3d(0.7, 0.5, 0.5)};
    SceneUpdate update = scene.apply_change(doc.mesh(), doc.apply(fracture));
    EXPECT_TRUE(update.reassembled_matrix);
    EXPECT_TRUE(update.warm_start);  // every vertex kept, crack copies placed by their origins
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "fracture");

    // Pulled apart and turned: light now reaches the crack faces, shadows move; the matrix stays.
    MovePieceOp pull;
    pull.piece = 1;
    pull.transform.rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pull.transform.translation = Eigen::Vector3d(0.5, 0.1, 0);
    update = scene.apply_change(doc.mesh(), doc.apply(pull));
    EXPECT_TRUE(update.rebuilt_surface);
    EXPECT_FALSE(update.reassembled_matrix);
    EXPECT_TRUE(update.warm_start);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "move");

    scene.apply_change(doc.mesh(), *doc.undo());
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "undo move");
    update = scene.apply_change(doc.mesh(), doc.apply(WeldOp{1e-9}));
    EXPECT_EQ(doc.mesh().piece_transforms.size(), 1u);
    EXPECT_TRUE(update.warm_start);  // the merged vertices' partners keep their phi
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "weld");

    PlaneCutOp exact;
    exact.plane = {Eigen::Vector3d(1, 0.3, 0.2), 0.6};
    exact.exact = true;
    update = scene.apply_change(doc.mesh(), doc.apply(exact));
    EXPECT_TRUE(update.warm_start);
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "exact cut");
}

TEST(LiveScene, FollowsTheRemovalOfAFragmentFromAWarmStart) {
    // A U whose bridge a cut removes, leaving a short arm (1/6 of the volume) beside the long one.
    Document doc(testing::make_cell_mesh(7, 6, 2, [](int i, int j, int) { return j == 0 || i == 0 || (i == 6 && j <= 1); }),
                 material_preset("marble"));
    const Lighting lighting = key_lighting();
    LiveScene scene(doc.mesh(), lighting, options());
    PlaneCutOp cut;
    cut.plane = {-Eigen::Vector3d::UnitY(), -1.5};
    cut.relax.iterations = 0;
    scene.apply_change(doc.mesh(), doc.apply(cut));
    scene.converge();
    const SceneUpdate update = scene.apply_change(doc.mesh(), doc.apply(RemoveFragmentsOp{0.2}));
    EXPECT_TRUE(update.reassembled_matrix);
    EXPECT_TRUE(update.warm_start);  // the long arm's vertices keep their phi
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "remove fragments");
    scene.apply_change(doc.mesh(), *doc.undo());
    expect_matches_fresh_solve(scene, doc.mesh(), lighting, "undo remove fragments");
}

TEST(LiveScene, PaintRewritesExactlyTheRowsOfThePaintedTets) {
    Document doc(testing::make_cube_mesh(7), material_preset("marble"));
    LiveScene scene(doc.mesh(), key_lighting(), options());
    const ChangeReport paint = doc.apply(paint_at({0.4, 0.5, 0.6}));
    const SceneUpdate update = scene.apply_change(doc.mesh(), paint);
    std::set<int32_t> expected;
    for (const int32_t t : paint.changed_material_tets)
        for (const int32_t v : doc.mesh().tets[t]) expected.insert(v);
    ASSERT_FALSE(expected.empty());
    EXPECT_LT(expected.size(), doc.mesh().vertex_count() / 2);
    EXPECT_EQ(update.updated_rows, std::vector<int32_t>(expected.begin(), expected.end()));
    EXPECT_FALSE(update.reassembled_matrix);
    EXPECT_FALSE(update.recomputed_values);
    EXPECT_FALSE(update.rebuilt_surface);
    EXPECT_FALSE(update.recomputed_light);  // the brush stays inside: no boundary eta, so no q, changes
}

TEST(LiveScene, StepsAreBoundedAndAConvergedSceneIsIdle) {
    Document doc(testing::make_cube_mesh(7), material_preset("marble"));
    LiveSceneOptions o = options();
    o.relative_tolerance = 1e-6;
    LiveScene scene(doc.mesh(), key_lighting(), o);
    FrameReport frame = scene.step(3);
    for (int c = 0; c < 3; ++c) EXPECT_LE(frame.iterations[c], 3);
    EXPECT_FALSE(frame.converged);
    const double first_error = frame.max_error();
    for (int i = 0; i < 200 && !frame.converged; ++i) frame = scene.step(3);
    EXPECT_TRUE(frame.converged);
    EXPECT_LT(frame.max_error(), first_error);
    EXPECT_LE(frame.max_error(), 1e-6);
    EXPECT_TRUE(scene.converged());
    EXPECT_EQ(scene.step(3).total_iterations(), 0);
    // An edit makes it work again.
    scene.apply_change(doc.mesh(), doc.apply(paint_at({0.5, 0.5, 0.5})));
    EXPECT_FALSE(scene.converged());
    EXPECT_GT(scene.step(3).total_iterations(), 0);
}

TEST(LiveScene, TimeBudgetedStepsReachTheTolerance) {
    Document doc(testing::make_cube_mesh(6), material_preset("marble"));
    LiveSceneOptions o = options();
    o.relative_tolerance = 1e-6;
    LiveScene scene(doc.mesh(), key_lighting(), o);
    FrameReport frame = scene.step_for(0, 2);  // a zero budget still runs one chunk
    EXPECT_GT(frame.total_iterations(), 0);
    EXPECT_LE(frame.iterations[0], 2);
    for (int i = 0; i < 1000 && !frame.converged; ++i) frame = scene.step_for(1.0, 2);
    EXPECT_TRUE(frame.converged);
    EXPECT_THROW(scene.step_for(-1), InvalidArgumentError);
}

// Multigrid CG counts its budget in V-cycles (one per 4 iterations of the editor's budget, at least
// one; live_solver.h), each serving all three channels, and its phi and radiance follow edits to the
// from-scratch solve.
TEST(LiveScene, MultigridFramesRunVcyclesAndFollowTheFreshSolve) {
    Document doc(testing::make_cube_mesh(12), material_preset("marble"));
    LiveSceneOptions o = options();
    o.method = LiveMethod::MultigridCg;
    LiveScene scene(doc.mesh(), key_lighting(), o);
    EXPECT_EQ(scene.step(0).total_iterations(), 0);
    for (const auto& [budget, vcycles] : {std::pair{3, 1}, std::pair{4, 1}, std::pair{9, 2}}) {
        const FrameReport frame = scene.step(budget);
        ASSERT_FALSE(frame.converged) << budget;
        for (int c = 0; c < 3; ++c) EXPECT_EQ(frame.iterations[c], vcycles) << "budget " << budget;
        EXPECT_GT(frame.max_error(), kTolerance);
    }
    // A time budget runs whole V-cycles, at least one.
    const FrameReport timed = scene.step_for(0);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(timed.iterations[c], 1);
    expect_matches_fresh_solve(scene, doc.mesh(), key_lighting(), "multigrid");
    EXPECT_TRUE(scene.converged());
    EXPECT_EQ(scene.step(8).total_iterations(), 0);  // idle once converged
    scene.apply_change(doc.mesh(), doc.apply(paint_at({0.5, 0.5, 0.5})));
    EXPECT_FALSE(scene.converged());
    expect_matches_fresh_solve(scene, doc.mesh(), key_lighting(), "multigrid after paint");
    Lighting turned = key_lighting();
    turned.lights[0].vector = Eigen::Vector3d(0.8, -0.8, -0.7).normalized();
    scene.set_lighting(turned);
    expect_matches_fresh_solve(scene, doc.mesh(), turned, "multigrid after a light change");
}

}  // namespace
}  // namespace waxwork
