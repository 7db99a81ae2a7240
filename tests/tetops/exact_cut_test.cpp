// Exact cutting: crossed tets are split along the surface, so the cross-section lies on it.
#include "base/error.h"
#include "io/surface_reader.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/exact_cut.h"
#include "tetops/fracture.h"
#include "tetops/mesh_checks.h"
#include "tetops/quality.h"
#include "tetops/test_meshes.h"
#include "tetops/tet_mesh.h"
#include "tetops/tetrahedralize.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

namespace waxwork {
namespace {

using testing::expect_valid_conforming;
using testing::make_cube_mesh;
using testing::on_unit_cube_boundary;
using testing::tets_under_parent_guard;
using testing::volume_by_original_id;

// Volume of {x in [0,1]^3 : n.x <= d} for n with positive components: inclusion-exclusion over the
// cube's corners of the simplex volumes max(0, d - n.v)^3 / (6 n_x n_y n_z).
double kept_cube_volume(const Eigen::Vector3d& n, double d) {
    double sum = 0;
    for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d v(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        const double s = std::max(0.0, d - n.dot(v));
        sum += ((corner & 1) + ((corner >> 1) & 1) + ((corner >> 2) & 1)) % 2 ? -s * s * s : s * s * s;
    }
    return sum / (6 * n.x() * n.y() * n.z());
}

// The largest |side| over vertices of boundary faces that are not on the cube's boundary (the
// cross-section), and the number of such faces.
std::pair<double, size_t> cross_section_deviation(const TetMesh& mesh, const TetConnectivity& c,
                                                  const CuttingSurface& surface) {
    double worst = 0;
    size_t faces = 0;
    for (const BoundaryFace& f : c.boundary_faces) {
        bool outer = true;
        for (int32_t v : f.vertices) outer = outer && on_unit_cube_boundary(mesh.positions[v]);
        if (outer) continue;
        ++faces;
        for (int32_t v : f.vertices) worst = std::max(worst, std::abs(surface.side(mesh.positions[v])));
    }
    return {worst, faces};
}

TEST(ExactCut, ObliquePlaneThroughACube) {
    const TetMesh before = make_cube_mesh(6);
    const Eigen::Vector3d n(1.0, 0.7, 0.45);
    const double d = 1.13;
    const PlaneCut plane(n, d);
    for (double snap : {0.0, 0.2}) {
        TetMesh mesh = before;
        ExactCutOptions options;
        options.split.snap_fraction = snap;
        // Without snapping nor the guarded optimisation after the split, no vertex moves.
        if (snap == 0) options.split.smooth_below_deg = 0;
        const ExactCutResult r = cut_exact(mesh, plane, options);
        EXPECT_GT(r.tets_split, 0u);
        EXPECT_GT(r.vertices_added, 0u);
        EXPECT_EQ(r.vertices_snapped > 0, snap > 0);
        const TetConnectivity c = expect_valid_conforming(mesh);
        EXPECT_EQ(c.component_count, 1);
        EXPECT_NEAR(total_volume(mesh), kept_cube_volume(n, d), 1e-13) << snap;
        const auto [deviation, faces] = cross_section_deviation(mesh, c, plane);
        EXPECT_GT(faces, 0u);
        EXPECT_LT(deviation, 1e-14);
        for (const auto& p : mesh.positions) EXPECT_LE(plane.side(p), 1e-14);
        for (size_t t = 0; t < mesh.tet_count(); ++t) EXPECT_GT(signed_volume(mesh, t), 0.0);
        EXPECT_GT(r.min_dihedral_deg, 0.0);
        EXPECT_NEAR(r.min_dihedral_deg, measure_quality(mesh).min_dihedral_deg, 1e-12);
        // Bookkeeping: every tet and vertex after the cut knows where it came from.
        ASSERT_EQ(r.new_to_old_tet.size(), mesh.tet_count());
        ASSERT_EQ(r.vertex_origins.size(), mesh.vertex_count());
        for (size_t t = 0; t < mesh.tet_count(); ++t)
            EXPECT_EQ(mesh.original_ids[t], before.original_ids[r.new_to_old_tet[t]]);
        for (size_t v = 0; v < mesh.vertex_count(); ++v) {
            const auto [a, b, t] = r.vertex_origins[v];
            if (a == b && snap == 0) {
                EXPECT_EQ(mesh.positions[v], before.positions[a]);
            }
            if (a != b) {
                EXPECT_NEAR(plane.side(mesh.positions[v]), 0.0, 1e-15);
                // Made at the plane's crossing of edge ab, where nothing moves it afterwards.
                if (snap == 0) {
                    EXPECT_LT(((1 - t) * before.positions[a] + t * before.positions[b] - mesh.positions[v]).norm(), 1e-15);
                }
            }
        }
        if (snap == 0) {
            // No vertex moved: each kept tet is whole or cut, never bigger than it was.
            const auto parts = volume_by_original_id(mesh), whole = volume_by_original_id(before);
            for (const auto& [id, volume] : parts) EXPECT_LE(volume, whole.at(id) * (1 + 1e-12));
        }
    }
}

TEST(ExactCut, ChildrenKeepMaterialOriginalIdAndPiece) {
    TetMesh before = make_cube_mesh(4);
    before.materials.resize(before.tet_count());
    for (size_t t = 0; t < before.tet_count(); ++t) before.materials[t].mua = {0.01 * static_cast<double>(t), 0.5, 1.0};
    TetMesh mesh = before;
    const ExactCutResult r = cut_exact(mesh, PlaneCut(Eigen::Vector3d(0.3, 1, 0.2), 0.61));
    ASSERT_GT(r.tets_split, 0u);
    ASSERT_EQ(mesh.materials.size(), mesh.tet_count());
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        EXPECT_EQ(mesh.materials[t], before.materials[r.new_to_old_tet[t]]);
        EXPECT_EQ(mesh.original_ids[t], before.original_ids[r.new_to_old_tet[t]]);
        EXPECT_EQ(mesh.piece_ids[t], 0);
    }
}

TEST(ExactCut, SnappingImprovesTheWorstAngle) {
    const TetMesh before = make_cube_mesh(8);
    // A plane just past a grid plane: without snapping, thin tets next to x = 0.5.
    const PlaneCut plane(Eigen::Vector3d(1, 0.05, 0.02), 0.51);
    TetMesh snapped = before, unsnapped = before;
    ExactCutOptions options;
    const ExactCutResult a = cut_exact(snapped, plane, options);
    options.split.snap_fraction = 0;
    const ExactCutResult b = cut_exact(unsnapped, plane, options);
    EXPECT_GT(a.vertices_snapped, 0u);
    EXPECT_GT(a.min_dihedral_deg, b.min_dihedral_deg);
    EXPECT_LT(a.tets_split, b.tets_split);
    expect_valid_conforming(snapped);
    expect_valid_conforming(unsnapped);
    EXPECT_NEAR(total_volume(snapped), total_volume(unsnapped), 1e-13);
}

TEST(ExactCut, BoundaryBendZeroKeepsACurvedSurfaceExactly) {
    // A cube whose top is a gentle bump: its boundary faces bend by a few degrees.
    TetMesh before = make_cube_mesh(8);
    for (auto& p : before.positions) p.z() *= 1 + 0.08 * std::sin(3 * p.x()) * std::cos(2 * p.y());
    ASSERT_NO_THROW(validate(before));
    const PlaneCut plane(Eigen::Vector3d(1, 0.1, 0.03), 0.515);
    TetMesh reference = before, flat_only = before, bent = before;
    ExactCutOptions options;
    options.split.snap_fraction = 0;
    cut_exact(reference, plane, options);  // no vertex moves: the exact kept volume
    options.split.snap_fraction = 0.2;
    options.split.boundary_bend_deg = 0;
    const ExactCutResult a = cut_exact(flat_only, plane, options);
    options.split.boundary_bend_deg = 20;
    const ExactCutResult b = cut_exact(bent, plane, options);
    EXPECT_NEAR(total_volume(flat_only), total_volume(reference), 1e-13);
    EXPECT_GT(b.vertices_snapped, a.vertices_snapped);  // curved boundary vertices slide too
    EXPECT_GE(b.min_dihedral_deg, a.min_dihedral_deg);
    EXPECT_NEAR(total_volume(bent), total_volume(reference), 1e-3 * total_volume(reference));
    expect_valid_conforming(flat_only);
    expect_valid_conforming(bent);
    options.split.boundary_bend_deg = 90;
    EXPECT_THROW(cut_exact(bent, plane, options), InvalidArgumentError);
}

// A boundary vertex where nothing may slide (a bump of 26 degrees on a cube face) lies a hair past the
// plane: 1e-9, and 1e-4 (6e-4 of its edges along x, 1/6 long). Split there, its edges would leave tets
// of almost no angle; with a bend allowance it steps onto the plane instead (the surface moves by at
// most 1e-3 of an edge), and with bend 0 the surface is kept exactly and the sliver is counted under
// the guard. 5e-4 past it (3e-3 of an edge) the vertex stays where it is and the edges are split.
TEST(ExactCut, ACrossingAHairFromAStuckBoundaryVertexIsSnappedNotSplit) {
    for (const double past : {1e-9, 1e-4, 5e-4}) {
        SCOPED_TRACE("the vertex " + std::to_string(past) + " past the plane");
        TetMesh before = make_cube_mesh(6);
        int32_t bumped = -1;
        for (size_t v = 0; v < before.vertex_count(); ++v)
            if ((before.positions[v] - Eigen::Vector3d(0.5, 0, 0.5)).norm() < 1e-12) bumped = static_cast<int32_t>(v);
        ASSERT_GE(bumped, 0);
        before.positions[static_cast<size_t>(bumped)] += Eigen::Vector3d(past, -0.08, 0);
        const double angle_before = measure_quality(before).min_dihedral_deg;
        const PlaneCut plane(Eigen::Vector3d(1, 0, 0), 0.5);

        TetMesh snapped = before;
        const ExactCutResult r = cut_exact(snapped, plane);
        for (const auto& p : snapped.positions) EXPECT_LE(plane.side(p), 1e-14);
        expect_valid_conforming(snapped);
        EXPECT_EQ(r.tets_under_guard, 0u);
        if (past < 1e-3 / 6) {
            EXPECT_EQ(r.vertices_added, 0u);
            EXPECT_GT(r.min_dihedral_deg, 0.9 * angle_before);  // the bump, not a sliver
        } else {
            EXPECT_GT(r.vertices_added, 0u);
        }

        TetMesh exact_shape = before;
        ExactCutOptions keep_shape;
        keep_shape.split.boundary_bend_deg = 0;
        const ExactCutResult kept = cut_exact(exact_shape, plane, keep_shape);
        EXPECT_GT(kept.vertices_added, 0u);
        if (past < 1e-3 / 6) {
            EXPECT_GE(kept.tets_under_guard, 1u);
            EXPECT_LT(kept.min_dihedral_deg, 0.5);
        }
        for (const auto& p : exact_shape.positions) EXPECT_LE(plane.side(p), 1e-14);
    }
}

TEST(ExactCut, PlanesThroughVerticesAndEdges) {
    // x = 0.4 is a grid plane of the 5-cell cube: nothing to split, the cut follows existing faces.
    TetMesh mesh = make_cube_mesh(5);
    const ExactCutResult r = cut_exact(mesh, PlaneCut(Eigen::Vector3d(1, 0, 0), 0.4));
    EXPECT_EQ(r.tets_split, 0u);
    EXPECT_EQ(r.vertices_added, 0u);
    expect_valid_conforming(mesh);
    EXPECT_NEAR(total_volume(mesh), 0.4, 1e-14);

    // x + y = 0.8 passes through grid vertices and diagonals of cells: some tets are split through a
    // vertex (the 1-1-2 and 1-2-1 cases).
    TetMesh diagonal = make_cube_mesh(5);
    const PlaneCut plane(Eigen::Vector3d(1, 1, 0), 0.8);
    const ExactCutResult rd = cut_exact(diagonal, plane);
    const TetConnectivity c = expect_valid_conforming(diagonal);
    EXPECT_NEAR(total_volume(diagonal), 0.5 * 0.8 * 0.8, 1e-14);
    EXPECT_LT(cross_section_deviation(diagonal, c, plane).first, 1e-14);
    (void)rd;

    // x + y + z = 1.2 crosses every kind of configuration at once.
    TetMesh corner = make_cube_mesh(5);
    const PlaneCut slanted(Eigen::Vector3d(1, 1, 1), 1.2);
    cut_exact(corner, slanted);
    expect_valid_conforming(corner);
    EXPECT_NEAR(total_volume(corner), kept_cube_volume(Eigen::Vector3d(1, 1, 1), 1.2), 1e-14);
}

TEST(ExactCut, RepeatedCutsAndEverythingOrNothing) {
    TetMesh mesh = make_cube_mesh(6);
    cut_exact(mesh, PlaneCut(Eigen::Vector3d(1, 0, 0), 0.63));
    cut_exact(mesh, PlaneCut(Eigen::Vector3d(0, 1, 0), 0.41));
    cut_exact(mesh, PlaneCut(Eigen::Vector3d(0, 0, -1), -0.27));  // keeps z >= 0.27
    expect_valid_conforming(mesh);
    EXPECT_NEAR(total_volume(mesh), 0.63 * 0.41 * 0.73, 1e-13);
    // A second cut along the same plane changes nothing.
    const TetMesh once = mesh;
    const ExactCutResult again = cut_exact(mesh, PlaneCut(Eigen::Vector3d(1, 0, 0), 0.63));
    EXPECT_EQ(again.tets_split, 0u);
    EXPECT_EQ(again.tets_removed, 0u);
    EXPECT_EQ(mesh.tets, once.tets);

    TetMesh all = make_cube_mesh(2);
    cut_exact(all, PlaneCut(Eigen::Vector3d(1, 0, 0), -1));
    EXPECT_EQ(all.tet_count(), 0u);
    EXPECT_NO_THROW(validate(all));
    TetMesh none = make_cube_mesh(2);
    const TetMesh untouched = none;
    cut_exact(none, PlaneCut(Eigen::Vector3d(1, 0, 0), 2));
    EXPECT_EQ(none, untouched);
}

TEST(ExactCut, StrokeCutFollowsTheStroke) {
    const TetMesh before = make_cube_mesh(6);
    // A straight stroke seen from far away along -z: its surface is (almost) the plane through the
    // eye and the stroke; the kept volume matches the plane cut.
    const Eigen::Vector3d eye(0.5, 0.5, 10);
    const Eigen::Vector3d view(0, 0, -1);
    const std::vector<Eigen::Vector3d> straight = {{0.2, 0.1, 5}, {0.7, 0.9, 5}};
    const StrokeCut stroke(eye, view, straight);
    TetMesh mesh = before;
    const ExactCutResult r = cut_exact(mesh, stroke);
    EXPECT_GT(r.tets_split, 0u);
    const TetConnectivity c = expect_valid_conforming(mesh);
    // The plane through the eye containing the stroke segment, oriented like the stroke's side test.
    const Eigen::Vector3d normal = (straight[1] - straight[0]).cross(eye - straight[0]).normalized();
    const PlaneCut plane_a(normal, normal.dot(eye)), plane_b(-normal, -normal.dot(eye));
    const Eigen::Vector3d probe(0.0, 1.0, 0.5);  // left of the stroke as seen from the eye
    const PlaneCut& plane = (stroke.side(probe) > 0) == (plane_a.side(probe) > 0) ? plane_a : plane_b;
    TetMesh reference = before;
    cut_exact(reference, plane);
    EXPECT_NEAR(total_volume(mesh), total_volume(reference), 1e-9);
    // Cross-section on the stroke surface to bisection precision (in side() units ~ distance).
    EXPECT_LT(cross_section_deviation(mesh, c, stroke).first, 1e-12);
    for (const auto& p : mesh.positions) EXPECT_LE(stroke.side(p), 1e-12);

    // A bent stroke: two panels meeting inside the cube.
    const std::vector<Eigen::Vector3d> bent = {{0.1, 0.2, 5}, {0.5, 0.6, 5}, {0.9, 0.3, 5}};
    TetMesh bent_mesh = before;
    const StrokeCut bent_stroke(eye, view, bent, /*flip=*/true);
    cut_exact(bent_mesh, bent_stroke);
    const TetConnectivity cb = expect_valid_conforming(bent_mesh);
    EXPECT_LT(cross_section_deviation(bent_mesh, cb, bent_stroke).first, 1e-12);
    EXPECT_GT(total_volume(bent_mesh), 0.0);
    EXPECT_LT(total_volume(bent_mesh), 1.0);
}

TEST(ExactCut, MovedPiecesAreCutInWorldSpace) {
    TetMesh mesh = join_meshes(make_cube_mesh(4), make_cube_mesh(4, Eigen::Vector3d(0, 0, 3)));
    for (size_t t = mesh.tet_count() / 2; t < mesh.tet_count(); ++t) mesh.piece_ids[t] = 1;
    RigidTransform moved;
    moved.rotation = Eigen::AngleAxisd(0.5 * M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    moved.translation = Eigen::Vector3d(4, 0, -3);  // piece 1 now spans x in [3, 4], z in [0, 1]
    mesh.piece_transforms.push_back(moved);
    const PlaneCut plane(Eigen::Vector3d(0, 0, 1), 0.35);  // keeps z <= 0.35 of both
    cut_exact(mesh, plane);
    expect_valid_conforming(mesh);
    EXPECT_NEAR(total_volume(mesh), 2 * 0.35, 1e-13);
    for (const auto& p : world_positions(mesh)) EXPECT_LE(p.z(), 0.35 + 1e-14);
    EXPECT_EQ(mesh.piece_transforms[1], moved);
}

// The guarantee: every tet the cut creates or moves has a minimum dihedral angle of at least
// min(0.5 degrees, that of the tet it comes from), except exactly tets_under_guard of them; the
// cross-section stays on the plane. Planes through grid vertices, a hair off them, and oblique.
TEST(ExactCut, NewAndMovedTetsKeepTheGuardOrAreCounted) {
    const TetMesh before = make_cube_mesh(6);
    const std::vector<std::pair<Eigen::Vector3d, double>> planes = {
        {{1, 0, 0}, 0.5 + 1e-7},          // nearly through a grid plane
        {{1, 0.05, 0.02}, 0.51},          // just past one, tilted
        {{1, 1, 0}, 0.8 + 1e-9},          // nearly through vertices and cell diagonals
        {{1, 1, 1}, 1.5},                 // through vertices
        {{1, 0.7, 0.45}, 1.13},           // oblique
        {{0.3, 1, 0.2}, 0.61 - 1e-6},
    };
    size_t with_total = 0, without_total = 0;
    for (const auto& [n, d] : planes) {
        const PlaneCut plane(n, d);
        TetMesh mesh = before, plain = before;
        const ExactCutResult r = cut_exact(mesh, plane);
        EXPECT_EQ(r.tets_under_guard,
                  tets_under_parent_guard(mesh, before, [&](size_t t) { return r.new_to_old_tet[t]; }))
            << n.transpose() << " " << d;
        const TetConnectivity c = expect_valid_conforming(mesh);
        EXPECT_LT(cross_section_deviation(mesh, c, plane).first, 1e-14);
        for (const auto& p : mesh.positions) EXPECT_LE(plane.side(p), 1e-14);
        // Without snapping, the optimisation after the split alone: it leaves fewer tets under the
        // guard than the case split does.
        ExactCutOptions options;
        options.split.snap_fraction = 0;
        TetMesh unsnapped = before;
        const ExactCutResult u = cut_exact(unsnapped, plane, options);
        EXPECT_EQ(u.tets_under_guard,
                  tets_under_parent_guard(unsnapped, before, [&](size_t t) { return u.new_to_old_tet[t]; }));
        options.split.smooth_below_deg = 0;
        const ExactCutResult p = cut_exact(plain, plane, options);
        EXPECT_EQ(p.tets_under_guard,
                  tets_under_parent_guard(plain, before, [&](size_t t) { return p.new_to_old_tet[t]; }));
        // Vertices move within the cube's faces and the plane: the kept volume does not change.
        EXPECT_NEAR(total_volume(mesh), total_volume(plain), 1e-12) << d;
        EXPECT_NEAR(total_volume(unsnapped), total_volume(plain), 1e-12) << d;
        with_total += u.tets_under_guard;
        without_total += p.tets_under_guard;
    }
    EXPECT_GT(without_total, 0u);
    EXPECT_LT(with_total, without_total);
}

// On a fractured mesh (pieces, crack faces as boundary): the same recount, and the cut stays on the
// plane.
TEST(ExactCut, GuardOnAFracturedMesh) {
    TetMesh before = make_cube_mesh(6);
    const std::vector<Eigen::Vector3d> seeds = {{0.2, 0.3, 0.25}, {0.8, 0.2, 0.3}, {0.3, 0.75, 0.7}, {0.7, 0.8, 0.65}, {0.5, 0.5, 0.5}};
    fracture_voronoi(before, seeds);
    for (double d : {0.5 + 1e-8, 0.37, 0.62}) {
        const PlaneCut plane(Eigen::Vector3d(1, 0.1, -0.05), d);
        TetMesh mesh = before;
        const ExactCutResult r = cut_exact(mesh, plane);
        EXPECT_GT(r.tets_split, 0u);
        EXPECT_EQ(r.tets_under_guard,
                  tets_under_parent_guard(mesh, before, [&](size_t t) { return r.new_to_old_tet[t]; }));
        expect_valid_conforming(mesh, false);
        for (const auto& p : mesh.positions) EXPECT_LE(plane.side(p), 1e-14);
        for (size_t v = 0; v < mesh.vertex_count(); ++v)
            if (!r.vertex_origins[v].is_vertex()) {
                EXPECT_NEAR(plane.side(mesh.positions[v]), 0.0, 1e-15);
            }
    }
}

// Spot (curved boundary, TetGen tets) at about 50K tets: an exact cut through the middle, and an exact
// cut after an exact fracture into 5 cells. Reported and recounted exceptions agree, and the
// cross-section lies on the plane.
TEST(ExactCut, GuardOnSpot) {
    MeshingOptions meshing;
    meshing.sizing.target_tets = 50000;
    const TetMesh spot =
        tetrahedralize(read_surface_file(std::string(WAXWORK_ASSET_DIR) + "/meshes/spot.obj"), meshing).mesh;
    TetMesh fractured = spot;
    const FractureResult broken = fracture_voronoi(fractured, scatter_fracture_seeds(fractured, 5, 1));
    std::map<int64_t, size_t> index;
    for (size_t t = 0; t < spot.tet_count(); ++t) index[spot.original_ids[t]] = t;
    EXPECT_EQ(broken.tets_under_guard, tets_under_parent_guard(fractured, spot, [&](size_t t) {
                  return index.at(fractured.original_ids[t]);
              }));
    for (const TetMesh* before : {&spot, static_cast<const TetMesh*>(&fractured)}) {
        for (double d : {0.0, 0.013}) {
            const PlaneCut plane(Eigen::Vector3d(1, 0, 0), d);
            TetMesh mesh = *before;
            const ExactCutResult r = cut_exact(mesh, plane);
            EXPECT_GT(r.tets_split, 0u);
            EXPECT_EQ(r.tets_under_guard,
                      tets_under_parent_guard(mesh, *before, [&](size_t t) { return r.new_to_old_tet[t]; }));
            EXPECT_NO_THROW(validate(mesh));
            for (size_t v = 0; v < mesh.vertex_count(); ++v) {
                EXPECT_LE(plane.side(mesh.positions[v]), 1e-14);
                if (!r.vertex_origins[v].is_vertex()) {
                    EXPECT_NEAR(plane.side(mesh.positions[v]), 0.0, 1e-15);
                }
            }
        }
    }
}

TEST(ExactCut, RejectsBadOptions) {
    TetMesh mesh = make_cube_mesh(2);
    ExactCutOptions options;
    options.split.snap_fraction = 0.5;
    EXPECT_THROW(cut_exact(mesh, PlaneCut(Eigen::Vector3d(1, 0, 0), 0.5), options), InvalidArgumentError);
    options.split.snap_fraction = 0.1;
    options.split.min_dihedral_guard_deg = -1;
    EXPECT_THROW(cut_exact(mesh, PlaneCut(Eigen::Vector3d(1, 0, 0), 0.5), options), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
