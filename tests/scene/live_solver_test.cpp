// The live scene's methods and backends (scene/live_solver.h): each converges to the same phi, follows
// edits (paint rows, all values, a cut) to what a fresh scene gives, and a GPU that fails falls back to
// the CPU with a reason.
#include "base/error.h"
#include "render/surface_renderer.h"
#include "scene/live_scene.h"
#include "scene/live_test_scene.h"
#include "solver/material.h"
#include "tetops/box_mesh.h"
#include "tetops/cut.h"
#include "tetops/sliver_maker.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <optional>
#include <random>
#include <tuple>

namespace waxwork {
namespace {

using testing::key_lighting;
using testing::paint_at;

struct Config {
    LiveMethod method;
    LiveBackend backend;
    // The GPU solves in float: its estimated error cannot go far below 1e-6 (gpu_conjugate_gradient.h).
    double tolerance;
    const char* name;
};

const Config kConfigs[] = {
    {LiveMethod::JacobiCg, LiveBackend::Cpu, 1e-9, "cpu jacobi"},
    {LiveMethod::MultigridCg, LiveBackend::Cpu, 1e-9, "cpu mgcg"},
    {LiveMethod::JacobiCg, LiveBackend::Gpu, 1e-6, "gpu cg"},
    {LiveMethod::Multires, LiveBackend::Cpu, 1e-9, "cpu multires"},
    {LiveMethod::Multires, LiveBackend::Gpu, 1e-6, "gpu multires"},
    {LiveMethod::MultigridCg, LiveBackend::Gpu, 1e-6, "gpu mgcg"},
};

// What the panel says runs: the multigrid on the device is not Jacobi CG.
void expect_description_names_the_method(const LiveScene& scene, const Config& config) {
    const std::string description = scene.solver_description();
    if (config.method == LiveMethod::MultigridCg) {
        EXPECT_NE(description.find("multigrid"), std::string::npos) << config.name << ": " << description;
        EXPECT_EQ(description.find("Jacobi"), std::string::npos) << config.name << ": " << description;
    }
    if (config.backend == LiveBackend::Gpu) {
        EXPECT_NE(description.find("GPU"), std::string::npos) << config.name << ": " << description;
    }
}

LiveSceneOptions options_for(const Config& config) {
    LiveSceneOptions o;
    o.mm_per_unit = 10;  // a 1 cm marble cube: phi varies strongly across it
    o.relative_tolerance = config.tolerance;
    o.method = config.method;
    o.backend = config.backend;
    return o;
}

// max |a - b| / max |b| over vertices and channels.
double relative_difference(const std::vector<std::array<double, 3>>& a, const std::vector<std::array<double, 3>>& b) {
    EXPECT_EQ(a.size(), b.size());
    double largest = 0, difference = 0;
    for (size_t v = 0; v < std::min(a.size(), b.size()); ++v)
        for (int c = 0; c < 3; ++c) {
            largest = std::max(largest, std::abs(b[v][c]));
            difference = std::max(difference, std::abs(a[v][c] - b[v][c]));
        }
    EXPECT_GT(largest, 0);
    return difference / largest;
}

std::vector<std::array<double, 3>> reference_phi(const TetMesh& mesh,
                                                double crease_angle = kDefaultCreaseAngleDegrees) {
    LiveSceneOptions options = options_for(kConfigs[0]);
    options.crease_angle_degrees = crease_angle;
    LiveScene scene(mesh, key_lighting(), options);
    scene.converge();
    return scene.phi();
}

TEST(LiveSolver, EveryMethodAndBackendConvergesToTheSamePhi) {
    const TetMesh mesh = testing::make_cube_mesh(7);
    Document doc(mesh, material_preset("marble"));
    const auto reference = reference_phi(doc.mesh());
    for (const Config& config : kConfigs) {
        LiveScene scene(doc.mesh(), key_lighting(), options_for(config));
        // Frames of a few iterations, as the editor runs them, then to the tolerance.
        for (int i = 0; i < 3; ++i) scene.step(4);
        scene.converge();
        EXPECT_EQ(scene.backend(), config.backend) << config.name << ": " << scene.gpu_fallback_reason();
        EXPECT_EQ(scene.gpu_fallback_reason(), "") << config.name;
        EXPECT_LT(relative_difference(scene.phi(), reference), 1e-4) << config.name;
        expect_description_names_the_method(scene, config);
    }
}

TEST(LiveSolver, EditedScenesConvergeToWhatAFreshSceneGives) {
    for (const Config& config : kConfigs) {
        Document doc(testing::make_cube_mesh(7), material_preset("marble"));
        LiveScene scene(doc.mesh(), key_lighting(), options_for(config));
        scene.converge();
        // Paint (rows only: the device and the multigrid levels take only the changed rows), twice
        // before the next frame so the pending rows merge.
        scene.apply_change(doc.mesh(), doc.apply(paint_at({0.5, 0.5, 0.5}, "ketchup")));
        const SceneUpdate update = scene.apply_change(doc.mesh(), doc.apply(paint_at({0.3, 0.6, 0.4}, "skin1")));
        ASSERT_FALSE(update.updated_rows.empty());
        ASSERT_FALSE(update.reassembled_matrix);
        scene.step(3);
        scene.converge();
        {
            LiveScene fresh(doc.mesh(), key_lighting(), options_for(config));
            fresh.converge();
            EXPECT_LT(relative_difference(scene.phi(), fresh.phi()), 1e-4) << config.name << " paint";
            EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << config.name << " paint";
        }
        // All values on the kept pattern.
        scene.apply_change(doc.mesh(), doc.apply(SetMaterialOp{material_preset("skin2"), std::nullopt}));
        scene.converge();
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << config.name << " set material";
        // A cut: new pattern, warm start through the vertex map.
        PlaneCutOp cut;
        cut.plane = {Eigen::Vector3d(1, 0.3, 0.2), 0.6};
        scene.apply_change(doc.mesh(), doc.apply(cut));
        scene.step(2);
        scene.converge();
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << config.name << " cut";
        EXPECT_EQ(scene.backend(), config.backend) << config.name << ": " << scene.gpu_fallback_reason();
        EXPECT_EQ(scene.method_fallback_reason(), "") << config.name;
        expect_description_names_the_method(scene, config);
    }
}

// Large enough for a hierarchy of several levels: painting then updates the coarse Galerkin rows in
// place (MultigridPreconditioner::update_values) instead of the one-level rebuild of the small cube; on
// the GPU the recomputed rows of every level are uploaded (GpuMultigridPreconditioner::update_values).
TEST(LiveSolver, MultigridOnSeveralLevelsFollowsPaintToTheFreshSolution) {
    for (const Config& config : {kConfigs[1], kConfigs[5]}) {
        Document doc(testing::make_cube_mesh(14), material_preset("marble"));
        LiveScene scene(doc.mesh(), key_lighting(), options_for(config));
        scene.converge();
        for (int i = 0; i < 3; ++i) {
            const SceneUpdate update = scene.apply_change(
                doc.mesh(), doc.apply(paint_at({0.2 + 0.3 * i, 0.5, 0.4}, i % 2 ? "skin1" : "ketchup")));
            ASSERT_FALSE(update.updated_rows.empty());
            scene.step(2);
        }
        const FrameReport report = scene.converge();
        EXPECT_LT(report.total_iterations(), 60) << config.name;  // a preconditioner that follows the paint stays strong
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << config.name;
        EXPECT_EQ(scene.backend(), config.backend) << config.name << ": " << scene.gpu_fallback_reason();
        expect_description_names_the_method(scene, config);
    }
}

// sqrt(sum (a - b)^2 / sum b^2) per channel: the relative error measure of tests/multires and
// bench/multires_bench.cpp.
std::array<double, 3> relative_l2_error(const std::vector<std::array<double, 3>>& a,
                                        const std::vector<std::array<double, 3>>& b) {
    EXPECT_EQ(a.size(), b.size());
    std::array<double, 3> error{};
    for (int c = 0; c < 3; ++c) {
        double e = 0, norm = 0;
        for (size_t v = 0; v < std::min(a.size(), b.size()); ++v) {
            e += (a[v][c] - b[v][c]) * (a[v][c] - b[v][c]);
            norm += b[v][c] * b[v][c];
        }
        error[c] = std::sqrt(e / norm);
    }
    return error;
}

// The editor's frame after a 10-degree light turn: multigrid CG warm-started from the previous light's
// solution (MultigridFrameSolver::set_right_hand_side) is within 1% of the new converged solution
// after one frame of budget 8 (two V-cycles) everywhere, and after one V-cycle (budget 4) in the l2
// sense, measured against a converged reference (its own estimate lags one update and still
// describes the phi before it).
TEST(LiveSolver, MultigridIsWithinOnePercentOfATurnedLightAfterOneFrame) {
    Document doc(testing::make_cube_mesh(14), material_preset("marble"));
    Lighting turned = key_lighting();
    turned.lights[0].vector = Eigen::AngleAxisd(10 * M_PI / 180, Eigen::Vector3d::UnitZ()) * turned.lights[0].vector;
    LiveScene reference(doc.mesh(), turned, options_for(kConfigs[0]));
    reference.converge();
    for (const auto& [budget, vcycles, config] :
         {std::tuple{8, 2, kConfigs[1]}, std::tuple{4, 1, kConfigs[1]}, std::tuple{8, 2, kConfigs[5]}}) {
        LiveSceneOptions o = options_for(config);
        o.relative_tolerance = 1e-3;  // the editor's frames
        LiveScene scene(doc.mesh(), key_lighting(), o);
        scene.converge();
        for (const double before : relative_l2_error(scene.phi(), reference.phi()))
            ASSERT_GT(before, 5e-2) << "the turn must change phi";
        scene.set_lighting(turned);
        const FrameReport frame = scene.step(budget);
        for (int c = 0; c < 3; ++c) EXPECT_EQ(frame.iterations[c], vcycles);
        const std::array<double, 3> after = relative_l2_error(scene.phi(), reference.phi());
        for (int c = 0; c < 3; ++c) EXPECT_LT(after[c], 1e-2) << config.name << " budget " << budget << ", channel " << c;
        if (vcycles == 2) {
            EXPECT_LT(relative_difference(scene.phi(), reference.phi()), 1e-2) << config.name;
        }
    }
}

// Painting then running frames (no converge()) reaches what a fresh scene of the painted document gives.
TEST(LiveSolver, MultigridFramesAfterPaintingEqualAFreshScene) {
    for (const auto& [n, config] : {std::pair{7, kConfigs[1]}, std::pair{14, kConfigs[1]}, std::pair{7, kConfigs[5]},
                                    std::pair{14, kConfigs[5]}}) {  // one level (its exact solve refactorised) and several
        Document doc(testing::make_cube_mesh(n), material_preset("marble"));
        LiveScene scene(doc.mesh(), key_lighting(), options_for(config));
        scene.converge();
        scene.apply_change(doc.mesh(), doc.apply(paint_at({0.5, 0.4, 0.5}, "ketchup")));
        scene.apply_change(doc.mesh(), doc.apply(paint_at({0.3, 0.6, 0.7}, "skin1")));
        FrameReport frame;
        int frames = 0;
        for (; frames < 200 && !frame.converged; ++frames) {
            frame = scene.step(8);
            for (int c = 0; c < 3; ++c) EXPECT_LE(frame.iterations[c], 2);
        }
        EXPECT_TRUE(frame.converged) << n << " " << config.name;
        LiveScene fresh(doc.mesh(), key_lighting(), options_for(config));
        fresh.converge();
        EXPECT_LT(relative_difference(scene.phi(), fresh.phi()), 1e-4) << n << " " << config.name;
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << n << " " << config.name;
    }
}

// The multires solvers keep their hierarchy across frames: paint after a whole-object material must
// still reach every level (the value change must not swallow later row changes).
TEST(LiveSolver, MultiresFollowsPaintAfterAMaterialChange) {
    for (const Config& config : {kConfigs[3], kConfigs[4]}) {
        Document doc(testing::make_cube_mesh(7), material_preset("marble"));
        LiveScene scene(doc.mesh(), key_lighting(), options_for(config));
        scene.converge();
        scene.apply_change(doc.mesh(), doc.apply(SetMaterialOp{material_preset("skin2"), std::nullopt}));
        scene.step(3);
        for (const Eigen::Vector3d& at : {Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(0.2, 0.7, 0.6)}) {
            const SceneUpdate update = scene.apply_change(doc.mesh(), doc.apply(paint_at(at, "ketchup")));
            ASSERT_FALSE(update.updated_rows.empty());
            scene.step(3);
        }
        scene.converge();
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << config.name;
        EXPECT_EQ(scene.backend(), config.backend) << config.name << ": " << scene.gpu_fallback_reason();
    }
}

// After a cut the multires method keeps the phi carried through the cut and lets its coarse-to-fine
// pass correct it (MultiresSolver::set_warm_start) instead of starting again from zero: its first frame
// is closer than a fresh scene's (the cold pass) and than Jacobi CG's from the same carried phi, and
// the GPU backend starts from the same corrected vector (computed on the host hierarchy).
TEST(LiveSolver, MultiresCorrectsThePhiCarriedThroughACut) {
    PlaneCutOp cut;
    cut.plane = {Eigen::Vector3d(1, 0.3, 0.2).normalized(), 0.55};
    auto first_frame_error = [&](const Config& config, bool cut_first) {
        Document doc(testing::make_cube_mesh(14), material_preset("marble"));
        std::optional<LiveScene> scene;
        if (cut_first) {
            doc.apply(cut);
            scene.emplace(doc.mesh(), key_lighting(), options_for(config));  // phi = 0: a cold start
        } else {
            scene.emplace(doc.mesh(), key_lighting(), options_for(config));
            scene->converge();
            const SceneUpdate update = scene->apply_change(doc.mesh(), doc.apply(cut));
            EXPECT_TRUE(update.warm_start);
        }
        scene->step(1);
        EXPECT_EQ(scene->backend(), config.backend) << config.name << ": " << scene->gpu_fallback_reason();
        EXPECT_EQ(scene->method_fallback_reason(), "") << config.name;
        return relative_difference(scene->phi(), reference_phi(doc.mesh()));
    };
    const double jacobi = first_frame_error(kConfigs[0], false);
    const double cold = first_frame_error(kConfigs[3], true);
    const double corrected = first_frame_error(kConfigs[3], false);
    Config gpu = kConfigs[4];
    gpu.tolerance = 1e-5;  // float on a volume of 16,464 tets: 1e-6 is below what its CG can confirm
    const double corrected_gpu = first_frame_error(gpu, false);
    EXPECT_LT(corrected, jacobi);
    EXPECT_LT(corrected, cold);
    // float on the device against double on the host, one CG iteration from the same start.
    EXPECT_NEAR(corrected_gpu, corrected, 1e-3 + 0.05 * corrected);
}

// The CPU multigrid CG rebuilds its hierarchy around a cut too (then its Galerkin operators), and
// converges to the same phi.
TEST(LiveSolver, MultigridRebuildsItsHierarchyAroundACut) {
    PlaneCutOp cut;
    cut.plane = {Eigen::Vector3d(1, 0.3, 0.2).normalized(), 0.55};
    // CPU: built with the scene. GPU: at the first frame, and after the cut rebuilt on the host at once
    // (hierarchy and Galerkin operators) for the device solver built at the next frame.
    for (const Config& config : {kConfigs[1], kConfigs[5]}) {
        Document doc(testing::make_cube_mesh(14), material_preset("marble"));
        LiveScene scene(doc.mesh(), key_lighting(), options_for(config));
        scene.converge();
        ASSERT_GE(scene.multires_levels().size(), 2u) << config.name;
        EXPECT_EQ(scene.multires_levels()[0][1], -1) << config.name;
        EXPECT_EQ(scene.multigrid_copied_rows(), 0) << config.name;
        scene.apply_change(doc.mesh(), doc.apply(cut));
        // The Galerkin rows away from the cut are copied from the operators before it.
        EXPECT_GT(scene.multigrid_copied_rows(), 0) << config.name;
        auto levels = scene.multires_levels();
        ASSERT_GE(levels.size(), 2u) << config.name;
        EXPECT_EQ(levels[0][0], static_cast<int64_t>(doc.mesh().vertex_count())) << config.name;
        EXPECT_GT(levels[0][1], 0) << config.name;
        EXPECT_LT(levels[0][1], levels[0][0] / 2) << config.name;
        const int64_t copied = scene.multigrid_copied_rows();
        scene.converge();
        EXPECT_EQ(scene.multires_levels(), levels) << config.name;  // the solver runs on that hierarchy
        EXPECT_EQ(scene.multigrid_copied_rows(), copied) << config.name;  // and those operators
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << config.name;
        EXPECT_EQ(scene.method_fallback_reason(), "") << config.name;
        // A relaxation moves vertices on the same graph: the hierarchy is kept and its values follow.
        scene.apply_change(doc.mesh(), doc.apply(RelaxOp{cut.plane, RelaxSettings{5, 0.3, 0.5}}));
        scene.converge();
        EXPECT_EQ(scene.multires_levels(), levels) << config.name;
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << config.name;
        // Painting before the next GPU frame makes a hierarchy waiting for it (rebuilt around a second
        // cut) stale, its level 0 having the old values: the device solver is then built afresh.
        PlaneCutOp second = cut;
        second.plane.offset = 0.45;
        scene.apply_change(doc.mesh(), doc.apply(second));
        scene.apply_change(doc.mesh(), doc.apply(paint_at({0.3, 0.5, 0.5}, "ketchup")));
        scene.converge();
        levels = scene.multires_levels();
        ASSERT_GE(levels.size(), 2u) << config.name;
        if (config.backend == LiveBackend::Gpu) {
            EXPECT_EQ(levels[0][1], -1) << config.name;
            EXPECT_EQ(scene.multigrid_copied_rows(), 0) << config.name;
        } else {
            EXPECT_GT(levels[0][1], 0) << config.name;  // around the second cut, kept through the paint
        }
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << config.name;
    }
}

// The multires method rebuilds its hierarchy from the previous one after an edit that says where the
// vertices went: after a cut (removal or exact) or its undo only around the rows the cut changed is
// the selection made again; a relaxation (same graph) keeps the hierarchy and updates its values. The
// solution stays right throughout.
TEST(LiveSolver, MultiresRebuildsItsHierarchyAroundACut) {
    PlaneCutOp cut;
    cut.plane = {Eigen::Vector3d(1, 0.3, 0.2).normalized(), 0.55};
    Document doc(testing::make_cube_mesh(14), material_preset("marble"));
    LiveScene scene(doc.mesh(), key_lighting(), options_for(kConfigs[3]));
    auto levels = scene.multires_levels();
    ASSERT_GE(levels.size(), 2u);
    EXPECT_EQ(levels[0][1], -1);  // built from scratch
    scene.converge();
    scene.apply_change(doc.mesh(), doc.apply(cut));
    levels = scene.multires_levels();
    ASSERT_GE(levels.size(), 2u);
    EXPECT_EQ(levels[0][0], static_cast<int64_t>(doc.mesh().vertex_count()));
    EXPECT_GT(levels[0][1], 0);
    EXPECT_LT(levels[0][1], levels[0][0] / 2);
    scene.converge();
    EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4);
    scene.apply_change(doc.mesh(), doc.apply(RelaxOp{cut.plane, RelaxSettings{5, 0.3, 0.5}}));
    EXPECT_EQ(scene.multires_levels(), levels);  // the same graph: the hierarchy is kept
    scene.converge();
    EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4);
    // An exact cut maps its kept vertices through their origins; the vertices it creates are new rows.
    PlaneCutOp exact;
    exact.plane = {Eigen::Vector3d(0, 1, 0.1).normalized(), 0.8};
    exact.exact = true;
    const size_t before_exact = doc.mesh().vertex_count();
    scene.apply_change(doc.mesh(), doc.apply(exact));
    levels = scene.multires_levels();
    ASSERT_GE(levels.size(), 2u);
    EXPECT_GT(levels[0][1], 0);
    EXPECT_LT(levels[0][1], static_cast<int64_t>(before_exact) / 2);
    scene.converge();
    EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4);
    // Undoing the exact cut maps its kept vertices back (Document::undo reports the map): a warm start
    // and a rebuild around the cut again.
    const SceneUpdate undone = scene.apply_change(doc.mesh(), *doc.undo());
    EXPECT_TRUE(undone.warm_start);
    levels = scene.multires_levels();
    ASSERT_GE(levels.size(), 2u);
    EXPECT_EQ(levels[0][0], static_cast<int64_t>(before_exact));
    EXPECT_GT(levels[0][1], 0);
    EXPECT_LT(levels[0][1], levels[0][0] / 2);
    scene.converge();
    EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4);
    EXPECT_EQ(scene.method_fallback_reason(), "");
}

