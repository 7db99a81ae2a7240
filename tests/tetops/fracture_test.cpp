// Fracture into pieces (Voronoi cells and planes), piece transforms and welding.
#include "base/error.h"
#include "tetops/connectivity.h"
#include "tetops/fracture.h"
#include "tetops/mesh_checks.h"
#include "tetops/quality.h"
#include "tetops/test_meshes.h"
#include "tetops/tet_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace waxwork {
namespace {

using testing::boundary_area;
using testing::expect_pieces_separate_and_connected;
using testing::expect_valid_conforming;
using testing::make_cube_mesh;
using testing::on_unit_cube_boundary;
using testing::tets_under_parent_guard;
using testing::volume_by_original_id;

// The two nearest seeds of x: (nearest, second nearest).
std::pair<size_t, size_t> two_nearest(const std::vector<Eigen::Vector3d>& seeds, const Eigen::Vector3d& x) {
    size_t a = 0, b = 1;
    if ((seeds[b] - x).norm() < (seeds[a] - x).norm()) std::swap(a, b);
    for (size_t i = 2; i < seeds.size(); ++i) {
        const double d = (seeds[i] - x).norm();
        if (d < (seeds[a] - x).norm()) b = a, a = i;
        else if (d < (seeds[b] - x).norm()) b = i;
    }
    return {a, b};
}

TEST(FractureSeeds, DeterministicInsideAndValidated) {
    const TetMesh mesh = make_cube_mesh(4);
    const auto a = scatter_fracture_seeds(mesh, 20, 5);
    const auto b = scatter_fracture_seeds(mesh, 20, 5);
    const auto c = scatter_fracture_seeds(mesh, 20, 6);
    ASSERT_EQ(a.size(), 20u);
    EXPECT_EQ(a, b);
    EXPECT_NE(a, c);
    for (const auto& p : a) EXPECT_TRUE((p.array() > 0).all() && (p.array() < 1).all()) << p.transpose();
    EXPECT_THROW(scatter_fracture_seeds(mesh, 0, 1), InvalidArgumentError);
    EXPECT_THROW(scatter_fracture_seeds(mesh, -3, 1), InvalidArgumentError);
    EXPECT_THROW(scatter_fracture_seeds(mesh, 1'000'000, 1), InvalidArgumentError);
    EXPECT_THROW(scatter_fracture_seeds(TetMesh{}, 2, 1), InvalidArgumentError);
}

TEST(FractureVoronoi, ExactCellsArePiecesWithFlatCracks) {
    const TetMesh before = make_cube_mesh(6);
    TetMesh mesh = before;
    // Four well separated seeds: every cell holds plenty of tets, so exactly four pieces.
    const std::vector<Eigen::Vector3d> seeds = {{0.2, 0.3, 0.25}, {0.8, 0.2, 0.3}, {0.3, 0.75, 0.7}, {0.7, 0.8, 0.65}};
    // Without snapping, the guarded optimisation or the collapse of swallowed walls no vertex moves, so
    // children add up exactly to their parents (below).
    FractureOptions options;
    options.snap_fraction = 0;
    options.smooth_below_deg = 0;
    options.collapse_swallowed_walls = false;
    const FractureResult r = fracture_voronoi(mesh, seeds, options);
    EXPECT_EQ(r.pieces_before, 1);
    EXPECT_EQ(r.pieces_after, 4);
    EXPECT_GT(r.tets_split, 0u);
    EXPECT_GT(r.vertices_duplicated, 0u);
    EXPECT_GT(r.min_dihedral_deg, 0.0);
    EXPECT_EQ(mesh.piece_transforms.size(), 4u);

    const TetConnectivity c = expect_valid_conforming(mesh);
    expect_pieces_separate_and_connected(mesh, c);
    EXPECT_EQ(c.component_count, 4);
    EXPECT_NEAR(total_volume(mesh), 1.0, 1e-12);

    // Every original tet is still there, whole or as children adding up to it.
    const auto volume_before = volume_by_original_id(before);
    const auto volume_after = volume_by_original_id(mesh);
    ASSERT_EQ(volume_after.size(), volume_before.size());
    for (const auto& [id, volume] : volume_before) EXPECT_NEAR(volume_after.at(id), volume, 1e-14) << id;

    // Each piece is one cell: every tet centroid is nearest to its piece's seed, and crack faces lie
    // on the bisector of the two nearest seeds.
    std::map<int32_t, size_t> seed_of_piece;
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const Tet& tet = mesh.tets[t];
        const Eigen::Vector3d centroid =
            0.25 * (mesh.positions[tet[0]] + mesh.positions[tet[1]] + mesh.positions[tet[2]] + mesh.positions[tet[3]]);
        const size_t cell = two_nearest(seeds, centroid).first;
        auto [it, inserted] = seed_of_piece.try_emplace(mesh.piece_ids[t], cell);
        EXPECT_EQ(it->second, cell) << "piece " << mesh.piece_ids[t] << " spans two cells";
    }
    double worst = 0;
    size_t crack_faces = 0;
    for (const BoundaryFace& f : c.boundary_faces) {
        bool outer = true;
        for (int32_t v : f.vertices) outer = outer && on_unit_cube_boundary(mesh.positions[v]);
        if (outer) continue;
        ++crack_faces;
        const size_t own = seed_of_piece.at(mesh.piece_ids[f.tet]);
        // The face lies on the bisector between its own seed and some other seed.
        double best = std::numeric_limits<double>::infinity();
        for (size_t other = 0; other < seeds.size(); ++other) {
            if (other == own) continue;
            double face_worst = 0;
            for (int32_t v : f.vertices) {
                const Eigen::Vector3d& p = mesh.positions[v];
                face_worst = std::max(face_worst, std::abs((p - seeds[own]).norm() - (p - seeds[other]).norm()));
            }
            best = std::min(best, face_worst);
        }
        worst = std::max(worst, best);
    }
    EXPECT_GT(crack_faces, 0u);
    EXPECT_LT(worst, 1e-12);
}

