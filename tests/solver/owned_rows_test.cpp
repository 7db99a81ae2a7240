// One process's rows of the diffusion system (solver/owned_rows.h): equal to the whole assembly's rows,
// right-hand side and crease corners included, whatever the range; the partition and its edge cut.
#include "solver/owned_rows.h"

#include "base/error.h"
#include "solver/material.h"
#include "solver/solved_scene.h"
#include "tetops/box_mesh.h"
#include "tetops/connectivity.h"
#include "tetops/spatial_order.h"

#include <gtest/gtest.h>

#include <set>
#include <utility>

namespace waxwork {
namespace {

TEST(BalancedRowRange, CoversTheRowsInOrderWithSizesDifferingByAtMostOne) {
    for (const auto& [rows, ranks] : {std::pair<size_t, int>{10, 3}, {7, 7}, {1000, 4}, {5, 1}}) {
        int32_t next = 0;
        for (int r = 0; r < ranks; ++r) {
            const RowRange range = balanced_row_range(rows, ranks, r);
            EXPECT_EQ(range.begin, next);
            EXPECT_GE(range.size(), static_cast<int32_t>(rows / ranks));
            EXPECT_LE(range.size(), static_cast<int32_t>(rows / ranks + 1));
            next = range.end;
        }
        EXPECT_EQ(next, static_cast<int32_t>(rows));
    }
}

TEST(BalancedRowRange, RefusesMoreRanksThanRows) {
    EXPECT_THROW(balanced_row_range(4, 5, 0), InvalidArgumentError);
    EXPECT_THROW(balanced_row_range(4, 2, 2), InvalidArgumentError);
}

// A lit box, Morton ordered as fresh meshes are, plus one vertex of no tet (an identity row).
struct LitBox {
    TetMesh mesh;
    TetConnectivity connectivity;
    std::vector<TetMaterial> materials;
    LitScene lit;
    std::vector<PortableCornerLight> corners;

    LitBox() {
        mesh = make_box_mesh({4, 3, 5}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 3, 5));
        sort_spatially(mesh);
        mesh.positions.push_back(Eigen::Vector3d(9, 9, 9));
        connectivity = build_connectivity(mesh);
        materials.assign(mesh.tet_count(), material_preset("skin1"));
        Lighting lighting;
        // Oblique: three faces of the box lit, so its edges are creases with corner light.
        lighting.lights = {Light{LightType::Directional, Eigen::Vector3d(-1, -0.7, -0.4), {1, 0.8, 0.6}}};
        lit = light_scene(mesh, connectivity, materials, lighting);
        for (const CornerLight& c : lit.corners) {
            const BoundaryFace& face = connectivity.boundary_faces[c.face];
            corners.push_back({face.tet, face.local_face, c.vertices, c.delta});
        }
    }
};

TEST(OwnedRows, EqualTheWholeAssemblysRowsAndRightHandSide) {
    const LitBox box;
    ASSERT_FALSE(box.corners.empty());
    for (const Discretization discretization : {Discretization::TransCut, Discretization::Fem}) {
        AssemblyOptions options;
        options.discretization = discretization;
        options.mm_per_unit = 3;
        const DiffusionMatrix whole = assemble_diffusion_matrix(box.mesh, box.connectivity, box.materials, options);
        std::array<std::vector<double>, 3> b;
        for (int c = 0; c < 3; ++c) {
            b[c].resize(whole.size());
            diffusion_right_hand_side(whole, box.lit.scene.q, c, b[c]);
            add_corner_light(whole, box.lit.corners, c, b[c]);
        }
        const int ranks = 3;
        for (int r = 0; r < ranks; ++r) {
            const RowRange range = balanced_row_range(box.mesh.vertex_count(), ranks, r);
            const OwnedRows rows = assemble_owned_rows(box.mesh, box.materials, box.lit.scene.q, box.corners, range, options);
            EXPECT_LT(rows.local_tets, box.mesh.tet_count());
            ASSERT_EQ(rows.offsets.size(), static_cast<size_t>(range.size()) + 1);
            for (int32_t i = 0; i < range.size(); ++i) {
                const int32_t v = range.begin + i;
                const auto first = whole.offsets[v], count = whole.offsets[v + 1] - first;
                ASSERT_EQ(rows.offsets[i + 1] - rows.offsets[i], count) << "row " << v;
                int32_t inside = 0;
                for (int32_t k = 0; k < count; ++k) {
                    const int32_t column = rows.columns[rows.offsets[i] + k];
                    EXPECT_EQ(column, whole.columns[first + k]);
                    inside += range.contains(column);
                    for (int c = 0; c < 3; ++c)
                        EXPECT_DOUBLE_EQ(rows.values[c][rows.offsets[i] + k], whole.values[c][first + k]) << "row " << v;
                }
                EXPECT_EQ(rows.inside_count[i], inside);
                EXPECT_EQ(rows.outside_count[i], count - inside);
                for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(rows.rhs[c][i], b[c][v]) << "row " << v << " channel " << c;
            }
        }
    }
}

TEST(OwnedRows, EdgeCountsSumToTheMeshsEdgesAndTheirCut) {
    const LitBox box;
    for (const int ranks : {1, 2, 5}) {
        std::vector<RowRange> ranges;
        EdgeCount total;
        for (int r = 0; r < ranks; ++r) {
            ranges.push_back(balanced_row_range(box.mesh.vertex_count(), ranks, r));
            const OwnedRows rows =
                assemble_owned_rows(box.mesh, box.materials, box.lit.scene.q, box.corners, ranges.back(), {});
            const EdgeCount count = owned_edge_count(rows);
            total.edges += count.edges;
            total.cut += count.cut;
        }
        const auto owner = [&](int32_t v) {
            for (int r = 0; r < ranks; ++r)
                if (ranges[r].contains(v)) return r;
            return -1;
        };
        int64_t cut = 0;
        for (const auto& [a, b] : box.connectivity.edges) cut += owner(a) != owner(b);
        EXPECT_EQ(total.edges, static_cast<int64_t>(box.connectivity.edges.size())) << ranks << " ranks";
        EXPECT_EQ(total.cut, cut) << ranks << " ranks";
        if (ranks == 1) {
            EXPECT_EQ(total.cut, 0);
        }
    }
}

TEST(OwnedRows, RefusesMismatchedSizes) {
    const LitBox box;
    std::vector<std::array<double, 3>> short_q(box.mesh.vertex_count() - 1);
    EXPECT_THROW(assemble_owned_rows(box.mesh, box.materials, short_q, {}, {0, 1}, {}), InvalidArgumentError);
    EXPECT_THROW(assemble_owned_rows(box.mesh, box.materials, box.lit.scene.q, {},
                                     {0, static_cast<int32_t>(box.mesh.vertex_count()) + 1}, {}),
                 InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