// Hands `change` (just made on `doc`) to `scene`, which must keep its warm start, and runs one frame of
// it and of a fresh scene on the edited volume: their errors against the converged solution.
struct FirstFrameErrors {
    double warm = 0, cold = 0;
};
FirstFrameErrors first_frame_errors(const Document& doc, LiveScene& scene, const ChangeReport& change,
                                    const Config& config) {
    const SceneUpdate update = scene.apply_change(doc.mesh(), change);
    EXPECT_TRUE(update.warm_start) << change.name;
    scene.step(1);
    LiveScene fresh(doc.mesh(), key_lighting(), options_for(config));
    fresh.step(1);
    const std::vector<std::array<double, 3>> reference = reference_phi(doc.mesh());
    return {relative_difference(scene.phi(), reference), relative_difference(fresh.phi(), reference)};
}

// Undoing a cut keeps phi on the vertices the cut kept, and the restored third of the cube starts from
// the values at its border (extend_to_unknown_vertices): 0.40 against a fresh scene's 0.75 after one
// frame here; from zero it was 0.56.
TEST(LiveSolver, UndoingACutKeepsTheWarmStart) {
    PlaneCutOp cut;
    cut.plane = {Eigen::Vector3d(1, 0.3, 0.2).normalized(), 0.7};
    Document doc(testing::make_cube_mesh(14), material_preset("marble"));
    LiveScene scene(doc.mesh(), key_lighting(), options_for(kConfigs[0]));
    scene.apply_change(doc.mesh(), doc.apply(cut));
    scene.converge();
    const FirstFrameErrors errors = first_frame_errors(doc, scene, *doc.undo(), kConfigs[0]);
    EXPECT_LT(errors.warm, 0.65 * errors.cold);
}