// Parent of each tet after a fracture: the tet of `before` with its original id.
std::vector<size_t> parents_by_original_id(const TetMesh& mesh, const TetMesh& before) {
    std::map<int64_t, size_t> index;
    for (size_t t = 0; t < before.tet_count(); ++t) index[before.original_ids[t]] = t;
    std::vector<size_t> parent(mesh.tet_count());
    for (size_t t = 0; t < mesh.tet_count(); ++t) parent[t] = index.at(mesh.original_ids[t]);
    return parent;
}

// The guarantee with snapping and the guarded optimisation on: every tet has a minimum dihedral angle
// of at least min(0.5 degrees, its parent's) except exactly tets_under_guard; cracks stay flat (on
// bisectors) and the volume whole. Without the optimisation more tets fall under the guard.
TEST(FractureVoronoi, ExactTetsKeepTheGuardOrAreCountedAndCracksStayFlat) {
    const TetMesh before = make_cube_mesh(6);
    size_t with_total = 0, without_total = 0;
    for (uint32_t seed : {1u, 2u, 3u}) {
        const std::vector<Eigen::Vector3d> seeds = scatter_fracture_seeds(before, 8, seed);
        TetMesh mesh = before, plain = before;
        const FractureResult r = fracture_voronoi(mesh, seeds);
        const std::vector<size_t> parent = parents_by_original_id(mesh, before);
        EXPECT_EQ(r.tets_under_guard, tets_under_parent_guard(mesh, before, [&](size_t t) { return parent[t]; }));
        const TetConnectivity c = expect_valid_conforming(mesh, false);
        EXPECT_NEAR(total_volume(mesh), 1.0, 1e-12);
        // Crack faces (not on the cube) lie on the bisector of some two seeds.
        double worst = 0;
        for (const BoundaryFace& f : c.boundary_faces) {
            bool outer = true;
            for (int32_t v : f.vertices) outer = outer && on_unit_cube_boundary(mesh.positions[v]);
            if (outer) continue;
            double best = std::numeric_limits<double>::infinity();
            for (size_t i = 0; i < seeds.size(); ++i)
                for (size_t j = i + 1; j < seeds.size(); ++j) {
                    double face_worst = 0;
                    for (int32_t v : f.vertices) {
                        const Eigen::Vector3d& p = mesh.positions[v];
                        face_worst = std::max(face_worst, std::abs((p - seeds[i]).norm() - (p - seeds[j]).norm()));
                    }
                    best = std::min(best, face_worst);
                }
            worst = std::max(worst, best);
        }
        EXPECT_LT(worst, 1e-12) << seed;

        FractureOptions options;
        options.smooth_below_deg = 0;
        const FractureResult p = fracture_voronoi(plain, seeds, options);
        const std::vector<size_t> plain_parent = parents_by_original_id(plain, before);
        EXPECT_EQ(p.tets_under_guard,
                  tets_under_parent_guard(plain, before, [&](size_t t) { return plain_parent[t]; }));
        with_total += r.tets_under_guard;
        without_total += p.tets_under_guard;
    }
    EXPECT_GT(without_total, 0u);
    EXPECT_LT(with_total, without_total);
}

