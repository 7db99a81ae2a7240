// As-rigid-as-possible deformation (tetops/arap_deformation.h): rigid motions are reproduced exactly,
// a bent bar keeps its volume and inverts nothing, the guard shortens steps that would break a tet,
// and deformation works on cut, painted and multi-body volumes.
#include "base/error.h"
#include "base/progress.h"
#include "io/volume_file.h"
#include "support/scratch_dir.h"
#include "tetops/arap_deformation.h"
#include "tetops/box_mesh.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/exact_cut.h"
#include "tetops/paint.h"
#include "tetops/quality.h"
#include "tetops/tet_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <numeric>

namespace waxwork {
namespace {

// A 4 x 1 x 1 bar along x, 16 x 4 x 4 cells (1536 tets).
TetMesh make_bar() { return make_box_mesh({16, 4, 4}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 1, 1)); }

std::vector<int32_t> vertices_where(const TetMesh& mesh, const std::function<bool(const Eigen::Vector3d&)>& pick) {
    std::vector<int32_t> out;
    for (size_t v = 0; v < mesh.vertex_count(); ++v)
        if (pick(mesh.positions[v])) out.push_back(static_cast<int32_t>(v));
    return out;
}

std::vector<int32_t> all_tets(const TetMesh& mesh) {
    std::vector<int32_t> tets(mesh.tet_count());
    std::iota(tets.begin(), tets.end(), 0);
    return tets;
}

// Largest relative change of any edge length of any tet between two position sets: 0 for a rigid motion.
double max_relative_edge_change(const TetMesh& mesh, const std::vector<Eigen::Vector3d>& a,
                                const std::vector<Eigen::Vector3d>& b) {
    double worst = 0;
    for (const Tet& tet : mesh.tets)
        for (const auto& e : kTetEdges) {
            const double la = (a[tet[e[0]]] - a[tet[e[1]]]).norm(), lb = (b[tet[e[0]]] - b[tet[e[1]]]).norm();
            worst = std::max(worst, std::abs(la - lb) / la);
        }
    return worst;
}

TetMesh with_positions(TetMesh mesh, std::vector<Eigen::Vector3d> positions) {
    mesh.positions = std::move(positions);
    return mesh;
}

TEST(ArapDeformation, TranslationOfTheHandleTranslatesTheFreeBodyExactly) {
    const TetMesh bar = make_bar();
    ArapDeformer deformer(bar, all_tets(bar));
    const std::vector<int32_t> handle = vertices_where(bar, [](const Eigen::Vector3d& p) { return p.x() >= 3.5; });
    deformer.set_constrained(handle);
    const Eigen::Vector3d shift(0.3, -1.7, 2.25);
    std::vector<Eigen::Vector3d> targets;
    for (int32_t v : handle) targets.push_back(bar.positions[v] + shift);
    const ArapSolveReport report = deformer.solve(targets, 2);
    EXPECT_LT(max_relative_edge_change(bar, bar.positions, deformer.positions()), 1e-9);
    for (size_t v = 0; v < bar.vertex_count(); ++v)
        EXPECT_LT((deformer.positions()[v] - bar.positions[v] - shift).norm(), 1e-9) << v;
    EXPECT_LT(report.energy, 1e-18);
}

TEST(ArapDeformation, RotationIsAFixedPoint) {
    const TetMesh bar = make_bar();
    const Eigen::Matrix3d r = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
    const Eigen::Vector3d t(5, -2, 1);
    std::vector<Eigen::Vector3d> rotated;
    for (const Eigen::Vector3d& p : bar.positions) rotated.push_back(r * p + t);
    ArapDeformer deformer(bar, all_tets(bar));
    const std::vector<int32_t> handle = vertices_where(bar, [](const Eigen::Vector3d& p) { return p.x() <= 0.25; });
    deformer.set_constrained(handle);
    std::vector<Eigen::Vector3d> targets;
    for (int32_t v : handle) targets.push_back(rotated[v]);
    deformer.set_positions(rotated);
    const ArapSolveReport report = deformer.solve(targets, 3);
    for (size_t v = 0; v < bar.vertex_count(); ++v) EXPECT_LT((deformer.positions()[v] - rotated[v]).norm(), 1e-9) << v;
    EXPECT_LT(max_relative_edge_change(bar, bar.positions, deformer.positions()), 1e-9);
    EXPECT_LT(report.energy, 1e-18);
}

// From the rest shape, the iterations find a rotation of the whole free body by themselves: both ends
// held at a rigid rotation, the middle converges to it (the energy falls monotonically, Sec. 3).
TEST(ArapDeformation, IterationsConvergeToARigidRotation) {
    const TetMesh bar = make_bar();
    const Eigen::Matrix3d r = Eigen::AngleAxisd(0.6, Eigen::Vector3d(0, 0, 1)).toRotationMatrix();
    ArapDeformer deformer(bar, all_tets(bar));
    const std::vector<int32_t> ends =
        vertices_where(bar, [](const Eigen::Vector3d& p) { return p.x() <= 0.25 || p.x() >= 3.75; });
    deformer.set_constrained(ends);
    std::vector<Eigen::Vector3d> targets;
    for (int32_t v : ends) targets.push_back(r * bar.positions[v]);
    double previous = std::numeric_limits<double>::infinity(), first = 0;
    for (int frame = 0; frame < 40; ++frame) {
        const double energy = deformer.solve(targets, 5).energy;
        EXPECT_LE(energy, previous * (1 + 1e-12)) << frame;
        if (frame == 0) first = energy;
        previous = energy;
    }
    // The convergence is linear (local/global is a block descent), so 200 iterations reach a small
    // fraction of the first frame's energy rather than rounding.
    EXPECT_GT(first, 1e-4);
    EXPECT_LT(previous, 1e-8 * first) << "first " << first << ", last " << previous;
    EXPECT_LT(max_relative_edge_change(bar, bar.positions, deformer.positions()), 1e-5);
}

TEST(ArapDeformation, RefactorsOnlyWhenTheConstrainedSetChanges) {
    const TetMesh bar = make_bar();
    ArapDeformer deformer(bar, all_tets(bar));
    std::vector<int32_t> handle = vertices_where(bar, [](const Eigen::Vector3d& p) { return p.x() >= 3.5; });
    deformer.set_constrained(handle);
    std::reverse(handle.begin(), handle.end());
    deformer.set_constrained(handle);
    EXPECT_EQ(deformer.factorizations(), 1);
    EXPECT_EQ(deformer.constrained(), handle);  // the new order is the targets' order
    handle.pop_back();
    deformer.set_constrained(handle);
    EXPECT_EQ(deformer.factorizations(), 2);
}

// Circular bend of the bar's middle: the end x >= 3.75 follows the end of an arc of angle `a` and length
// L = 3.5 that starts at x = 0.25 (pinned), bending about z in 9 frames of 10 degrees.
TEST(ArapDeformation, BarBent90DegreesKeepsVolumeAndInvertsNothing) {
    const TetMesh bar = make_bar();
    const std::vector<int32_t> pinned = vertices_where(bar, [](const Eigen::Vector3d& p) { return p.x() <= 0.25; });
    const std::vector<int32_t> handle = vertices_where(bar, [](const Eigen::Vector3d& p) { return p.x() >= 3.75; });
    std::vector<int32_t> constrained = handle;
    constrained.insert(constrained.end(), pinned.begin(), pinned.end());
    ArapDeformer deformer(bar, all_tets(bar));
    deformer.set_constrained(constrained);
    const double length = 3.5;
    const Eigen::Vector3d end_centre(3.75, 0.5, 0.5);
    int shortened = 0;
    for (int frame = 1; frame <= 9; ++frame) {
        const double a = std::numbers::pi / 2 * frame / 9, rho = length / a;
        const Eigen::Vector3d arc_centre(0.25, 0.5 + rho, 0.5);
        const Eigen::Matrix3d r = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
        const Eigen::Vector3d arc_end = arc_centre + r * Eigen::Vector3d(0, -rho, 0);
        std::vector<Eigen::Vector3d> targets;
        for (int32_t v : handle) targets.push_back(arc_end + r * (bar.positions[v] - end_centre));
        for (int32_t v : pinned) targets.push_back(bar.positions[v]);
        const std::vector<Eigen::Vector3d> before = deformer.positions();
        deformer.solve(targets, 20);
        GuardedStep step = guard_step(bar, all_tets(bar), before, deformer.positions());
        if (step.shortened()) {
            ++shortened;
            deformer.set_positions(std::move(step.positions));
        }
    }
    EXPECT_EQ(shortened, 0);
    const TetMesh bent = with_positions(bar, deformer.positions());
    // The end is where the arc puts it: turned 90 degrees, its centre at (0.25 + rho, 0.5 + rho).
    const double rho = length / (std::numbers::pi / 2);
    const int32_t corner = box_vertex_index({16, 4, 4}, 16, 0, 0);  // (4, 0, 0)
    EXPECT_LT((bent.positions[corner] - Eigen::Vector3d(0.25 + rho + 0.5, 0.5 + rho + 0.25, 0)).norm(), 1e-9);
    for (size_t t = 0; t < bent.tet_count(); ++t) ASSERT_GT(signed_volume(bent, t), 0) << t;
    EXPECT_GE(mesh_min_dihedral_deg(bent), 0.5);
    // ARAP is not volume preserving, but to first order the stretch of the outer side of a bend cancels
    // the compression of the inner side; what remains is second order in the strain (the bar's half
    // thickness over the bend radius, 0.5 / 2.23 ~ 0.22, whose square is 5%). Bound: 2%.
    const double before = total_volume(bar), after = total_volume(bent);
    EXPECT_LT(std::abs(after - before) / before, 0.02) << "volume " << before << " -> " << after;
}

TEST(ArapDeformation, GuardShortensAnAbsurdDragAndNothingInverts) {
    const TetMesh bar = make_bar();
    const TetConnectivity connectivity = build_connectivity(bar);
    const PinSphere pin{Eigen::Vector3d(0, 0.5, 0.5), 1.0};
    const DragRegion region = select_drag_region(bar, connectivity, Eigen::Vector3d(4, 0.5, 0.5), 1.0,
                                                 HandleMotion::translation(Eigen::Vector3d(-60, 40, 0)), std::span(&pin, 1));
    ArapDeformer deformer(bar, region.body_tets);
    const DragReport report = run_drag(deformer, bar, region, bar.positions, 1, 3);
    EXPECT_GE(report.shortened_steps, 1);
    EXPECT_LT(report.last_step_fraction, 1);
    EXPECT_GT(report.handle_error, 1);  // the handle could not get there
    EXPECT_EQ(report.inverted_tets, 0u);
    const TetMesh result = with_positions(bar, deformer.positions());
    for (size_t t = 0; t < result.tet_count(); ++t) ASSERT_GT(signed_volume(result, t), 0) << t;
    EXPECT_GE(mesh_min_dihedral_deg(result), 0.5 - 1e-9);
    EXPECT_NEAR(report.min_dihedral_deg, mesh_min_dihedral_deg(result), 1e-12);
}

TEST(ArapDeformation, GuardStepKeepsTheWholeStepWhenItIsFine) {
    const TetMesh bar = make_bar();
    std::vector<Eigen::Vector3d> moved = bar.positions;
    for (Eigen::Vector3d& p : moved) p += Eigen::Vector3d(1, 2, 3);
    const GuardedStep step = guard_step(bar, all_tets(bar), bar.positions, moved);
    EXPECT_FALSE(step.shortened());
    EXPECT_EQ(step.positions, moved);
    EXPECT_NEAR(step.min_dihedral_deg, mesh_min_dihedral_deg(bar), 1e-9);
}

TEST(ArapDeformation, SelectsHandlePinsAndTheGrabbedBodyOnly) {
    // Two separate bars side by side (two bodies of one piece): a drag of one leaves the other.
    const TetMesh a = make_bar();
    std::vector<Eigen::Vector3d> positions = a.positions;
    std::vector<Tet> tets = a.tets;
    const int32_t offset = static_cast<int32_t>(a.vertex_count());
    for (const Eigen::Vector3d& p : a.positions) positions.push_back(p + Eigen::Vector3d(0, 3, 0));
    for (Tet tet : a.tets) {
        for (int32_t& v : tet) v += offset;
        tets.push_back(tet);
    }
    const TetMesh two = make_tet_mesh(positions, tets);
    const TetConnectivity connectivity = build_connectivity(two);
    const PinSphere pin{Eigen::Vector3d(0, 0.5, 0.5), 0.8};
    // The grab's falloff reaches the second bar (at y >= 3) too, but its handle vertex is farther.
    const DragRegion region = select_drag_region(two, connectivity, Eigen::Vector3d(4, 1.2, 0.5), 3.0,
                                                 HandleMotion::translation(Eigen::Vector3d(0, 0, 1)), std::span(&pin, 1));
    EXPECT_EQ(region.body_tets.size(), a.tet_count());
    for (int32_t v : region.handle) {
        EXPECT_LT(v, offset);
        const double d = (two.positions[v] - Eigen::Vector3d(4, 1.2, 0.5)).norm();
        EXPECT_GE(handle_falloff(d, 3.0), kHandleMinWeight);
    }
    for (int32_t v : region.pinned) EXPECT_LE((two.positions[v] - pin.center).norm(), pin.radius);
    EXPECT_FALSE(region.pinned.empty());
    ArapDeformer deformer(two, region.body_tets);
    const DragReport report = run_drag(deformer, two, region, two.positions, 4, 5);
    EXPECT_EQ(report.inverted_tets, 0u);
    EXPECT_LT(report.handle_error, 1e-12);
    for (size_t v = offset; v < two.vertex_count(); ++v) EXPECT_EQ(deformer.positions()[v], two.positions[v]);
    for (int32_t v : region.pinned) EXPECT_EQ(deformer.positions()[v], two.positions[v]);
    for (const int32_t v : region.handle)  // the whole handle moves as one grip
        EXPECT_LT((deformer.positions()[v] - two.positions[v] - Eigen::Vector3d(0, 0, 1)).norm(), 1e-12);
}

TEST(ArapDeformation, MovesInTheRestFrameOfTheGrabbedPiece) {
    TetMesh bar = make_bar();
    bar.piece_transforms[0].rotation = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    bar.piece_transforms[0].translation = Eigen::Vector3d(10, 0, 0);
    const TetConnectivity connectivity = build_connectivity(bar);
    // The rest-frame end x = 4 is at world (10 - 0.5, 4, 0.5); a world move along +x is rest-frame -y.
    const DragRegion region = select_drag_region(bar, connectivity, Eigen::Vector3d(9.5, 4, 0.5), 0.6,
                                                 HandleMotion::translation(Eigen::Vector3d(0.2, 0, 0)), {});
    ASSERT_FALSE(region.handle.empty());
    for (int32_t v : region.handle) EXPECT_GE(bar.positions[v].x(), 3.6);
    EXPECT_LT((region.motion_rest.move - Eigen::Vector3d(0, -0.2, 0)).norm(), 1e-12);
}

TEST(ArapDeformation, RejectsBadRegions) {
    const TetMesh bar = make_bar();
    const TetConnectivity connectivity = build_connectivity(bar);
    const Eigen::Vector3d grab(4, 0.5, 0.5), move(0, 1, 0);
    EXPECT_THROW(select_drag_region(bar, connectivity, grab, 0.0, HandleMotion::translation(move), {}), InvalidArgumentError);
    EXPECT_THROW(select_drag_region(bar, connectivity, grab, std::nan(""), HandleMotion::translation(move), {}), InvalidArgumentError);
    EXPECT_THROW(select_drag_region(bar, connectivity, Eigen::Vector3d(40, 0, 0), 1.0, HandleMotion::translation(move), {}), InvalidArgumentError);
    EXPECT_THROW(select_drag_region(bar, connectivity, grab, 1.0, HandleMotion::translation(Eigen::Vector3d(0, std::nan(""), 0)), {}),
                 InvalidArgumentError);
    const PinSphere everything{Eigen::Vector3d(2, 0.5, 0.5), 100};
    EXPECT_THROW(select_drag_region(bar, connectivity, grab, 1.0, HandleMotion::translation(move), std::span(&everything, 1)), InvalidArgumentError);
    const PinSphere free_end{Eigen::Vector3d(0, 0.5, 0.5), 0.3};
    EXPECT_THROW(select_drag_region(bar, connectivity, grab, 100, HandleMotion::translation(move), std::span(&free_end, 1)), InvalidArgumentError);
    ArapDeformer deformer(bar, all_tets(bar));
    EXPECT_THROW(deformer.set_constrained({}), InvalidArgumentError);
    EXPECT_THROW(deformer.set_constrained(all_tets(bar)), InvalidArgumentError);  // 1536 > vertex count
    deformer.set_constrained({0, 1});
    EXPECT_THROW(deformer.solve(std::vector<Eigen::Vector3d>(1), 1), InvalidArgumentError);
    EXPECT_THROW(deformer.solve(std::vector<Eigen::Vector3d>(2), 0), InvalidArgumentError);
}

TEST(ArapDeformation, BendAndTwistRotateAboutTheAxis) {
    const std::vector<Eigen::Vector3d> points{{1, 0, 0}, {1, 0, 2}};
    const auto bent = bend_about_axis(points, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 3), std::numbers::pi / 2);
    EXPECT_LT((bent[0] - Eigen::Vector3d(0, 1, 0)).norm(), 1e-12);
    EXPECT_LT((bent[1] - Eigen::Vector3d(0, 1, 2)).norm(), 1e-12);
    const auto twisted = twist_about_axis(points, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1), std::numbers::pi / 4);
    EXPECT_LT((twisted[0] - points[0]).norm(), 1e-12);  // s = 0: not turned
    EXPECT_LT((twisted[1] - Eigen::Vector3d(0, 1, 2)).norm(), 1e-12);  // s = 2: a quarter turn
    EXPECT_THROW(bend_about_axis(points, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 1), InvalidArgumentError);
}

