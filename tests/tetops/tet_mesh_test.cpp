#include "base/error.h"
#include "tetops/connectivity.h"
#include "tetops/quality.h"
#include "tetops/spatial_order.h"
#include "tetops/test_meshes.h"
#include "tetops/tet_mesh.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <random>
#include <set>

namespace waxwork {
namespace {
using testing::make_cube_mesh;

TEST(TetMesh, MakeReorientsNegativeTets) {
    std::vector<Eigen::Vector3d> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    TetMesh mesh = make_tet_mesh(p, {{0, 1, 3, 2}});
    EXPECT_GT(signed_volume(mesh, 0), 0);
    EXPECT_NEAR(total_volume(mesh), 1.0 / 6.0, 1e-15);
    EXPECT_EQ(mesh.original_ids, std::vector<int32_t>{0});
    EXPECT_EQ(mesh.piece_ids, std::vector<int32_t>{0});
    EXPECT_EQ(mesh.piece_transforms.size(), 1u);
    EXPECT_TRUE(find_invariant_violations(mesh).empty());
}

TEST(TetMesh, MakeRejectsDegenerateAndOutOfRange) {
    std::vector<Eigen::Vector3d> p = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 0, 1}};
    EXPECT_THROW(make_tet_mesh(p, {{0, 1, 2, 3}}), InvalidMeshError);  // collinear base: flat
    EXPECT_THROW(make_tet_mesh(p, {{0, 1, 2, 7}}), InvalidMeshError);
}