// Undoing a weld maps the welded volume's vertices back onto the fractured one (the crack copies it
// merged start from their neighbours' values): 0.23 against 0.73 after one frame here.
TEST(LiveSolver, UndoingAWeldKeepsTheWarmStart) {
    Document doc(testing::make_cube_mesh(14), material_preset("marble"));
    FractureOp fracture;
    fracture.seeds = {Eigen::Vector3d(0.3, 0.5, 0.5), Eigen::Vector3d(0.7, 0.5, 0.5)};
    doc.apply(fracture);
    doc.apply(WeldOp{1e-9});
    LiveScene scene(doc.mesh(), key_lighting(), options_for(kConfigs[0]));
    scene.converge();
    const FirstFrameErrors errors = first_frame_errors(doc, scene, *doc.undo(), kConfigs[0]);
    EXPECT_LT(errors.warm, 0.5 * errors.cold);
}

// A fracture keeps every vertex and appends crack copies and wall vertices (their origins place them):
// the scene keeps its warm start, so its first frame is closer than a fresh scene's, and the multires
// and multigrid hierarchies are rebuilt around the cracks. Undoing it maps the kept vertices back. The cracks become
// boundary (light leaves through them), so the carried phi is off by 0.43 near them here and the
// gain is Jacobi CG's (0.39 against 0.66 after one frame) more than multires' (0.18 against 0.24),
// whose first frame runs the coarse pass either way. (With wall vertices at their edges' midpoints
// instead of their crossing parameters the carried phi was 0.44 off and multires' first frame 0.21.)
TEST(LiveSolver, AFractureKeepsTheWarmStartAndRebuildsTheHierarchyAroundTheCracks) {
    FractureOp fracture;
    fracture.seeds = {Eigen::Vector3d(0.3, 0.4, 0.5), Eigen::Vector3d(0.7, 0.5, 0.45), Eigen::Vector3d(0.5, 0.8, 0.6)};
    for (const Config& config : {kConfigs[0], kConfigs[1], kConfigs[3]}) {
        Document doc(testing::make_cube_mesh(14), material_preset("marble"));
        LiveScene scene(doc.mesh(), key_lighting(), options_for(config));
        scene.converge();
        const size_t before = doc.mesh().vertex_count();
        const FirstFrameErrors errors = first_frame_errors(doc, scene, doc.apply(fracture), config);
        EXPECT_LT(errors.warm, (config.method == LiveMethod::JacobiCg ? 0.75 : 1.0) * errors.cold) << config.name;
        if (config.method != LiveMethod::JacobiCg) {
            // The walls cross the whole cube, so they touch more than half of its rows, not all.
            const auto levels = scene.multires_levels();
            ASSERT_GE(levels.size(), 2u);
            EXPECT_EQ(levels[0][0], static_cast<int64_t>(doc.mesh().vertex_count()));
            EXPECT_GT(levels[0][1], static_cast<int64_t>(doc.mesh().vertex_count() - before));  // and the new ones
            EXPECT_LT(levels[0][1], 3 * levels[0][0] / 4);
        }
        scene.converge();
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << config.name;

        const SceneUpdate undone = scene.apply_change(doc.mesh(), *doc.undo());
        EXPECT_TRUE(undone.warm_start) << config.name;
        if (config.method != LiveMethod::JacobiCg) {
            const auto levels = scene.multires_levels();
            ASSERT_GE(levels.size(), 2u);
            EXPECT_EQ(levels[0][0], static_cast<int64_t>(before));
            EXPECT_GT(levels[0][1], 0);
            EXPECT_LT(levels[0][1], 3 * levels[0][0] / 4);
        }
        scene.converge();
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << config.name;
        EXPECT_EQ(scene.method_fallback_reason(), "") << config.name;
    }
}