// The Bend and Twist tools: the handle turns rigidly about the axis and its vertices end exactly
// there, the pinned end stays, and nothing inverts.
TEST(ArapDeformation, BendAndTwistToolsTurnTheHandleAboutTheAxis) {
    const TetMesh bar = make_bar();
    const TetConnectivity connectivity = build_connectivity(bar);
    const PinSphere pin{Eigen::Vector3d(0, 0.5, 0.5), 0.6};
    const std::vector<HandleMotion> motions = {
        HandleMotion::bend(Eigen::Vector3d(2, 0.5, 0.5), Eigen::Vector3d(0, 0, 1), std::numbers::pi / 4),
        HandleMotion::twist(Eigen::Vector3d(0, 0.5, 0.5), Eigen::Vector3d(1, 0, 0), std::numbers::pi / 16)};
    for (const HandleMotion& motion : motions) {
        const DragRegion region =
            select_drag_region(bar, connectivity, Eigen::Vector3d(4, 0.5, 0.5), 1.0, motion, std::span(&pin, 1));
        ArapDeformer deformer(bar, region.body_tets);
        const DragReport report = run_drag(deformer, bar, region, bar.positions, 6, 10);
        EXPECT_EQ(report.shortened_steps, 0);
        EXPECT_EQ(report.inverted_tets, 0u);
        EXPECT_EQ(report.handle_vertices, region.handle.size());
        for (const int32_t v : region.handle)
            EXPECT_LT((deformer.positions()[v] - motion.apply(bar.positions[v], 1.0)).norm(), 1e-9) << v;
        for (int32_t v : region.pinned) EXPECT_EQ(deformer.positions()[v], bar.positions[v]);
        // The end turned: by 45 degrees about the elbow at x = 2 (bend), by about pi/4 about x (twist).
        const int32_t corner = box_vertex_index({16, 4, 4}, 16, 0, 0);
        EXPECT_GT((deformer.positions()[corner] - bar.positions[corner]).norm(), 0.3);
        const TetMesh result = with_positions(bar, deformer.positions());
        EXPECT_GE(mesh_min_dihedral_deg(result), 0.5);
    }
}