TEST(TetMesh, ValidateFindsEveryKindOfViolation) {
    TetMesh good = make_cube_mesh(2);
    EXPECT_NO_THROW(validate(good));

    TetMesh inverted = good;
    std::swap(inverted.tets[3][0], inverted.tets[3][1]);
    EXPECT_THROW(validate(inverted), InvalidMeshError);

    TetMesh nan_point = good;
    nan_point.positions[0].x() = std::nan("");
    EXPECT_FALSE(find_invariant_violations(nan_point).empty());

    TetMesh bad_piece = good;
    bad_piece.piece_ids[0] = 5;
    EXPECT_FALSE(find_invariant_violations(bad_piece).empty());

    TetMesh bad_material = good;
    bad_material.materials.assign(good.tet_count(), TetMaterial{{0.1, 0.1, 0.1}, {1, 1, 1}, 1.3});
    EXPECT_TRUE(find_invariant_violations(bad_material).empty());
    // Stored materials must be solvable (material_problem): whatever a reader accepts or a save writes
    // can be rendered.
    const auto first_violation_with = [&](int tet, auto change) {
        TetMesh mesh = bad_material;
        change(mesh.materials[tet]);
        const std::vector<std::string> violations = find_invariant_violations(mesh);
        return violations.empty() ? std::string("(none)") : violations[0];
    };
    EXPECT_NE(first_violation_with(2, [](TetMaterial& m) { m.musp[1] = -1; })
                  .find("tet 2's material: mu_s' = -1 must be positive"),
              std::string::npos);
    EXPECT_NE(first_violation_with(2, [](TetMaterial& m) { m.musp[0] = 0; }).find("(channel r)"), std::string::npos);
    EXPECT_NE(first_violation_with(1, [](TetMaterial& m) { m.eta = 0; })
                  .find("tet 1's material: eta = 0 is outside [1, 3]"),
              std::string::npos);
    EXPECT_NE(first_violation_with(1, [](TetMaterial& m) { m.eta = 1e308; }).find("eta = 1e+308 is outside"),
              std::string::npos);
    EXPECT_NE(first_violation_with(0, [](TetMaterial& m) { m.mua[2] = 1e308; }).find("coefficient above 1e4 per mm"),
              std::string::npos);
    EXPECT_NE(first_violation_with(0, [](TetMaterial& m) { m.mua[2] = std::nan(""); }).find("mu_a is not finite"),
              std::string::npos);

    TetMesh short_ids = good;
    short_ids.original_ids.pop_back();
    EXPECT_FALSE(find_invariant_violations(short_ids).empty());

    TetMesh unreferenced = good;
    unreferenced.positions.push_back({5, 5, 5});
    EXPECT_FALSE(find_invariant_violations(unreferenced).empty());

    TetMesh triple_face = good;  // a third tet on an existing face
    const Tet& t0 = good.tets[0];
    triple_face.positions.push_back({-3, -3, -3});
    triple_face.tets.push_back({t0[1], t0[2], t0[3], static_cast<int32_t>(good.positions.size())});
    triple_face.tets.push_back({t0[1], t0[2], t0[3], static_cast<int32_t>(good.positions.size())});
    triple_face.original_ids.resize(triple_face.tets.size(), 0);
    triple_face.piece_ids.resize(triple_face.tets.size(), 0);
    EXPECT_FALSE(find_invariant_violations(triple_face).empty());

    const auto has = [](const std::vector<std::string>& violations, const std::string& text) {
        for (const std::string& v : violations)
            if (v.find(text) != std::string::npos) return true;
        return false;
    };
    // A tet listed twice: every face is shared by two tets, but both lie on the same side of it.
    TetMesh twice = good;
    twice.tets.push_back(good.tets[3]);
    twice.original_ids.push_back(0);
    twice.piece_ids.push_back(0);
    EXPECT_TRUE(has(find_invariant_violations(twice), "tets 3 and " + std::to_string(good.tet_count()) + " overlap"));
    // A tet folded over its neighbour's face (positively oriented, on the neighbour's side of it).
    TetMesh folded;
    folded.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.2, 0.2, 0.2}};
    folded.tets = {{0, 1, 2, 3}, {0, 1, 2, 4}};  // vertex 4 is on vertex 3's side of face (0, 1, 2)
    folded.original_ids = {0, 1};
    folded.piece_ids = {0, 0};
    folded.piece_transforms = {RigidTransform{}};
    ASSERT_GT(signed_volume(folded, 1), 0);
    EXPECT_TRUE(has(find_invariant_violations(folded), "both lie on the same side of their shared face (0, 1, 2)"));
    folded.positions[4] = {0.2, 0.2, -0.2};  // the other side: a valid pair
    folded.tets[1] = {0, 2, 1, 4};
    ASSERT_GT(signed_volume(folded, 1), 0);
    EXPECT_TRUE(find_invariant_violations(folded).empty());
    // Coordinates and moves beyond what the float renderer can multiply: refused whether they overflow
    // float itself (3.5e38) or only its products (1e13), while a valid mesh just inside is kept.
    for (const double reach : {1e300, 3.5e38, 1e13}) {
        TetMesh far = good;
        for (auto& p : far.positions) p *= reach;
        EXPECT_TRUE(has(find_invariant_violations(far), "lies beyond 1e12 (the renderer's float arithmetic would overflow)"))
            << reach;
        TetMesh far_move = good;
        far_move.piece_transforms[0].translation.x() = reach;
        EXPECT_TRUE(has(find_invariant_violations(far_move), "moves beyond 1e12")) << reach;
    }
    TetMesh large = good;
    double largest = 0;
    for (const auto& p : large.positions) largest = std::max(largest, p.cwiseAbs().maxCoeff());
    for (auto& p : large.positions) p *= 0.9e12 / largest;
    EXPECT_TRUE(find_invariant_violations(large).empty());
}

TEST(TetMesh, ValidateReportIsBoundedForBadlyBrokenMeshes) {
    TetMesh mesh = make_cube_mesh(6);
    for (auto& p : mesh.positions) p.x() = std::nan("");
    const auto violations = find_invariant_violations(mesh);
    EXPECT_LT(violations.size(), 20u);
}

TEST(Connectivity, SingleTet) {
    TetMesh mesh = make_tet_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 1, 2, 3}});
    const TetConnectivity c = build_connectivity(mesh);
    EXPECT_EQ(c.edges.size(), 6u);
    EXPECT_EQ(c.boundary_faces.size(), 4u);
    EXPECT_EQ(c.boundary_vertices.size(), 4u);
    EXPECT_EQ(c.component_count, 1);
    for (int v = 0; v < 4; ++v) EXPECT_EQ(c.vertex_vertices.row(v).size(), 3u);
}