TEST(LiveSolver, AFailingGpuFallsBackToTheCpuWithAReason) {
    for (const Config& config : {kConfigs[2], kConfigs[4], kConfigs[5]}) {
        Document doc(testing::make_cube_mesh(6), material_preset("marble"));
        setenv("WAXWORK_GPU_FORCE_FAIL", "1", 1);
        LiveSceneOptions o = options_for(config);
        LiveScene scene(doc.mesh(), key_lighting(), o);
        FrameReport frame = scene.step(5);
        unsetenv("WAXWORK_GPU_FORCE_FAIL");
        EXPECT_GT(frame.total_iterations(), 0) << config.name;  // the frame was solved on the CPU instead
        EXPECT_EQ(scene.backend(), LiveBackend::Cpu) << config.name;
        const std::string reason = scene.gpu_fallback_reason();
        EXPECT_NE(reason.find("WAXWORK_GPU_FORCE_FAIL"), std::string::npos) << config.name << ": " << reason;
        EXPECT_NE(scene.solver_description().find("CPU"), std::string::npos) << config.name;
        // The method stays: multires falls back to the CPU multires solver, not to Jacobi CG.
        if (config.method == LiveMethod::Multires) {
            EXPECT_NE(scene.solver_description().find("multires"), std::string::npos) << scene.solver_description();
        }
        if (config.method == LiveMethod::MultigridCg) {
            EXPECT_NE(scene.solver_description().find("CPU multigrid"), std::string::npos) << scene.solver_description();
        }
        scene.converge();
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << config.name;
        // Painting after the fallback keeps working on the CPU.
        scene.apply_change(doc.mesh(), doc.apply(paint_at({0.5, 0.5, 0.5}, "ketchup")));
        scene.converge();
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4) << config.name;
    }
}