// A drag reports its steps and stops between them when asked to.
TEST(ArapDeformation, DragReportsProgressAndStopsWhenCancelled) {
    const TetMesh bar = make_bar();
    const TetConnectivity connectivity = build_connectivity(bar);
    const PinSphere pin{Eigen::Vector3d(0, 0.5, 0.5), 0.6};
    const DragRegion region = select_drag_region(bar, connectivity, Eigen::Vector3d(4, 0.5, 0.5), 1.0,
                                                 HandleMotion::translation(Eigen::Vector3d(0, 0.5, 0)), std::span(&pin, 1));
    Progress progress;
    ArapDeformer deformer(bar, region.body_tets);
    run_drag(deformer, bar, region, bar.positions, 4, 2, {}, &progress);
    EXPECT_NE(progress.stage().find("deforming"), std::string::npos);
    EXPECT_FLOAT_EQ(progress.fraction(), 0.75f);  // set as the last of the four steps starts
    progress.request_cancel();
    deformer.reset();
    EXPECT_THROW(run_drag(deformer, bar, region, bar.positions, 4, 2, {}, &progress), CancelledError);
}

TEST(ArapDeformation, WorksAfterAnExactCut) {
    TetMesh bar = make_bar();
    cut_exact(bar, PlaneCut(Eigen::Vector3d(1, 0.3, 0.2), 3.1));
    validate(bar);
    const TetConnectivity connectivity = build_connectivity(bar);
    const PinSphere pin{Eigen::Vector3d(0, 0.5, 0.5), 0.6};
    const DragRegion region = select_drag_region(bar, connectivity, Eigen::Vector3d(2.8, 0.5, 0.5), 0.8,
                                                 HandleMotion::translation(Eigen::Vector3d(0, 0.6, 0.3)), std::span(&pin, 1));
    ArapDeformer deformer(bar, region.body_tets);
    const DragReport report = run_drag(deformer, bar, region, bar.positions, 3, 8);
    const TetMesh result = with_positions(bar, deformer.positions());
    EXPECT_TRUE(find_invariant_violations(result).empty());
    EXPECT_EQ(report.inverted_tets, 0u);
    EXPECT_GE(mesh_min_dihedral_deg(result), std::min(0.5, mesh_min_dihedral_deg(bar)) - 1e-9);
    EXPECT_GT((deformer.positions()[region.handle.front()] - bar.positions[region.handle.front()]).norm(), 0.3);
}