// Outward orientation: the sum over boundary faces of the divergence-theorem volume term equals the
// tet volume sum; with inward faces it would be negative.
double volume_from_boundary(const TetMesh& mesh, const TetConnectivity& c) {
    double volume = 0;
    for (const BoundaryFace& f : c.boundary_faces) {
        const auto& a = mesh.positions[f.vertices[0]];
        const auto& b = mesh.positions[f.vertices[1]];
        const auto& d = mesh.positions[f.vertices[2]];
        volume += a.dot(b.cross(d)) / 6.0;
    }
    return volume;
}

TEST(Connectivity, CubeCountsMatchEuler) {
    const int n = 4;
    TetMesh mesh = make_cube_mesh(n);
    const TetConnectivity c = build_connectivity(mesh);
    const size_t V = mesh.vertex_count(), T = mesh.tet_count();
    // Faces: each tet has 4 faces, interior ones are shared by 2: F = (4T + Fb)/2.
    const size_t Fb = c.boundary_faces.size();
    EXPECT_EQ(Fb, 6u * 2 * n * n);
    const size_t F = (4 * T + Fb) / 2;
    // Euler characteristic of a ball: V - E + F - T = 1.
    EXPECT_EQ(static_cast<long>(V) - static_cast<long>(c.edges.size()) + static_cast<long>(F) - static_cast<long>(T), 1);
    EXPECT_EQ(c.boundary_vertices.size(), static_cast<size_t>((n + 1) * (n + 1) * (n + 1) - (n - 1) * (n - 1) * (n - 1)));
    EXPECT_NEAR(volume_from_boundary(mesh, c), 1.0, 1e-12);
    EXPECT_EQ(c.component_count, 1);
}

TEST(Connectivity, NeighborsAreSymmetricAndShareAFace) {
    TetMesh mesh = make_cube_mesh(3);
    const TetConnectivity c = build_connectivity(mesh);
    for (size_t t = 0; t < mesh.tet_count(); ++t)
        for (int f = 0; f < 4; ++f) {
            const int32_t o = c.tet_neighbors[t][f];
            if (o < 0) continue;
            const auto& back = c.tet_neighbors[o];
            EXPECT_NE(std::find(back.begin(), back.end(), static_cast<int32_t>(t)), back.end());
            std::set<int32_t> shared;
            for (int32_t v : mesh.tets[t])
                if (std::find(mesh.tets[o].begin(), mesh.tets[o].end(), v) != mesh.tets[o].end()) shared.insert(v);
            EXPECT_EQ(shared.size(), 3u);
            EXPECT_EQ(shared.count(mesh.tets[t][f]), 0u);  // the face opposite local vertex f
        }
}

TEST(Connectivity, OneRingsMatchEdges) {
    TetMesh mesh = make_cube_mesh(3);
    const TetConnectivity c = build_connectivity(mesh);
    size_t directed = 0;
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        const auto row = c.vertex_vertices.row(v);
        EXPECT_TRUE(std::is_sorted(row.begin(), row.end()));
        directed += row.size();
        for (int32_t t : c.vertex_tets.row(v))
            EXPECT_NE(std::find(mesh.tets[t].begin(), mesh.tets[t].end(), static_cast<int32_t>(v)), mesh.tets[t].end());
    }
    EXPECT_EQ(directed, 2 * c.edges.size());
    EXPECT_TRUE(std::is_sorted(c.edges.begin(), c.edges.end()));
    for (const auto& e : c.edges) EXPECT_LT(e[0], e[1]);
}

TEST(Connectivity, TwoComponents) {
    TetMesh mesh = join_meshes(make_cube_mesh(2), make_cube_mesh(2, Eigen::Vector3d(3, 0, 0)));
    const TetConnectivity c = build_connectivity(mesh);
    EXPECT_EQ(c.component_count, 2);
    const size_t half = mesh.tet_count() / 2;
    for (size_t t = 0; t < mesh.tet_count(); ++t) EXPECT_EQ(c.tet_component[t], t < half ? 0 : 1);
    EXPECT_NEAR(volume_from_boundary(mesh, c), 2.0, 1e-12);
}