// A deliberately coarse case: a cube of 6 tets broken into 8 cells cannot keep every piece's tets
// above the guard; the count says so instead of a silent violation.
TEST(FractureVoronoi, CoarseCubeReportsTetsUnderTheGuard) {
    const TetMesh before = make_cube_mesh(1);
    ASSERT_EQ(before.tet_count(), 6u);
    const std::vector<Eigen::Vector3d> seeds = {{0.1, 0.2, 0.15}, {0.85, 0.2, 0.3}, {0.2, 0.9, 0.25}, {0.8, 0.75, 0.2},
                                                {0.3, 0.2, 0.8},  {0.9, 0.3, 0.7}, {0.15, 0.7, 0.9}, {0.6, 0.6, 0.6}};
    TetMesh mesh = before;
    FractureOptions options;
    options.min_piece_tets = 0;
    const FractureResult r = fracture_voronoi(mesh, seeds, options);
    const std::vector<size_t> parent = parents_by_original_id(mesh, before);
    EXPECT_GT(r.tets_under_guard, 0u);
    EXPECT_EQ(r.tets_under_guard, tets_under_parent_guard(mesh, before, [&](size_t t) { return parent[t]; }));
    expect_valid_conforming(mesh, false);
    EXPECT_NEAR(total_volume(mesh), 1.0, 1e-12);
}

// Per vertex after the fracture, its origin: vertices before keep their index (origin: themselves);
// appended vertices name lower indices, a crack copy sits where its original sits in another piece, and
// a wall vertex lies on the edge it names at the parameter it names (exactly so when no vertex moves:
// no snapping, bending or smoothing).
void expect_origins_describe(const TetMesh& mesh, size_t vertices_before, const FractureResult& r, bool vertices_fixed) {
    ASSERT_EQ(r.vertex_origins.size(), mesh.vertex_count());
    std::vector<int32_t> piece(mesh.vertex_count(), -1);
    for (size_t t = 0; t < mesh.tet_count(); ++t)
        for (int32_t v : mesh.tets[t]) piece[v] = mesh.piece_ids[t];
    size_t copies = 0, on_edges = 0;
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        const auto [a, b, t] = r.vertex_origins[v];
        if (v < vertices_before) {
            EXPECT_TRUE(r.vertex_origins[v] == VertexOrigin::vertex(static_cast<int32_t>(v))) << v;
            continue;
        }
        ASSERT_TRUE(a >= 0 && b >= 0 && static_cast<size_t>(a) < v && static_cast<size_t>(b) < v) << v;
        if (a == b) {
            ++copies;
            EXPECT_EQ(t, 0.0) << v;
            EXPECT_EQ(mesh.positions[v], mesh.positions[a]) << v;
            EXPECT_NE(piece[v], piece[a]) << v;
            continue;
        }
        ++on_edges;
        EXPECT_GE(t, 0.0) << v;
        EXPECT_LE(t, 1.0) << v;
        if (!vertices_fixed) continue;
        const Eigen::Vector3d pa = mesh.positions[a], pb = mesh.positions[b], p = mesh.positions[v];
        const double s = (p - pa).dot(pb - pa) / (pb - pa).squaredNorm();
        EXPECT_GT(s, 0.0) << v;
        EXPECT_LT(s, 1.0) << v;
        EXPECT_LT((pa + s * (pb - pa) - p).norm(), 1e-12) << v;
        EXPECT_NEAR(t, s, 1e-12) << v;
    }
    EXPECT_EQ(copies, r.vertices_duplicated);
    EXPECT_EQ(vertices_before + copies + on_edges, mesh.vertex_count());
    if (r.tets_split > 0) {
        EXPECT_GT(on_edges, 0u);
    } else {
        EXPECT_EQ(on_edges, 0u);
    }
}

