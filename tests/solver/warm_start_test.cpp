// Extending a warm start over vertices without a value (solver/warm_start.h).
#include "base/error.h"
#include "solver/warm_start.h"
#include "tetops/exact_cut.h"
#include "tetops/fracture.h"
#include "solver_test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace waxwork {
namespace {

// The pattern of a path 0 - 1 - ... - (n-1) plus, when `split`, a second path that touches no other.
DiffusionMatrix path_pattern(int n, int split = 0) {
    DiffusionMatrix m;
    const int total = n + split;
    for (int v = 0; v < total; ++v) {
        const int first = v < n ? 0 : n, last = v < n ? n - 1 : total - 1;
        if (v > first) m.columns.push_back(v - 1);
        m.diagonal.push_back(static_cast<int32_t>(m.columns.size()));
        m.columns.push_back(v);
        if (v < last) m.columns.push_back(v + 1);
        m.offsets.push_back(static_cast<int32_t>(m.columns.size()));
    }
    return m;
}

std::array<std::vector<double>, 3> filled_with(size_t n, double value) {
    return {std::vector<double>(n, value), std::vector<double>(n, value), std::vector<double>(n, value)};
}

TEST(WarmStart, UnknownVerticesTakeTheirKnownNeighboursValuesBreadthFirst) {
    // Known: 0 (value 1, 2, 3) and 6 (value 7, 8, 9); 1..5 unknown, 7..8 a separate unknown path.
    const DiffusionMatrix m = path_pattern(7, 2);
    std::vector<uint8_t> known(9, 0);
    known[0] = known[6] = 1;
    auto values = filled_with(9, -5.0);
    for (size_t c = 0; c < 3; ++c) {
        values[c][0] = 1.0 + static_cast<double>(c);
        values[c][6] = 7.0 + static_cast<double>(c);
    }
    EXPECT_EQ(extend_to_unknown_vertices(m, known, values), 5u);
    for (size_t c = 0; c < 3; ++c) {
        const double a = values[c][0], b = values[c][6];
        EXPECT_EQ(values[c][1], a);  // pass 1: from 0 alone
        EXPECT_EQ(values[c][5], b);  // pass 1: from 6 alone
        EXPECT_EQ(values[c][2], a);  // pass 2: from 1
        EXPECT_EQ(values[c][4], b);
        EXPECT_EQ(values[c][3], 0.5 * (a + b));  // pass 3: from 2 and 4, both of pass 2
        EXPECT_EQ(values[c][7], -5.0);  // no known vertex reaches the second path
        EXPECT_EQ(values[c][8], -5.0);
    }
    // Known values never change, and a constant stays constant.
    auto constant = filled_with(9, 0.0);
    for (auto& channel : constant) channel[0] = channel[6] = 2.5;
    extend_to_unknown_vertices(m, known, constant);
    for (size_t v = 0; v < 7; ++v) EXPECT_EQ(constant[1][v], 2.5) << v;
}

TEST(WarmStart, NothingKnownOrEverythingKnownChangesNothingAndSizesAreChecked) {
    const DiffusionMatrix m = path_pattern(5);
    auto values = filled_with(5, 3.0);
    EXPECT_EQ(extend_to_unknown_vertices(m, std::vector<uint8_t>(5, 0), values), 0u);
    EXPECT_EQ(extend_to_unknown_vertices(m, std::vector<uint8_t>(5, 1), values), 0u);
    for (const auto& channel : values) EXPECT_TRUE(std::all_of(channel.begin(), channel.end(), [](double x) { return x == 3.0; }));
    EXPECT_THROW(extend_to_unknown_vertices(m, std::vector<uint8_t>(4, 0), values), InvalidArgumentError);
    auto short_values = filled_with(4, 0.0);
    EXPECT_THROW(extend_to_unknown_vertices(m, std::vector<uint8_t>(5, 1), short_values), InvalidArgumentError);
}

TEST(WarmStart, AVertexMapCarriesValuesToTheVerticesItNames) {
    auto before = filled_with(4, 0.0);
    for (size_t c = 0; c < 3; ++c)
        for (size_t v = 0; v < 4; ++v) before[c][v] = 10.0 * static_cast<double>(c) + static_cast<double>(v);
    // 0 -> 2, 1 removed, 2 -> 0, 3 outside the 3 vertices after: only 0 and 2 are placed.
    const std::vector<int32_t> map = {2, -1, 0, 3};
    const CarriedValues after = carry_through_vertex_map(before, map, 3);
    EXPECT_EQ(after.known, (std::vector<uint8_t>{1, 0, 1}));
    for (size_t c = 0; c < 3; ++c) {
        EXPECT_EQ(after.values[c][0], before[c][2]);
        EXPECT_EQ(after.values[c][1], 0.0);
        EXPECT_EQ(after.values[c][2], before[c][0]);
    }
    EXPECT_THROW(carry_through_vertex_map(before, std::vector<int32_t>{0, 1}, 3), InvalidArgumentError);
}

// Values linear in position before an edit are linear after it when the vertices made on edges sit
// where their origins say (nothing moves them: no snapping, bending or smoothing): the carry uses each
// vertex's crossing parameter, which an oblique cut or a Voronoi wall puts far from the edge's middle.
TEST(WarmStart, OriginsCarryALinearFieldExactlyAcrossAnExactCutAndAFracture) {
    const TetMesh cube = test::make_cube_mesh(6, 1.0 / 6);
    const auto linear = [](const Eigen::Vector3d& x, size_t c) {
        return 0.3 + static_cast<double>(c) + Eigen::Vector3d(1.0, -2.0 + static_cast<double>(c), 0.5).dot(x);
    };
    std::array<std::vector<double>, 3> before;
    for (size_t c = 0; c < 3; ++c)
        for (const Eigen::Vector3d& x : cube.positions) before[c].push_back(linear(x, c));
    const auto expect_linear_after = [&](const TetMesh& mesh, const std::vector<VertexOrigin>& origins) {
        const CarriedValues after = carry_through_origins(before, origins);
        ASSERT_EQ(after.known.size(), mesh.vertex_count());
        double off_middle = 0;
        for (size_t v = 0; v < mesh.vertex_count(); ++v) {
            EXPECT_EQ(after.known[v], 1) << v;
            for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(after.values[c][v], linear(mesh.positions[v], c), 1e-12) << v;
            if (!origins[v].is_vertex()) off_middle = std::max(off_middle, std::abs(origins[v].t - 0.5));
        }
        EXPECT_GT(off_middle, 0.25);  // the edges' midpoints would be off the field
    };
    TetMesh cut = cube;
    ExactCutOptions fixed_cut;
    fixed_cut.split.snap_fraction = 0;
    fixed_cut.split.smooth_below_deg = 0;
    const ExactCutResult cut_result = cut_exact(cut, PlaneCut(Eigen::Vector3d(1.0, 0.7, 0.45), 1.13), fixed_cut);
    ASSERT_GT(cut_result.vertices_added, 0u);
    expect_linear_after(cut, cut_result.vertex_origins);

    TetMesh fractured = cube;
    FractureOptions fixed_fracture;
    fixed_fracture.snap_fraction = 0;
    fixed_fracture.boundary_bend_deg = 0;
    fixed_fracture.smooth_below_deg = 0;
    const FractureResult fracture = fracture_voronoi(fractured, scatter_fracture_seeds(cube, 6, 3), fixed_fracture);
    ASSERT_GT(fracture.tets_split, 0u);
    ASSERT_GT(fracture.vertices_duplicated, 0u);
    expect_linear_after(fractured, fracture.vertex_origins);
}

TEST(WarmStart, OriginsNamingVerticesWithoutAValueCarryNothing) {
    const std::array<std::vector<double>, 3> before = filled_with(2, 4.0);
    // 0 kept; 1 on edge 0-1 at 0.25; 2 names vertex 3, not placed yet; 3 out of range; 4 a bad
    // parameter; 5 copies 1, placed.
    const std::vector<VertexOrigin> origins = {VertexOrigin::vertex(0), {0, 1, 0.25}, {0, 3, 0.5}, {0, 7, 0.5},
                                               {0, 1, std::nan("")}, VertexOrigin::vertex(1)};
    const CarriedValues after = carry_through_origins(before, origins);
    EXPECT_EQ(after.known, (std::vector<uint8_t>{1, 1, 0, 0, 0, 1}));
    for (size_t c = 0; c < 3; ++c) {
        EXPECT_EQ(after.values[c][1], 4.0);
        EXPECT_EQ(after.values[c][2], 0.0);
        EXPECT_EQ(after.values[c][4], 0.0);
    }
}

}  // namespace
}  // namespace waxwork
