// build_connectivity against a plain reference builder (maps, sets and a breadth-first search) on
// shuffled, holed, cut, fractured and welded meshes: every field must be equal, bit for bit, and the
// same on one thread as on all of them.
#include "base/error.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/exact_cut.h"
#include "tetops/fracture.h"
#include "tetops/test_meshes.h"
#include "tetops/tet_mesh.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <deque>
#include <map>
#include <random>
#include <set>
#include <vector>

namespace waxwork {
namespace {

using testing::make_cube_mesh;
using testing::shuffled_holed_cube;

// The connectivity as its definitions in connectivity.h state it, one field at a time.
TetConnectivity reference_connectivity(const TetMesh& mesh) {
    const size_t n = mesh.vertex_count(), tet_count = mesh.tet_count();
    TetConnectivity c;
    std::vector<std::vector<int32_t>> stars(n);
    std::vector<std::set<int32_t>> rings(n);
    std::map<std::array<int32_t, 3>, std::vector<std::pair<int32_t, int>>> faces;
    for (size_t t = 0; t < tet_count; ++t) {
        const Tet& tet = mesh.tets[t];
        for (int k = 0; k < 4; ++k) {
            stars[tet[k]].push_back(static_cast<int32_t>(t));
            for (int j = 0; j < 4; ++j)
                if (j != k) rings[tet[k]].insert(tet[j]);
        }
        for (int f = 0; f < 4; ++f) {
            std::array<int32_t, 3> key = {tet[kTetFaces[f][0]], tet[kTetFaces[f][1]], tet[kTetFaces[f][2]]};
            std::sort(key.begin(), key.end());
            faces[key].push_back({static_cast<int32_t>(t), f});
        }
    }
    auto rows_of = [](const auto& lists) {
        CompressedRows rows;
        for (const auto& list : lists) {
            rows.indices.insert(rows.indices.end(), list.begin(), list.end());
            rows.offsets.push_back(static_cast<int32_t>(rows.indices.size()));
        }
        return rows;
    };
    c.vertex_tets = rows_of(stars);
    c.vertex_vertices = rows_of(rings);
    for (size_t v = 0; v < n; ++v)
        for (int32_t u : rings[v])
            if (u > static_cast<int32_t>(v)) c.edges.push_back({static_cast<int32_t>(v), u});

    c.tet_neighbors.assign(tet_count, {-1, -1, -1, -1});
    for (const auto& [key, sides] : faces) {
        if (sides.size() > 2) throw InvalidMeshError("face shared by more than two tets");
        if (sides.size() == 2) {
            c.tet_neighbors[sides[0].first][sides[0].second] = sides[1].first;
            c.tet_neighbors[sides[1].first][sides[1].second] = sides[0].first;
        }
    }
    c.is_boundary_vertex.assign(n, 0);
    for (size_t t = 0; t < tet_count; ++t)
        for (int f = 0; f < 4; ++f)
            if (c.tet_neighbors[t][f] < 0) {
                const Tet& tet = mesh.tets[t];
                const std::array<int32_t, 3> v = {tet[kTetFaces[f][0]], tet[kTetFaces[f][1]], tet[kTetFaces[f][2]]};
                c.boundary_faces.push_back({v, static_cast<int32_t>(t), f});
                for (int32_t u : v) c.is_boundary_vertex[u] = 1;
            }
    for (size_t v = 0; v < n; ++v)
        if (c.is_boundary_vertex[v]) c.boundary_vertices.push_back(static_cast<int32_t>(v));

    // Components by breadth-first search from the lowest unlabelled tet: numbered by their lowest tet.
    c.tet_component.assign(tet_count, -1);
    for (size_t seed = 0; seed < tet_count; ++seed) {
        if (c.tet_component[seed] >= 0) continue;
        std::deque<int32_t> queue = {static_cast<int32_t>(seed)};
        c.tet_component[seed] = c.component_count;
        while (!queue.empty()) {
            const int32_t t = queue.front();
            queue.pop_front();
            for (int32_t o : c.tet_neighbors[t])
                if (o >= 0 && c.tet_component[o] < 0) {
                    c.tet_component[o] = c.component_count;
                    queue.push_back(o);
                }
        }
        ++c.component_count;
    }
    return c;
}

void expect_same_connectivity(const TetConnectivity& a, const TetConnectivity& b, const std::string& what) {
    SCOPED_TRACE(what);
    EXPECT_EQ(a.edges, b.edges);
    EXPECT_EQ(a.vertex_vertices.offsets, b.vertex_vertices.offsets);
    EXPECT_EQ(a.vertex_vertices.indices, b.vertex_vertices.indices);
    EXPECT_EQ(a.vertex_tets.offsets, b.vertex_tets.offsets);
    EXPECT_EQ(a.vertex_tets.indices, b.vertex_tets.indices);
    EXPECT_EQ(a.tet_neighbors, b.tet_neighbors);
    ASSERT_EQ(a.boundary_faces.size(), b.boundary_faces.size());
    for (size_t f = 0; f < a.boundary_faces.size(); ++f) {
        EXPECT_EQ(a.boundary_faces[f].vertices, b.boundary_faces[f].vertices) << "face " << f;
        EXPECT_EQ(a.boundary_faces[f].tet, b.boundary_faces[f].tet) << "face " << f;
        EXPECT_EQ(a.boundary_faces[f].local_face, b.boundary_faces[f].local_face) << "face " << f;
    }
    EXPECT_EQ(a.boundary_vertices, b.boundary_vertices);
    EXPECT_EQ(a.is_boundary_vertex, b.is_boundary_vertex);
    EXPECT_EQ(a.tet_component, b.tet_component);
    EXPECT_EQ(a.component_count, b.component_count);
}

// build_connectivity equals the reference, on every thread and on one, and build_face_neighbors
// equals its neighbours.
void expect_matches_reference(const TetMesh& mesh, const std::string& what) {
    const TetConnectivity reference = reference_connectivity(mesh);
    expect_same_connectivity(build_connectivity(mesh), reference, what + ", all threads");
    tbb::task_arena one_thread(1);
    one_thread.execute([&] { expect_same_connectivity(build_connectivity(mesh), reference, what + ", one thread"); });
    EXPECT_EQ(build_face_neighbors(mesh), reference.tet_neighbors) << what;
}

TEST(ConnectivityReference, ShuffledAndHoledCubes) {
    for (uint32_t seed = 1; seed <= 6; ++seed)
        for (double drop : {0.0, 0.2, 0.6})
            expect_matches_reference(shuffled_holed_cube(5 + static_cast<int>(seed % 3), drop, seed),
                                     "seed " + std::to_string(seed) + ", drop " + std::to_string(drop));
}

TEST(ConnectivityReference, LargeEnoughForSeveralSortBlocks) {
    // 100K tets: more than one block of the parallel counting sort.
    expect_matches_reference(shuffled_holed_cube(26, 0.1, 11), "26^3 cells");
}

TEST(ConnectivityReference, AfterCuts) {
    const TetMesh cube = shuffled_holed_cube(8, 0.0, 4);
    std::mt19937 rng(7);
    std::normal_distribution<double> gauss;
    for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d normal = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
        const PlaneCut plane(normal, normal.dot(Eigen::Vector3d::Constant(0.5)));
        TetMesh removed = cube;
        remove_cut_away_tets(removed, plane);
        expect_matches_reference(removed, "plane cut " + std::to_string(k));
        TetMesh exact = cube;
        cut_exact(exact, plane);
        expect_matches_reference(exact, "exact cut " + std::to_string(k));
    }
}

TEST(ConnectivityReference, AfterFracturesAndWelds) {
    for (bool exact : {true, false}) {
        TetMesh mesh = make_cube_mesh(6);
        FractureOptions options;
        options.exact = exact;
        const FractureResult fractured = fracture_voronoi(mesh, scatter_fracture_seeds(mesh, 5, 3), options);
        ASSERT_GT(fractured.pieces_after, 1);
        const std::string mode = exact ? "exact" : "along faces";
        expect_matches_reference(mesh, "fracture, " + mode);
        weld_touching_pieces(mesh, 1e-9);
        expect_matches_reference(mesh, "weld, " + mode);
    }
}

TEST(ConnectivityReference, RejectsBadMeshesNamingTheTet) {
    TetMesh overfull = make_tet_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.2, 0.2, 0.3}, {-1, -1, -1}},
                                     {{0, 1, 2, 3}, {0, 1, 2, 4}, {0, 1, 2, 5}});
    EXPECT_THROW(build_connectivity(overfull), InvalidMeshError);
    EXPECT_THROW(build_face_neighbors(overfull), InvalidMeshError);

    TetMesh out_of_range = make_cube_mesh(2);
    out_of_range.tets[7][2] = static_cast<int32_t>(out_of_range.vertex_count());
    out_of_range.tets[9][1] = -1;
    try {
        build_connectivity(out_of_range);
        ADD_FAILURE() << "no error";
    } catch (const InvalidMeshError& e) {
        EXPECT_NE(std::string(e.what()).find("tet 7 references vertex 27"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace waxwork