TEST(ArapDeformation, PaintedMaterialsStayWithTheirTetsAndSaveAndReloadIdentically) {
    TetMesh bar = make_bar();
    TetMaterial base;
    base.mua = {0.01, 0.01, 0.01};
    base.musp = {1, 1, 1};
    base.eta = 1.3;
    PaintBrush brush;
    brush.material = base;
    brush.material.mua = {0.5, 0.02, 0.02};
    brush.sigma = 0.4;
    const std::vector<Eigen::Vector3d> stroke{{3.5, 0.5, 0.5}, {2.5, 0.5, 0.5}};
    paint_stroke(bar, stroke, brush, base);
    const TetMesh painted = bar;

    const TetConnectivity connectivity = build_connectivity(bar);
    const PinSphere pin{Eigen::Vector3d(0, 0.5, 0.5), 0.6};
    const DragRegion region = select_drag_region(bar, connectivity, Eigen::Vector3d(4, 0.5, 0.5), 1.0,
                                                 HandleMotion::translation(Eigen::Vector3d(0, 0, 0.8)), std::span(&pin, 1));
    ArapDeformer deformer(bar, region.body_tets);
    run_drag(deformer, bar, region, bar.positions, 2, 8);
    bar.positions = deformer.positions();
    EXPECT_EQ(bar.materials, painted.materials);
    EXPECT_EQ(bar.tets, painted.tets);
    EXPECT_EQ(bar.original_ids, painted.original_ids);
    EXPECT_NE(bar.positions, painted.positions);

    const auto path = testing::scratch_dir("arap_save") / "deformed.vtu";
    write_volume(bar, path);
    EXPECT_EQ(read_volume(path), bar);
}