// On a volume of extreme slivers the V-cycle's row-sum lumped setup fails. By default the multigrid
// rebuilds it with absolute lumping and keeps running; when that fallback is switched off the setup
// throws, and the live solver solves with Jacobi CG instead and says why. Both reach the same phi.
TEST(LiveSolver, MultigridThatCannotBeBuiltFallsBackToJacobiWithAReason) {
    TetMesh mesh = make_box_mesh({10, 10, 10}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(1));
    flatten_into_slivers(mesh, build_connectivity(mesh), 6, 1e-5);
    Document doc(mesh, material_preset("marble"));
    const auto reference = reference_phi(doc.mesh());
    for (const bool absolute_fallback : {true, false}) {
        LiveSceneOptions o = options_for(kConfigs[1]);  // CPU multigrid CG
        o.multigrid.fall_back_to_absolute = absolute_fallback;
        LiveScene scene(doc.mesh(), key_lighting(), o);
        for (int i = 0; i < 3; ++i) scene.step(8);
        scene.converge();
        const std::string description = scene.solver_description();
        if (absolute_fallback) {
            EXPECT_EQ(scene.method_fallback_reason(), "");
            EXPECT_NE(description.find("multigrid"), std::string::npos) << description;
            EXPECT_NE(description.find("absolute lumping"), std::string::npos) << description;
        } else {
            EXPECT_NE(scene.method_fallback_reason().find("not positive definite"), std::string::npos)
                << scene.method_fallback_reason();
            EXPECT_NE(description.find("Jacobi"), std::string::npos) << description;
        }
        EXPECT_LT(relative_difference(scene.phi(), reference), 1e-4) << "absolute fallback " << absolute_fallback;
        // Edits keep working (a paint stroke updates whichever solver runs).
        scene.apply_change(doc.mesh(), doc.apply(paint_at({0.5, 0.5, 0.5}, "ketchup")));
        scene.converge();
        EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh())), 1e-4);
        doc.undo();
    }
}