TEST(FractureVoronoi, VertexOriginsLeadEveryVertexBackToTheVolumeBefore) {
    const TetMesh before = make_cube_mesh(6);
    const auto seeds = scatter_fracture_seeds(before, 6, 3);
    FractureOptions fixed;
    fixed.snap_fraction = 0;
    fixed.boundary_bend_deg = 0;
    fixed.smooth_below_deg = 0;
    fixed.collapse_swallowed_walls = false;
    TetMesh mesh = before;
    const FractureResult r = fracture_voronoi(mesh, seeds, fixed);
    expect_origins_describe(mesh, before.vertex_count(), r, /*vertices_fixed=*/true);
    // Nested walls happen: some wall vertex lies on an edge made by an earlier wall.
    EXPECT_TRUE(std::any_of(r.vertex_origins.begin(), r.vertex_origins.end(), [&](const auto& o) {
        return !o.is_vertex() && static_cast<size_t>(std::max(o.a, o.b)) >= before.vertex_count();
    }));
    TetMesh snapped = before;
    expect_origins_describe(snapped, before.vertex_count(), fracture_voronoi(snapped, seeds), false);
    TetMesh faces = before;
    FractureOptions along_faces;
    along_faces.exact = false;
    expect_origins_describe(faces, before.vertex_count(), fracture_voronoi(faces, seeds, along_faces), true);
    TetMesh planes = before;
    const std::vector<Eigen::Vector4d> two = {{1, 0, 0, 0.43}, {0, 1, 0, 0.61}};
    expect_origins_describe(planes, before.vertex_count(), fracture_planes(planes, two, fixed), true);
}

TEST(FractureVoronoi, ScatteredSeedsDeterministicAndVolumePreserving) {
    const TetMesh before = make_cube_mesh(5);
    const auto seeds = scatter_fracture_seeds(before, 6, 42);
    TetMesh a = before, b = before;
    const FractureResult ra = fracture_voronoi(a, seeds);
    const FractureResult rb = fracture_voronoi(b, seeds);
    EXPECT_EQ(a, b);
    EXPECT_EQ(ra.pieces_after, rb.pieces_after);
    // A small cell may be merged away as dust; never more pieces than seeds in a convex volume.
    EXPECT_GE(ra.pieces_after, 2);
    EXPECT_LE(ra.pieces_after, 6);
    const TetConnectivity c = expect_valid_conforming(a);
    expect_pieces_separate_and_connected(a, c);
    EXPECT_EQ(c.component_count, ra.pieces_after);
    EXPECT_NEAR(total_volume(a), 1.0, 1e-12);
    for (size_t t = 0; t < a.tet_count(); ++t) EXPECT_GT(signed_volume(a, t), 0.0);
    // Snapping moves vertices but never loses a tet: every original id is still there unless the
    // collapse of swallowed walls reshaped its region into tets of other ids.
    TetMesh all_splits = before;
    FractureOptions keep_splits;
    keep_splits.collapse_swallowed_walls = false;
    const FractureResult rk = fracture_voronoi(all_splits, seeds, keep_splits);
    const auto ids_before = volume_by_original_id(before), ids_kept = volume_by_original_id(all_splits);
    ASSERT_EQ(ids_before.size(), ids_kept.size());
    EXPECT_TRUE(std::equal(ids_before.begin(), ids_before.end(), ids_kept.begin(),
                           [](const auto& x, const auto& y) { return x.first == y.first; }));
    for (const auto& [id, volume] : volume_by_original_id(a)) EXPECT_TRUE(ids_before.contains(id)) << id;
    // The collapse: fewer tets, the same pieces, no worse angle and no more tets under the guard.
    EXPECT_GT(ra.vertices_collapsed, 0u);
    EXPECT_EQ(rk.vertices_collapsed, 0u);
    EXPECT_LT(a.tet_count(), all_splits.tet_count());
    EXPECT_EQ(ra.pieces_after, rk.pieces_after);
    EXPECT_GE(ra.min_dihedral_deg, rk.min_dihedral_deg);
    EXPECT_LE(ra.tets_under_guard, rk.tets_under_guard);
    // Vertices move only inside a cell: the pieces' volumes are the same.
    const auto piece_volumes = [](const TetMesh& mesh) {
        std::vector<double> volume(mesh.piece_transforms.size(), 0.0);
        for (size_t t = 0; t < mesh.tet_count(); ++t) volume[static_cast<size_t>(mesh.piece_ids[t])] += signed_volume(mesh, t);
        std::sort(volume.begin(), volume.end());
        return volume;
    };
    const std::vector<double> with = piece_volumes(a), without = piece_volumes(all_splits);
    ASSERT_EQ(with.size(), without.size());
    for (size_t p = 0; p < with.size(); ++p) EXPECT_NEAR(with[p], without[p], 1e-12) << p;
    EXPECT_GT(ra.tets_split, 0u);
    // Snapping avoids slivers: the worst angle is better than with every crossed edge split.
    TetMesh unsnapped = before;
    FractureOptions no_snap;
    no_snap.snap_fraction = 0;
    const FractureResult ru = fracture_voronoi(unsnapped, seeds, no_snap);
    EXPECT_GE(ra.min_dihedral_deg, ru.min_dihedral_deg);
    EXPECT_GE(ru.tets_split, ra.tets_split);
}