// Every factorisation solves the same system: their drags agree to rounding.
TEST(ArapDeformation, EveryFactorGivesTheSameDrag) {
    const TetMesh bar = make_bar();
    const TetConnectivity connectivity = build_connectivity(bar);
    const PinSphere pin{Eigen::Vector3d(0, 0.5, 0.5), 0.6};
    const DragRegion region = select_drag_region(bar, connectivity, Eigen::Vector3d(4, 0.5, 0.5), 1.0,
                                                 HandleMotion::translation(Eigen::Vector3d(0, 0.8, 0.4)), std::span(&pin, 1));
    std::vector<std::vector<Eigen::Vector3d>> results;
    std::vector<double> energies;
    for (const ArapFactor factor :
         {ArapFactor::CholmodSimplicialSolves, ArapFactor::CholmodSupernodal, ArapFactor::EigenSimplicialLLT}) {
        ArapOptions options;
        options.factor = factor;
        ArapDeformer deformer(bar, region.body_tets, options);
        energies.push_back(run_drag(deformer, bar, region, bar.positions, 3, 4).energy);
        results.push_back(deformer.positions());
    }
    EXPECT_GT(energies[0], 1e-4);
    for (size_t k = 1; k < results.size(); ++k) {
        EXPECT_NEAR(energies[k], energies[0], 1e-9 * energies[0]) << k;
        for (size_t v = 0; v < bar.vertex_count(); ++v) ASSERT_LT((results[k][v] - results[0][v]).norm(), 1e-9) << k << " " << v;
    }
}