// The same on the GPU backend: the V-cycle built with absolute lumping runs on the device; one that
// cannot be built leaves GPU Jacobi CG solving (the backend stays: the system is at fault, not the
// driver). No accuracy bound against the double solution here: these slivers' matrix stored in float
// is another system at the 1e-4 level (every float solver stops there), which is not what this tests.
TEST(LiveSolver, GpuMultigridThatCannotBeBuiltFallsBackToGpuJacobiWithAReason) {
    TetMesh mesh = make_box_mesh({10, 10, 10}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(1));
    flatten_into_slivers(mesh, build_connectivity(mesh), 6, 1e-5);
    Document doc(mesh, material_preset("marble"));
    for (const bool absolute_fallback : {true, false}) {
        LiveSceneOptions o = options_for(kConfigs[5]);
        o.multigrid.fall_back_to_absolute = absolute_fallback;
        LiveScene scene(doc.mesh(), key_lighting(), o);
        FrameReport frame;
        for (int i = 0; i < 3; ++i) frame = scene.step(8);
        EXPECT_EQ(scene.backend(), LiveBackend::Gpu) << scene.gpu_fallback_reason();
        const std::string description = scene.solver_description();
        if (absolute_fallback) {
            EXPECT_EQ(scene.method_fallback_reason(), "");
            EXPECT_NE(description.find("GPU multigrid"), std::string::npos) << description;
            EXPECT_NE(description.find("absolute lumping"), std::string::npos) << description;
        } else {
            EXPECT_NE(scene.method_fallback_reason().find("not positive definite"), std::string::npos)
                << scene.method_fallback_reason();
            EXPECT_NE(description.find("GPU Jacobi"), std::string::npos) << description;
        }
        EXPECT_GT(frame.total_iterations(), 0) << "absolute fallback " << absolute_fallback;
        for (const auto& v : scene.phi())
            for (double x : v) ASSERT_TRUE(std::isfinite(x));
    }
}

// A tolerance below what float can reach on a volume of slivers: every GPU method (Jacobi CG, the
// multires, the multigrid CG) stops at its precision floor, and converge() finishes in double on the
// CPU from the GPU's phi, says why, and reaches what the CPU backend reaches alone. A CPU solve asked
// for less than double's floor names the floor instead.
TEST(LiveSolver, ConvergingBelowTheFloatFloorOnTheGpuFinishesInDoubleOnTheCpu) {
    TetMesh mesh = make_box_mesh({10, 10, 10}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(1));
    flatten_into_slivers(mesh, build_connectivity(mesh), 6, 1e-5);
    Document doc(mesh, material_preset("marble"));
    Config cpu = kConfigs[0];
    cpu.tolerance = 1e-8;
    LiveScene on_cpu(doc.mesh(), key_lighting(), options_for(cpu));
    ASSERT_TRUE(on_cpu.converge().converged);
    for (Config gpu : {kConfigs[2], kConfigs[4], kConfigs[5]}) {
        SCOPED_TRACE(gpu.name);
        gpu.tolerance = 1e-8;
        LiveScene scene(doc.mesh(), key_lighting(), options_for(gpu));
        ASSERT_EQ(scene.backend(), LiveBackend::Gpu) << scene.gpu_fallback_reason();
        const FrameReport report = scene.converge();
        EXPECT_TRUE(report.converged);
        EXPECT_LE(report.max_error(), 1e-8);
        EXPECT_EQ(scene.backend(), LiveBackend::Cpu);
        const std::string reason = scene.gpu_fallback_reason();
        EXPECT_NE(reason.find("float stopped at an estimated relative error"), std::string::npos) << reason;
        EXPECT_NE(reason.find("precision floor"), std::string::npos) << reason;
        EXPECT_LT(relative_difference(scene.phi(), on_cpu.phi()), 1e-6);
    }
    cpu.tolerance = 1e-17;
    LiveScene below_double(doc.mesh(), key_lighting(), options_for(cpu));
    try {
        below_double.converge();
        ADD_FAILURE() << "double CG reached 1e-17";
    } catch (const AlgorithmError& error) {
        EXPECT_NE(std::string(error.what()).find("the precision floor of CPU Jacobi CG"), std::string::npos)
            << error.what();
    }
}

// The renderer reading E from the GPU solver's buffer draws what it draws from the CPU's E.
TEST(LiveSolver, DeviceRadianceDrawsWhatTheCpuRadianceDraws) {
    // Every device solver: Jacobi CG, the multigrid CG and the multires hierarchy keep phi resident.
    for (const Config& config : {kConfigs[2], kConfigs[4], kConfigs[5]}) {
        HeadlessGlContext context;
        Document doc(testing::make_cube_mesh(7), material_preset("marble"));
        doc.apply(paint_at({0.5, 0.5, 0.9}, "skin1"));
        LiveSceneOptions o = options_for(config);
        o.gl_context = borrow_headless_solver_context(context);
        LiveScene scene(doc.mesh(), key_lighting(), o);
        scene.converge();
        ASSERT_EQ(scene.backend(), LiveBackend::Gpu) << config.name << ": " << scene.gpu_fallback_reason();
        ImageSettings settings;
        settings.width = 96;
        settings.height = 72;
        const SolvedScene solved = scene.solved_scene();
        // The cube's edges are creases: its corners and edges have copies with their own q, whose E
        // the device computes as well.
        ASSERT_FALSE(solved.shading.split_copies.empty());
        SurfaceRenderInput input = make_render_input(doc.mesh(), solved, key_lighting(), settings);
        const std::shared_ptr<const GpuBuffer> device = scene.device_radiance();
        ASSERT_TRUE(device);
        context.make_current();
        const std::vector<float> e = device->download<float>();
        ASSERT_EQ(e.size(), 3 * input.positions.size());
        float largest = 0;
        for (size_t i = 0; i < input.positions.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                largest = std::max(largest, input.radiance_factor[i][c]);
                EXPECT_NEAR(e[3 * i + c], input.radiance_factor[i][c], 1e-5f * std::abs(input.radiance_factor[i][c]) + 1e-7f);
            }
        EXPECT_GT(largest, 0);

        // The editor's GPU tick: the read-back copy of the device E feeds the automatic exposure and
        // the render input, with no E computed from phi on the CPU; it is the buffer, value for value.
        std::vector<std::array<float, 3>> host_copy;
        ASSERT_TRUE(scene.device_radiance(&host_copy));
        ASSERT_EQ(host_copy.size(), input.positions.size());
        const SolvedScene without_e = scene.solved_scene(/*with_radiance=*/false);
        EXPECT_TRUE(without_e.radiance_factor.empty());
        const SurfaceRenderInput from_copy = make_render_input(doc.mesh(), without_e, key_lighting(), settings, &host_copy);
        for (size_t i = 0; i < host_copy.size(); ++i)
            for (size_t c = 0; c < 3; ++c) {
                EXPECT_EQ(host_copy[i][c], e[3 * i + c]);
                EXPECT_EQ(from_copy.radiance_factor[i][c], host_copy[i][c]);
            }
        EXPECT_NEAR(automatic_exposure(from_copy), automatic_exposure(input), 1e-4f * automatic_exposure(input));
        // A copy that does not match the surface is refused, with the counts.
        host_copy.pop_back();
        try {
            make_render_input(doc.mesh(), without_e, key_lighting(), settings, &host_copy);
            ADD_FAILURE() << "a short radiance copy was accepted";
        } catch (const InvalidArgumentError& error) {
            EXPECT_NE(std::string(error.what()).find("shading vertices"), std::string::npos) << error.what();
        }
        // Without a copy, a scene solved without E is refused too (it has no E to draw).
        EXPECT_THROW(make_render_input(doc.mesh(), without_e, key_lighting(), settings), InvalidArgumentError);

        SurfaceRenderer renderer(context.gl());
        const Image from_cpu = renderer.render(input);
        input.device_radiance = device;
        const Image from_device = renderer.render(input);
        int difference = 0;
        for (size_t i = 0; i < from_cpu.rgba.size(); ++i)
            difference = std::max(difference, std::abs(int(from_cpu.rgba[i]) - int(from_device.rgba[i])));
        EXPECT_LE(difference, 1) << config.name;
        // The buffer is really what is drawn: a black one gives another image.
        const std::vector<float> zeros(e.size(), 0.0f);
        input.device_radiance = std::make_shared<GpuBuffer>(context.gl(), zeros.size() * sizeof(float), zeros.data());
        const Image black = renderer.render(input);
        difference = 0;
        for (size_t i = 0; i < from_cpu.rgba.size(); ++i)
            difference = std::max(difference, std::abs(int(from_cpu.rgba[i]) - int(black.rgba[i])));
        EXPECT_GT(difference, 40) << config.name;

        // The CPU backends have no device buffer.
        LiveScene cpu(doc.mesh(), key_lighting(), options_for(kConfigs[0]));
        cpu.converge();
        EXPECT_FALSE(cpu.device_radiance());
    }
}