TEST(FractureVoronoi, NonExactFollowsTetFacesAndKeepsEveryTet) {
    const TetMesh before = make_cube_mesh(5);
    TetMesh mesh = before;
    const std::vector<Eigen::Vector3d> seeds = {{0.25, 0.5, 0.5}, {0.75, 0.5, 0.5}, {0.5, 0.5, 0.9}};
    FractureOptions options;
    options.exact = false;
    const FractureResult r = fracture_voronoi(mesh, seeds, options);
    EXPECT_EQ(r.tets_split, 0u);
    EXPECT_EQ(r.pieces_after, 3);
    ASSERT_EQ(mesh.tet_count(), before.tet_count());
    EXPECT_EQ(mesh.original_ids, before.original_ids);  // no tet moved or split
    EXPECT_EQ(mesh.vertex_count(), before.vertex_count() + r.vertices_duplicated);
    const TetConnectivity c = expect_valid_conforming(mesh, /*manifold=*/false);
    expect_pieces_separate_and_connected(mesh, c);
    EXPECT_NEAR(total_volume(mesh), 1.0, 1e-12);
}

TEST(FractureVoronoi, OneSeedGivesOnePieceAndFracturesEachExistingPiece) {
    TetMesh mesh = make_cube_mesh(3);
    const std::vector<Eigen::Vector3d> one = {{0.5, 0.5, 0.5}};
    const FractureResult r = fracture_voronoi(mesh, one);
    EXPECT_EQ(r.pieces_after, 1);
    EXPECT_EQ(r.vertices_duplicated, 0u);

    // Two pieces (already apart), a cell wall through both: four pieces, each with its parent's
    // transform.
    TetMesh two = join_meshes(make_cube_mesh(4), make_cube_mesh(4, Eigen::Vector3d(0, 0, 2)));
    for (size_t t = two.tet_count() / 2; t < two.tet_count(); ++t) two.piece_ids[t] = 1;
    RigidTransform moved;
    moved.translation = Eigen::Vector3d(5, 0, 0);
    two.piece_transforms.push_back(moved);
    const std::vector<Eigen::Vector3d> seeds = {{0.2, 0.5, 0.5}, {0.8, 0.5, 0.5}, {5.2, 0.5, 2.5}, {5.8, 0.5, 2.5}};
    const FractureResult r2 = fracture_voronoi(two, seeds);
    EXPECT_EQ(r2.pieces_before, 2);
    EXPECT_EQ(r2.pieces_after, 4);
    const TetConnectivity c = expect_valid_conforming(two);
    expect_pieces_separate_and_connected(two, c);
    int moved_pieces = 0;
    for (const RigidTransform& x : two.piece_transforms) moved_pieces += x == moved;
    EXPECT_EQ(moved_pieces, 2);
    EXPECT_NEAR(total_volume(two), 2.0, 1e-12);
}

TEST(FractureVoronoi, PiecesOfAlmostNoVolumeAreDustWhateverTheirTets) {
    // A seed off the cube's corner owns the corner beyond x + y + z = 2.925: 7e-5 of the volume,
    // under 1e-3 of the mean cell's (0.5), however many tets the exact split makes of it.
    const TetMesh before = make_cube_mesh(4);
    const std::vector<Eigen::Vector3d> seeds = {{0.5, 0.5, 0.5}, {1.45, 1.45, 1.45}};
    FractureOptions by_tets_only;
    by_tets_only.min_piece_tets = 0;
    by_tets_only.min_piece_volume = 0;
    TetMesh kept = before;
    EXPECT_EQ(fracture_voronoi(kept, seeds, by_tets_only).pieces_after, 2);
    FractureOptions by_volume = by_tets_only;
    by_volume.min_piece_volume = FractureOptions{}.min_piece_volume;
    TetMesh merged = before;
    EXPECT_EQ(fracture_voronoi(merged, seeds, by_volume).pieces_after, 1);
    EXPECT_NEAR(total_volume(merged), 1.0, 1e-12);
    FractureOptions bad;
    for (double fraction : {-0.1, 1.0, std::numeric_limits<double>::quiet_NaN()}) {
        bad.min_piece_volume = fraction;
        TetMesh mesh = before;
        EXPECT_THROW(fracture_voronoi(mesh, seeds, bad), InvalidArgumentError) << fraction;
    }
}