// The float local step (previews) against the double one: a translation stays exact, a bend of the
// bar in six steps ends within 1e-5 of the bar's length of the double drag with the energy within
// 1e-4 of it, and inverted tets (det F < 0, which the float batch leaves to the double SVD) get the
// same rotations.
TEST(ArapDeformation, FloatRotationsStayCloseToTheDoubleOnes) {
    const TetMesh bar = make_bar();
    ArapOptions in_float;
    in_float.rotations = ArapRotations::Float;
    {
        ArapDeformer deformer(bar, all_tets(bar), in_float);
        const std::vector<int32_t> handle = vertices_where(bar, [](const Eigen::Vector3d& p) { return p.x() >= 3.5; });
        deformer.set_constrained(handle);
        const Eigen::Vector3d shift(0.3, -1.7, 2.25);
        std::vector<Eigen::Vector3d> targets;
        for (int32_t v : handle) targets.push_back(bar.positions[v] + shift);
        EXPECT_LT(deformer.solve(targets, 2).energy, 1e-18);
        for (size_t v = 0; v < bar.vertex_count(); ++v)
            EXPECT_LT((deformer.positions()[v] - bar.positions[v] - shift).norm(), 1e-9) << v;
    }
    const TetConnectivity connectivity = build_connectivity(bar);
    const PinSphere pin{Eigen::Vector3d(0, 0.5, 0.5), 0.6};
    const DragRegion region = select_drag_region(
        bar, connectivity, Eigen::Vector3d(4, 0.5, 0.5), 1.0,
        HandleMotion::bend(Eigen::Vector3d(2, 0.5, 0.5), Eigen::Vector3d(0, 0, 1), std::numbers::pi / 4), std::span(&pin, 1));
    ArapDeformer in_double_deformer(bar, region.body_tets), in_float_deformer(bar, region.body_tets, in_float);
    const DragReport d = run_drag(in_double_deformer, bar, region, bar.positions, 6, 10);
    const DragReport f = run_drag(in_float_deformer, bar, region, bar.positions, 6, 10);
    EXPECT_GT(d.energy, 1e-3);
    EXPECT_NEAR(f.energy, d.energy, 1e-4 * d.energy);
    double farthest = 0;
    for (size_t v = 0; v < bar.vertex_count(); ++v)
        farthest = std::max(farthest, (in_float_deformer.positions()[v] - in_double_deformer.positions()[v]).norm());
    EXPECT_LT(farthest, 1e-5 * 4);
    EXPECT_GT(farthest, 0);  // the float path ran

    // Inverted tets: one interior vertex pushed through its neighbours.
    std::vector<Eigen::Vector3d> pushed = bar.positions;
    const int32_t inner = box_vertex_index({16, 4, 4}, 8, 2, 2);
    pushed[inner] += Eigen::Vector3d(0.6, 0.1, 0);
    const TetMesh pushed_mesh = with_positions(bar, pushed);
    size_t inverted = 0;
    for (size_t t = 0; t < bar.tet_count(); ++t) inverted += signed_volume(pushed_mesh, t) <= 0;
    ASSERT_GT(inverted, 0u);
    const std::vector<int32_t> ends =
        vertices_where(bar, [](const Eigen::Vector3d& p) { return p.x() <= 0.25 || p.x() >= 3.75; });
    std::vector<Eigen::Vector3d> targets;
    for (int32_t v : ends) targets.push_back(pushed[v]);
    ArapDeformer a(bar, all_tets(bar)), b(bar, all_tets(bar), in_float);
    for (ArapDeformer* deformer : {&a, &b}) {
        deformer->set_constrained(ends);
        deformer->set_positions(pushed);
    }
    const double ea = a.solve(targets, 1).energy, eb = b.solve(targets, 1).energy;
    EXPECT_NEAR(eb, ea, 1e-4 * ea);
    for (size_t v = 0; v < bar.vertex_count(); ++v) ASSERT_LT((a.positions()[v] - b.positions()[v]).norm(), 1e-5) << v;

    // Far-stretched tets: the float batch's unscaled Newton takes more steps (x30), or leaves them to
    // the double path when it would need too many (x1e9).
    for (const double stretch : {30.0, 1e9}) {
        std::vector<Eigen::Vector3d> stretched = bar.positions;
        for (Eigen::Vector3d& p : stretched) p.x() *= stretch;
        ArapDeformer c(bar, all_tets(bar)), d(bar, all_tets(bar), in_float);
        std::vector<Eigen::Vector3d> stretched_targets;
        for (int32_t v : ends) stretched_targets.push_back(stretched[v]);
        for (ArapDeformer* deformer : {&c, &d}) {
            deformer->set_constrained(ends);
            deformer->set_positions(stretched);
        }
        const double ec = c.solve(stretched_targets, 1).energy, ed = d.solve(stretched_targets, 1).energy;
        EXPECT_GT(ec, 1);
        EXPECT_NEAR(ed, ec, 1e-4 * ec) << stretch;
    }
}

}  // namespace
}  // namespace waxwork