TEST(Connectivity, RejectsFaceSharedByThreeTets) {
    TetMesh mesh = make_tet_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.2, 0.2, 0.3}, {-1, -1, -1}},
                                 {{0, 1, 2, 3}, {0, 1, 2, 4}, {0, 1, 2, 5}});
    EXPECT_THROW(build_connectivity(mesh), InvalidMeshError);
}

TEST(Quality, RegularTet) {
    const Eigen::Vector3d p0(1, 1, 1), p1(1, -1, -1), p2(-1, 1, -1), p3(-1, -1, 1);
    const double expected = std::acos(1.0 / 3.0) * 180.0 / std::numbers::pi;  // 70.53 degrees
    for (double a : dihedral_angles_deg(p0, p1, p2, p3)) EXPECT_NEAR(a, expected, 1e-9);
    EXPECT_NEAR(radius_edge_ratio(p0, p1, p2, p3), std::sqrt(6.0) / 4.0, 1e-12);
}

TEST(Quality, CornerTetAnglesAndReport) {
    // The corner tet of a cube has three right dihedral angles at the corner edges and
    // three of acos(1/sqrt(3)) = 54.74 degrees at the far edges.
    const auto angles = dihedral_angles_deg({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1});
    std::vector<double> sorted(angles.begin(), angles.end());
    std::sort(sorted.begin(), sorted.end());
    const double far = std::acos(1.0 / std::sqrt(3.0)) * 180.0 / std::numbers::pi;
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(sorted[i], far, 1e-9);
    for (int i = 3; i < 6; ++i) EXPECT_NEAR(sorted[i], 90.0, 1e-9);

    TetMesh mesh = make_cube_mesh(2);
    const QualityReport q = measure_quality(mesh);
    EXPECT_NEAR(q.min_dihedral_deg, 45.0, 1e-9);  // Kuhn tets: angles of 45, 60 and 90 degrees
    EXPECT_NEAR(q.max_dihedral_deg, 90.0, 1e-9);
    EXPECT_EQ(q.tets_below_5_deg, 0u);
    EXPECT_NEAR(q.min_edge_length, 0.5, 1e-12);
}

TEST(Quality, MinimumAngleIsTheSmallestOfTheSix) {
    // min_dihedral_angle_deg takes one acos of the smallest cosine: the same as the smallest of
    // dihedral_angles_deg, on random tets, slivers (a point pulled onto the opposite face) and
    // degenerate ones (0).
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (int i = 0; i < 2000; ++i) {
        Eigen::Vector3d p[4];
        for (auto& x : p) x = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
        if (i % 3 == 0) p[3] = (p[0] + p[1] + p[2]) / 3 + std::pow(10.0, -1 - i % 12) * (p[3] - p[0]);
        const auto angles = dihedral_angles_deg(p[0], p[1], p[2], p[3]);
        EXPECT_NEAR(min_dihedral_angle_deg(p[0], p[1], p[2], p[3]), *std::min_element(angles.begin(), angles.end()),
                    1e-9)
            << i;
    }
    const Eigen::Vector3d o = Eigen::Vector3d::Zero(), x = Eigen::Vector3d::UnitX();
    EXPECT_EQ(min_dihedral_angle_deg(o, x, 2 * x, Eigen::Vector3d::UnitY()), 0.0);
}

TEST(Quality, SliverIsCounted) {
    // Four nearly coplanar points: a sliver with tiny dihedral angles.
    TetMesh mesh = make_tet_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0.001}, {0, 1, 0}}, {{0, 1, 2, 3}});
    const QualityReport q = measure_quality(mesh);
    EXPECT_LT(q.min_dihedral_deg, 1.0);
    EXPECT_GT(q.max_dihedral_deg, 179.0);
    EXPECT_EQ(q.tets_below_5_deg, 1u);
    // A sliver's circumradius is about half its diagonal, so its radius-edge ratio stays near 0.7:
    // the ratio alone cannot see slivers, which is why the dihedral bound matters.
    EXPECT_LT(q.max_radius_edge_ratio, 1.0);
}

}  // namespace
}  // namespace waxwork