// A cut by a bent stroke seen edge-on from a random side, through the volume's middle, that cuts away
// the side with fewer vertices, exact or relaxed.
StrokeCutOp random_stroke_cut(const std::vector<Eigen::Vector3d>& world, std::mt19937& rng) {
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const Eigen::Vector3d n = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
    const Eigen::Vector3d across = n.unitOrthogonal(), along = n.cross(across);
    Eigen::Vector3d middle = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& x : world) middle += x / static_cast<double>(world.size());
    middle += 0.25 * n;
    StrokeCutOp cut;
    cut.stroke.eye = middle + 3.0 * across;
    cut.stroke.view_direction = -across;
    cut.stroke.points = {middle - along, middle + 0.1 * unit(rng) * n, middle + along};
    cut.exact = rng() % 2;
    cut.relax.iterations = cut.exact ? 0 : 5;
    const StrokeCut surface(cut.stroke.eye, cut.stroke.view_direction, cut.stroke.points);
    size_t cut_away = 0;
    for (const Eigen::Vector3d& x : world) cut_away += surface.side(x) > 0 ? 1 : 0;
    cut.stroke.flip = 2 * cut_away > world.size();
    return cut;
}

// One random edit for `doc`, valid by construction (a cut keeps most of the volume, seeds and paint
// points lie at vertices). `last_plane`: the last plane cut's plane, for relaxing towards it. With
// `strokes`, half the cuts are stroke cuts (random_stroke_cut).
EditOperation random_edit(const Document& doc, std::mt19937& rng, std::optional<PlaneSurface>& last_plane,
                          bool strokes) {
    const TetMesh& mesh = doc.mesh();
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    const auto random_vertex = [&] { return world[std::uniform_int_distribution<size_t>(0, world.size() - 1)(rng)]; };
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (;;) {
        switch (std::uniform_int_distribution<int>(0, 6)(rng)) {
        case 0: {
            return testing::paint_at(random_vertex(), rng() % 2 ? "ketchup" : "skin1");
        }
        case 1: {
            if (mesh.tet_count() < 3000) continue;  // keep enough volume for the later edits
            if (strokes && rng() % 2) return random_stroke_cut(world, rng);
            // Cut away the 20% of vertices furthest along a random direction.
            PlaneCutOp cut;
            cut.plane.normal = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
            std::vector<double> heights;
            for (const Eigen::Vector3d& x : world) heights.push_back(cut.plane.normal.dot(x));
            std::nth_element(heights.begin(), heights.begin() + heights.size() * 8 / 10, heights.end());
            cut.plane.offset = heights[heights.size() * 8 / 10];
            cut.exact = rng() % 2;
            cut.relax.iterations = cut.exact ? 0 : 5;
            last_plane = cut.plane;
            return cut;
        }
        case 2: {
            if (!last_plane) continue;
            return RelaxOp{*last_plane, RelaxSettings{3, 0.2, 0.5}};
        }
        case 3: {
            if (mesh.piece_transforms.size() > 3) continue;
            FractureOp fracture;
            fracture.seeds = {random_vertex(), random_vertex()};
            fracture.exact = rng() % 2;
            return fracture;
        }
        case 4: {
            if (mesh.piece_transforms.size() < 2) continue;
            MovePieceOp move;
            move.piece = static_cast<int>(rng() % mesh.piece_transforms.size());
            move.transform = mesh.piece_transforms[static_cast<size_t>(move.piece)];
            move.transform.translation += 0.05 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
            return move;
        }
        case 5:
            if (mesh.piece_transforms.size() < 2) continue;
            // Weld the pieces that touch, or drop the parts under 30% of the volume (the smaller pieces).
            if (rng() % 2) return RemoveFragmentsOp{0.3};
            return WeldOp{1e-9};
        default:
            return SetMaterialOp{material_preset(rng() % 2 ? "marble" : "skin2"), std::nullopt};
        }
    }
}

// A positive whole number from the environment, else `fallback` (the soak runs below).
int environment_count(const char* name, int fallback) {
    const char* text = std::getenv(name);
    const int value = text ? std::atoi(text) : 0;
    return value > 0 ? value : fallback;
}