TEST(FractureVoronoi, DustIsMergedAndBadInputRejected) {
    const TetMesh before = make_cube_mesh(4);
    // A seed just outside a corner owns a sliver of the cube: fewer tets than the dust limit.
    const std::vector<Eigen::Vector3d> seeds = {{0.5, 0.5, 0.5}, {1.2, 1.2, 1.2}};
    TetMesh mesh = before;
    FractureOptions options;
    options.min_piece_tets = 50;
    const FractureResult r = fracture_voronoi(mesh, seeds, options);
    EXPECT_EQ(r.pieces_after, 1);
    expect_valid_conforming(mesh);
    TetMesh kept = before;
    options.min_piece_tets = 0;
    EXPECT_EQ(fracture_voronoi(kept, seeds, options).pieces_after, 2);

    TetMesh m = before;
    EXPECT_THROW(fracture_voronoi(m, std::vector<Eigen::Vector3d>{}), InvalidArgumentError);
    const std::vector<Eigen::Vector3d> nan_seed = {{std::nan(""), 0, 0}};
    EXPECT_THROW(fracture_voronoi(m, nan_seed), InvalidArgumentError);
    options.min_piece_tets = -1;
    EXPECT_THROW(fracture_voronoi(m, seeds, options), InvalidArgumentError);
    EXPECT_EQ(m, before);
}