namespace waxwork {
namespace {

// `info` prints the volume and the mean edge and radius-edge ratio: their sums must not depend on how
// many threads split the tets (they differed in the last digits from run to run).
TEST(Quality, SumsDoNotDependOnTheThreads) {
    TetMesh mesh = make_cube_mesh(24);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> jitter(-0.2, 0.2);
    for (Eigen::Vector3d& p : mesh.positions) p += Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng)) / 24;
    const auto measure = [&](int threads) {
        tbb::task_arena arena(threads);
        std::pair<double, QualityReport> out;
        arena.execute([&] { out = {total_volume(mesh), measure_quality(mesh)}; });
        return out;
    };
    const auto [volume, quality] = measure(1);
    for (const int threads : {2, 3, 8}) {
        const auto [v, q] = measure(threads);
        EXPECT_EQ(v, volume) << threads << " threads";
        EXPECT_EQ(q.mean_edge_length, quality.mean_edge_length) << threads << " threads";
        EXPECT_EQ(q.mean_radius_edge_ratio, quality.mean_radius_edge_ratio) << threads << " threads";
    }
}

TEST(SpatialOrder, KeepsTheMeshAndImprovesLocality) {
    // Scramble a structured cube, then sort it back into spatial order.
    TetMesh mesh = testing::make_cube_mesh(6);
    std::vector<int32_t> perm(mesh.tet_count());
    std::iota(perm.begin(), perm.end(), 0);
    std::shuffle(perm.begin(), perm.end(), std::mt19937(7));
    std::vector<Tet> shuffled;
    for (int32_t t : perm) shuffled.push_back(mesh.tets[t]);
    TetMesh scrambled = make_tet_mesh(mesh.positions, shuffled);
    scrambled.materials.resize(scrambled.tet_count());
    for (size_t t = 0; t < scrambled.tet_count(); ++t) scrambled.materials[t] = TetMaterial{{0.1, 0.1, 0.1}, {1, 1, 1}, 1.0 + double(t) / 1e6};
    const double volume = total_volume(scrambled);

    // The mean index distance between face neighbours measures memory locality.
    auto neighbor_spread = [](const TetMesh& m) {
        const TetConnectivity c = build_connectivity(m);
        double sum = 0;
        size_t count = 0;
        for (size_t t = 0; t < m.tet_count(); ++t)
            for (int32_t o : c.tet_neighbors[t])
                if (o >= 0) sum += std::abs(double(o) - double(t)), ++count;
        return sum / double(count);
    };
    TetMesh sorted = scrambled;
    sort_spatially(sorted);
    EXPECT_NO_THROW(validate(sorted));
    EXPECT_NEAR(total_volume(sorted), volume, 1e-12);
    EXPECT_LT(neighbor_spread(sorted), 0.25 * neighbor_spread(scrambled));
    // Materials moved with their tets: the multiset of tet (centroid, eta) pairs is unchanged.
    auto tagged = [](const TetMesh& m) {
        std::vector<std::array<double, 4>> rows;
        for (size_t t = 0; t < m.tet_count(); ++t) {
            Eigen::Vector3d c = Eigen::Vector3d::Zero();
            for (int32_t v : m.tets[t]) c += m.positions[v];
            rows.push_back({c.x(), c.y(), c.z(), m.materials[t].eta});
        }
        std::sort(rows.begin(), rows.end());
        return rows;
    };
    EXPECT_EQ(tagged(sorted), tagged(scrambled));
    // Vertices are numbered in order of first use.
    int32_t next = 0;
    for (const Tet& tet : sorted.tets)
        for (int32_t v : tet) {
            EXPECT_LE(v, next);
            if (v == next) ++next;
        }
}

}  // namespace
}  // namespace waxwork
