// The diffusion matrix's pattern and incidences against a plain reference (sorted rows and a binary
// search per slot), on shuffled, holed and cut meshes, on every thread and on one.
#include "solver/diffusion_matrix.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/fracture.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <set>

namespace waxwork {
namespace {

using testing::make_cube_mesh;
using testing::shuffled_holed_cube;

// The slot of column `col` in row `row` (the reference's lookup).
int32_t slot_of(const DiffusionMatrix& m, int32_t row, int32_t col) {
    const auto begin = m.columns.begin() + m.offsets[row], end = m.columns.begin() + m.offsets[row + 1];
    const auto it = std::lower_bound(begin, end, col);
    EXPECT_TRUE(it != end && *it == col) << "column " << col << " missing in row " << row;
    return static_cast<int32_t>(it - m.columns.begin());
}

// Row i: i and every vertex sharing a tet with it, ascending; each incidence's slots by search.
DiffusionMatrix reference_pattern(const TetMesh& mesh, const TetConnectivity& conn) {
    const size_t n = mesh.vertex_count();
    std::vector<std::set<int32_t>> rows(n);
    for (size_t i = 0; i < n; ++i) rows[i].insert(static_cast<int32_t>(i));
    for (const Tet& tet : mesh.tets)
        for (int32_t a : tet)
            for (int32_t b : tet) rows[a].insert(b);
    DiffusionMatrix m;
    m.offsets = {0};
    for (size_t i = 0; i < n; ++i) {
        m.diagonal.push_back(static_cast<int32_t>(m.columns.size() + std::distance(rows[i].begin(), rows[i].find(static_cast<int32_t>(i)))));
        m.columns.insert(m.columns.end(), rows[i].begin(), rows[i].end());
        m.offsets.push_back(static_cast<int32_t>(m.columns.size()));
    }
    for (size_t i = 0; i < n; ++i)
        for (int32_t t : conn.vertex_tets.row(i)) {
            const Tet& tet = mesh.tets[t];
            DiffusionMatrix::TetIncidence inc{};
            inc.local = static_cast<int32_t>(std::find(tet.begin(), tet.end(), static_cast<int32_t>(i)) - tet.begin());
            int s = 0;
            for (int k = 0; k < 4; ++k)
                if (k != inc.local) inc.slots[s++] = slot_of(m, static_cast<int32_t>(i), tet[k]);
            m.tet_incidences.push_back(inc);
        }
    std::vector<std::vector<std::pair<int32_t, std::array<int32_t, 2>>>> faces(n);
    for (size_t f = 0; f < conn.boundary_faces.size(); ++f) {
        const auto& v = conn.boundary_faces[f].vertices;
        for (int a = 0; a < 3; ++a)
            faces[v[a]].push_back({static_cast<int32_t>(f),
                                   {slot_of(m, v[a], v[(a + 1) % 3]), slot_of(m, v[a], v[(a + 2) % 3])}});
    }
    for (size_t i = 0; i < n; ++i) {
        for (const auto& [f, slots] : faces[i]) {
            m.vertex_faces.push_back(f);
            m.vertex_face_slots.push_back(slots);
        }
        m.vertex_face_offsets.push_back(static_cast<int32_t>(m.vertex_faces.size()));
    }
    return m;
}

void expect_same_pattern(const DiffusionMatrix& a, const DiffusionMatrix& b, const std::string& what) {
    SCOPED_TRACE(what);
    EXPECT_EQ(a.offsets, b.offsets);
    EXPECT_EQ(a.columns, b.columns);
    EXPECT_EQ(a.diagonal, b.diagonal);
    ASSERT_EQ(a.tet_incidences.size(), b.tet_incidences.size());
    for (size_t k = 0; k < a.tet_incidences.size(); ++k) {
        EXPECT_EQ(a.tet_incidences[k].local, b.tet_incidences[k].local) << "incidence " << k;
        EXPECT_EQ(a.tet_incidences[k].slots, b.tet_incidences[k].slots) << "incidence " << k;
    }
    EXPECT_EQ(a.vertex_face_offsets, b.vertex_face_offsets);
    EXPECT_EQ(a.vertex_faces, b.vertex_faces);
    EXPECT_EQ(a.vertex_face_slots, b.vertex_face_slots);
}

void expect_pattern_matches_reference(const TetMesh& mesh, const std::string& what) {
    const TetConnectivity conn = build_connectivity(mesh);
    const DiffusionMatrix reference = reference_pattern(mesh, conn);
    expect_same_pattern(assemble_diffusion_pattern(mesh, conn), reference, what + ", all threads");
    tbb::task_arena one_thread(1);
    one_thread.execute(
        [&] { expect_same_pattern(assemble_diffusion_pattern(mesh, conn), reference, what + ", one thread"); });
}

TEST(DiffusionPattern, MatchesReferenceOnShuffledHoledAndCutMeshes) {
    for (uint32_t seed = 1; seed <= 3; ++seed)
        for (double drop : {0.0, 0.3})
            expect_pattern_matches_reference(shuffled_holed_cube(6, drop, seed),
                                             "seed " + std::to_string(seed) + ", drop " + std::to_string(drop));
    TetMesh cut = shuffled_holed_cube(7, 0.0, 9);
    const Eigen::Vector3d normal = Eigen::Vector3d(1, 0.4, -0.3).normalized();
    remove_cut_away_tets(cut, PlaneCut(normal, normal.dot(Eigen::Vector3d::Constant(0.5))));
    expect_pattern_matches_reference(cut, "plane cut");
    TetMesh fractured = make_cube_mesh(6);
    fracture_voronoi(fractured, scatter_fracture_seeds(fractured, 4, 2));
    expect_pattern_matches_reference(fractured, "exact fracture");
}

}  // namespace
}  // namespace waxwork