// Random sequences of edits, undos and redos with a few frames between them, as a user makes them: the
// edits' maps and origins carry phi, the hierarchies and Galerkin operators are rebuilt or updated
// around them (multires, multigrid, on both backends), and every method still converges to what a
// fresh scene gives on the volume reached, on its backend and without falling back. Seed 17 found an
// exact fracture whose wall passed 4e-9 from a vertex of a relaxed cut's cross-section: split there,
// the tets kept a 3e-6 degree angle and Jacobi CG could not reach the test's 1e-9 (the snap at a
// hair's breadth in tetops/exact_cut.h). Seeds 17 and 570 (20 steps) found crossings 1e-3 and 3e-6 of
// an edge from a stuck vertex, 0.014 and 0.004 degrees when split, on which GPU CG in float stalled at
// 7e-5 and 6e-4; the snap reaches 1e-3 of an edge since. The GPU methods solve in float, whose floor
// is near 1e-6 on clean meshes, so they converge to 1e-4. That bound is on the D-norm error (conjugate_gradient.h);
// the max-norm difference checked here can be 50 times larger (seed 38 after 14 steps: 5e-3, near
// slivers of 1.2 degrees and in specks of 6 vertices that no light reaches), so they are compared
// within 2e-2: a matrix row or light the device did not get after an edit is off by far more. Longer soaks:
// WAXWORK_EDIT_FIRST_SEED, WAXWORK_EDIT_SEQUENCES (20 per CPU method, a quarter of that per GPU method;
// 8 with stroke cuts) and WAXWORK_EDIT_STEPS (10). The seeds above are those of the plane-cut mix.
// Now and then the crease angle changes too (the View panel's slider: new fans, new sources), drawn
// from a second generator so that the edits of a seed stay those the notes above name.
void check_random_edit_sequences(bool strokes, int default_sequences) {
    const int first_seed = environment_count("WAXWORK_EDIT_FIRST_SEED", 1);
    const int sequences = environment_count("WAXWORK_EDIT_SEQUENCES", default_sequences);
    const int steps = environment_count("WAXWORK_EDIT_STEPS", 10);
    for (Config config : kConfigs) {
        const bool gpu = config.backend == LiveBackend::Gpu;
        if (gpu) config.tolerance = 1e-4;
        int skipped = 0, run = 0;  // sequences in which the multires coarse pass skipped a level
        for (int seed = first_seed; seed < first_seed + (gpu ? std::max(1, sequences / 4) : sequences); ++seed, ++run) {
            bool skipped_here = false;
            std::mt19937 rng(static_cast<uint32_t>(seed));
            std::mt19937 crease_rng(static_cast<uint32_t>(seed) ^ 0x9e3779b9u);
            Document doc(testing::make_cube_mesh(12), material_preset("marble"));
            LiveScene scene(doc.mesh(), key_lighting(), options_for(config));
            std::optional<PlaneSurface> last_plane;
            std::string log;
            for (int step = 0; step < steps; ++step) {
                std::optional<ChangeReport> change;
                const int choice = std::uniform_int_distribution<int>(0, 9)(rng);
                if (choice == 0 && doc.can_undo()) {
                    change = doc.undo();
                } else if (choice == 1 && doc.can_redo()) {
                    change = doc.redo();
                } else {
                    change = doc.apply(random_edit(doc, rng, last_plane, strokes));
                }
                log += change->name + " (min " + std::to_string(doc.min_dihedral_deg()) + " deg); ";
                SCOPED_TRACE(std::string(config.name) + ", seed " + std::to_string(seed) + ": " + log);
                ASSERT_NO_THROW(scene.apply_change(doc.mesh(), *change));
                if (crease_rng() % 4 == 0) {
                    constexpr std::array<double, 5> kAngles = {0.0, 20.0, 40.0, 90.0, 180.0};
                    const double angle = kAngles[crease_rng() % kAngles.size()];
                    log += "crease angle " + std::to_string(angle) + "; ";
                    ASSERT_NO_THROW(scene.set_crease_angle(angle));
                }
                scene.step(static_cast<int>(rng() % 3) * 2);
                if (step % 5 == 4 || step == steps - 1) {
                    ASSERT_NO_THROW(scene.converge());
                    EXPECT_LT(relative_difference(scene.phi(), reference_phi(doc.mesh(), scene.options().crease_angle_degrees)),
                              gpu ? 2e-2 : 1e-4);
                    EXPECT_EQ(scene.backend(), config.backend) << scene.gpu_fallback_reason();
                    // The paper's coarse-to-fine pass may skip a coarse level whose BiCGSTAB diverges
                    // (Eq. 17's operators are not symmetric; 4 of 250 soak sequences of 20 steps), which
                    // level-0 CG makes up for; no other fallback is expected.
                    const std::string reason = scene.method_fallback_reason();
                    if (config.method == LiveMethod::Multires && !reason.empty()) {
                        EXPECT_NE(reason.find("the coarse-to-fine pass skipped"), std::string::npos) << reason;
                        skipped_here = true;
                    } else {
                        EXPECT_EQ(reason, "");
                    }
                }
            }
            skipped += skipped_here ? 1 : 0;
        }
        if (config.method == LiveMethod::Multires)
            std::printf("%s: the coarse pass skipped a level in %d of %d sequences\n", config.name, skipped, run);
    }
}

TEST(LiveSolver, RandomEditSequencesConvergeToTheFreshSolution) { check_random_edit_sequences(false, 20); }

TEST(LiveSolver, RandomEditSequencesWithStrokeCutsConvergeToTheFreshSolution) { check_random_edit_sequences(true, 8); }

TEST(LiveSolver, NamesParseAndBadNamesAreRejected) {
    EXPECT_EQ(parse_live_method(live_method_name(LiveMethod::MultigridCg)), LiveMethod::MultigridCg);
    EXPECT_EQ(parse_live_method(live_method_name(LiveMethod::JacobiCg)), LiveMethod::JacobiCg);
    EXPECT_EQ(parse_live_method("multires"), LiveMethod::Multires);
    EXPECT_STREQ(live_method_name(LiveMethod::Multires), "multires");
    EXPECT_EQ(parse_live_backend(live_backend_name(LiveBackend::Gpu)), LiveBackend::Gpu);
    EXPECT_EQ(parse_live_backend(live_backend_name(LiveBackend::Cpu)), LiveBackend::Cpu);
    EXPECT_THROW(parse_live_method("gauss"), InvalidArgumentError);
    EXPECT_THROW(parse_live_backend("tpu"), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