// More pieces than the tets allow pieces of min_piece_tets are refused up front, and an exact split
// that multiplies the tets past 32 times and 100,000 more (each wall splitting what earlier walls
// split) stops with an error naming the growth, instead of running for minutes into 1e-5-degree
// slivers.
TEST(FractureVoronoi, TooManyPiecesForTheVolumeAreRefused) {
    const TetMesh cube = make_cube_mesh(6);  // 1,296 tets
    TetMesh mesh = cube;
    try {
        fracture_voronoi(mesh, scatter_fracture_seeds(cube, 163, 1));
        ADD_FAILURE() << "163 pieces of 8 tets from 1,296 tets";
    } catch (const InvalidArgumentError& error) {
        EXPECT_NE(std::string(error.what()).find("so at most 162"), std::string::npos) << error.what();
    }
    EXPECT_EQ(mesh, cube);
    mesh = cube;
    try {
        fracture_voronoi(mesh, scatter_fracture_seeds(cube, 160, 1));
        ADD_FAILURE() << "160 exact pieces of a 1,296-tet cube";
    } catch (const InvalidArgumentError& error) {
        EXPECT_NE(std::string(error.what()).find("more than 32 times the 1296 it started with and 100000 more"),
                  std::string::npos)
            << error.what();
        EXPECT_NE(std::string(error.what()).find("--no-exact"), std::string::npos) << error.what();
    }
    EXPECT_LE(mesh.tet_count(), 2 * (32 * cube.tet_count() + 100'000));  // stopped soon after the limit
    mesh = cube;  // the same pieces along tet faces
    FractureOptions faces;
    faces.exact = false;
    EXPECT_GT(fracture_voronoi(mesh, scatter_fracture_seeds(cube, 160, 1), faces).pieces_after, 1);
    mesh = cube;
    EXPECT_EQ(fracture_voronoi(mesh, scatter_fracture_seeds(cube, 8, 1)).pieces_after, 8);
}

TEST(FracturePlanes, TwoPlanesFourPiecesWithExactVolumes) {
    TetMesh mesh = make_cube_mesh(5);
    const std::vector<Eigen::Vector4d> planes = {{1, 0, 0, 0.43}, {0, 2, 0, 2 * 0.31}};
    const FractureResult r = fracture_planes(mesh, planes);
    EXPECT_EQ(r.pieces_after, 4);
    EXPECT_GT(r.tets_split, 0u);
    const TetConnectivity c = expect_valid_conforming(mesh);
    expect_pieces_separate_and_connected(mesh, c);
    std::vector<double> volume(4, 0.0);
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        volume[mesh.piece_ids[t]] += signed_volume(mesh, t);
    }
    for (int p = 0; p < 4; ++p) {
        // Which quadrant the piece is in, from any of its vertices (all on one side or on a plane).
        double lo_x = 1, lo_y = 1;
        for (size_t t = 0; t < mesh.tet_count(); ++t)
            if (mesh.piece_ids[t] == p)
                for (int32_t v : mesh.tets[t]) lo_x = std::min(lo_x, mesh.positions[v].x()), lo_y = std::min(lo_y, mesh.positions[v].y());
        const double wx = lo_x < 0.43 - 1e-9 ? 0.43 : 0.57;
        const double wy = lo_y < 0.31 - 1e-9 ? 0.31 : 0.69;
        EXPECT_NEAR(volume[p], wx * wy, 1e-12) << p;
    }
    // Non-exact planes: whole tets only.
    TetMesh coarse = make_cube_mesh(5);
    FractureOptions options;
    options.exact = false;
    const FractureResult rc = fracture_planes(coarse, planes, options);
    EXPECT_EQ(rc.tets_split, 0u);
    EXPECT_EQ(rc.pieces_after, 4);
    expect_valid_conforming(coarse, /*manifold=*/false);
    const std::vector<Eigen::Vector4d> bad = {{0, 0, 0, 1}};
    EXPECT_THROW(fracture_planes(coarse, bad), InvalidArgumentError);
}

TEST(PieceTransform, OnlyRigidFiniteMotions) {
    TetMesh mesh = make_cube_mesh(2);
    RigidTransform x;
    x.rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    x.translation = Eigen::Vector3d(1, -2, 3);
    set_piece_transform(mesh, 0, x);
    EXPECT_EQ(mesh.piece_transforms[0], x);
    EXPECT_NO_THROW(validate(mesh));
    EXPECT_THROW(set_piece_transform(mesh, 1, x), InvalidArgumentError);
    EXPECT_THROW(set_piece_transform(mesh, -1, x), InvalidArgumentError);
    RigidTransform scaled = x;
    scaled.rotation *= 1.01;
    EXPECT_THROW(set_piece_transform(mesh, 0, scaled), InvalidArgumentError);
    RigidTransform mirrored = x;
    mirrored.rotation.col(0) *= -1;
    EXPECT_THROW(set_piece_transform(mesh, 0, mirrored), InvalidArgumentError);
    RigidTransform nan = x;
    nan.translation.x() = std::nan("");
    EXPECT_THROW(set_piece_transform(mesh, 0, nan), InvalidArgumentError);
    EXPECT_EQ(mesh.piece_transforms[0], x);
}

// The welding tests' fracture: five Voronoi cells from seed 3, exact walls or along tet faces.
FractureResult fracture_into_five(TetMesh& mesh, bool exact) {
    FractureOptions options;
    options.exact = exact;
    return fracture_voronoi(mesh, scatter_fracture_seeds(mesh, 5, 3), options);
}

TEST(Weld, FractureThenWeldInPlaceRestoresOnePiece) {
    const TetMesh before = make_cube_mesh(5);
    const double area_before = boundary_area(before, build_connectivity(before));
    for (bool exact : {true, false}) {
        TetMesh mesh = before;
        const FractureResult f = fracture_into_five(mesh, exact);
        ASSERT_GT(f.pieces_after, 1);
        const TetMesh fractured = mesh;
        const WeldResult w = weld_touching_pieces(mesh, 1e-9);
        EXPECT_EQ(w.pieces_before, f.pieces_after);
        EXPECT_EQ(w.pieces_after, 1);
        EXPECT_EQ(w.vertices_merged, f.vertices_duplicated);
        // The vertex map: merged vertices go, the others keep their order and (in place) their position.
        ASSERT_EQ(w.old_to_new_vertex.size(), fractured.vertex_count());
        size_t merged = 0;
        int32_t last = -1;
        for (size_t v = 0; v < fractured.vertex_count(); ++v) {
            const int32_t to = w.old_to_new_vertex[v];
            if (to < 0) {
                ++merged;
                continue;
            }
            EXPECT_EQ(to, last + 1) << v;
            last = to;
            EXPECT_EQ(mesh.positions[static_cast<size_t>(to)], fractured.positions[v]) << v;
        }
        EXPECT_EQ(merged, w.vertices_merged);
        EXPECT_EQ(static_cast<size_t>(last + 1), mesh.vertex_count());
        const TetConnectivity c = expect_valid_conforming(mesh);
        EXPECT_EQ(c.component_count, 1);
        EXPECT_NEAR(total_volume(mesh), 1.0, 1e-12);
        EXPECT_NEAR(boundary_area(mesh, c), area_before, 1e-12);
    }
}

// Welding in place restores one piece whatever the tolerance: exact copies weld at 0 (the radius
// search keeps distances equal to it), and tolerances up to and beyond the edge length (0.2) weld as
// much as tiny ones. Pairing every vertex within the tolerance used to chain across the cracks from
// about half an edge on: at 0.1 a third of the crack faces stayed inside one piece, from 0.3 nothing
// welded.
TEST(Weld, EveryToleranceWeldsTheCracksOfAFractureInPlace) {
    const TetMesh before = make_cube_mesh(5);
    const double area_before = boundary_area(before, build_connectivity(before));
    for (bool exact : {true, false}) {
        TetMesh fractured = before;
        const FractureResult f = fracture_into_five(fractured, exact);
        ASSERT_GT(f.pieces_after, 1);
        for (const double tolerance : {0.0, 1e-9, 1e-4, 0.05, 0.1, 0.15, 0.3, 1.0, 10.0}) {
            TetMesh mesh = fractured;
            const WeldResult w = weld_touching_pieces(mesh, tolerance);
            EXPECT_EQ(w.pieces_after, 1) << tolerance << " exact " << exact;
            EXPECT_EQ(w.vertices_merged, f.vertices_duplicated) << tolerance << " exact " << exact;
            const TetConnectivity c = expect_valid_conforming(mesh);
            EXPECT_NEAR(boundary_area(mesh, c), area_before, 1e-12) << tolerance << " exact " << exact;
        }
    }
}

TEST(Weld, MovedApartPiecesStayApartAndMovedBackWeld) {
    TetMesh mesh = make_cube_mesh(4);
    const std::vector<Eigen::Vector4d> plane = {{1, 0, 0, 0.5}};
    ASSERT_EQ(fracture_planes(mesh, plane).pieces_after, 2);
    RigidTransform away;
    away.translation = Eigen::Vector3d(0.3, 0, 0);
    set_piece_transform(mesh, 1, away);
    const TetMesh apart = mesh;
    WeldResult w = weld_touching_pieces(mesh, 1e-6);
    EXPECT_EQ(w.pieces_after, 2);
    EXPECT_EQ(w.vertices_merged, 0u);
    EXPECT_EQ(mesh, apart);

    // Moved away and back: they touch again.
    {
        TetMesh back = apart;
        set_piece_transform(back, 1, RigidTransform{});
        EXPECT_EQ(weld_touching_pieces(back, 1e-9).pieces_after, 1);
        const TetConnectivity cb = expect_valid_conforming(back);
        EXPECT_NEAR(boundary_area(back, cb), 6.0, 1e-12);
    }

    // Move both pieces by the same rigid motion: they touch again, in a rotated frame.
    RigidTransform motion;
    motion.rotation = Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.2, 1, -0.4).normalized()).toRotationMatrix();
    motion.translation = Eigen::Vector3d(3, 1, -2);
    set_piece_transform(mesh, 0, motion);
    set_piece_transform(mesh, 1, motion);
    const double area_apart = boundary_area(mesh, build_connectivity(mesh));
    w = weld_touching_pieces(mesh, 1e-9);
    EXPECT_EQ(w.pieces_after, 1);
    ASSERT_EQ(mesh.piece_transforms.size(), 1u);
    EXPECT_EQ(mesh.piece_transforms[0], motion);
    const TetConnectivity c = expect_valid_conforming(mesh);
    EXPECT_NEAR(total_volume(mesh), 1.0, 1e-12);
    EXPECT_NEAR(boundary_area(mesh, c), 6.0, 1e-10);
    EXPECT_NEAR(area_apart - boundary_area(mesh, c), 2.0, 1e-10);  // the crack's two faces are gone

    // Pieces with different transforms whose world positions meet are re-expressed in the lowest
    // piece's frame.
    TetMesh other = make_cube_mesh(4);
    ASSERT_EQ(fracture_planes(other, plane).pieces_after, 2);
    RigidTransform shift;
    shift.translation = Eigen::Vector3d(0, 0, 1);
    // Express piece 1 in a frame shifted by +z, so its world positions are unchanged.
    std::vector<uint8_t> in_piece1(other.vertex_count(), 0);
    for (size_t t = 0; t < other.tet_count(); ++t)
        if (other.piece_ids[t] == 1)
            for (int32_t v : other.tets[t]) in_piece1[v] = 1;
    for (size_t v = 0; v < other.vertex_count(); ++v)
        if (in_piece1[v]) other.positions[v] -= shift.translation;
    set_piece_transform(other, 1, shift);
    EXPECT_EQ(weld_touching_pieces(other, 1e-9).pieces_after, 1);
    expect_valid_conforming(other);
    EXPECT_NEAR(total_volume(other), 1.0, 1e-12);
    EXPECT_EQ(other.piece_transforms[0], RigidTransform{});
    EXPECT_THROW(weld_touching_pieces(other, -1), InvalidArgumentError);
    EXPECT_THROW(weld_touching_pieces(other, std::nan("")), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
