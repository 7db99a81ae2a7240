// The regular grid the grid methods solve on: point location, interior and boundary links (also
// across cracks and slits whose faces coincide), crossings, and sampling back at the vertices.
#include "base/error.h"
#include "solver/methods/voxel_grid.h"
#include "grid_test_meshes.h"
#include "solver_test_meshes.h"
#include "tetops/box_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace waxwork {
namespace {

std::array<double, 3> linear_q(const Eigen::Vector3d& p) { return {1 + p.x(), 2 + 2 * p.y(), 3 + 3 * p.z()}; }

// A volume whose q is linear in position on the boundary vertices (zero inside).
struct Scene : test::MethodScene {
    explicit Scene(TetMesh m) : MethodScene(std::move(m)) {
        for (int32_t v : connectivity.boundary_vertices) q[v] = linear_q(mesh.positions[v]);
    }
};

bool tet_contains(const TetMesh& mesh, int32_t t, const Eigen::Vector3d& p) {
    const Tet& tet = mesh.tets[t];
    Eigen::Matrix3d edges;
    edges << mesh.positions[tet[1]] - mesh.positions[tet[0]], mesh.positions[tet[2]] - mesh.positions[tet[0]],
        mesh.positions[tet[3]] - mesh.positions[tet[0]];
    const Eigen::Vector3d b = edges.inverse() * (p - mesh.positions[tet[0]]);
    return b.minCoeff() > -1e-9 && b.sum() < 1 + 1e-9;
}

Eigen::Vector3d crossing(const VoxelGrid& grid, const VoxelLink& link) {
    const auto& s = kVoxelDirections[link.direction];
    return grid.cell_centre(link.cell) + link.fraction * grid.cell_size * Eigen::Vector3d(s[0], s[1], s[2]);
}

TEST(VoxelGrid, BoxCellsLinksAndCrossings) {
    // [0,4]^3 at 0.5 mm: 8^3 cells, all inside; the outer links cross the faces half a cell out.
    const Scene scene(make_box_mesh({4, 4, 4}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(4)));
    const VoxelGrid grid = voxelize(scene.problem(), 0.5);
    EXPECT_EQ(grid.dims, (std::array<int, 3>{8, 8, 8}));
    ASSERT_EQ(grid.cell_count(), 512u);
    EXPECT_NEAR(grid.cell_centre(0).x(), 0.25, 1e-12);
    for (size_t c = 0; c < grid.cell_count(); ++c) {
        EXPECT_TRUE(tet_contains(scene.mesh, grid.cell_tet[c], grid.cell_centre(static_cast<int32_t>(c))));
        for (int d = 0; d < 6; ++d) {
            const int32_t n = grid.neighbor[d][c];
            const auto& s = kVoxelDirections[d];
            const auto& k = grid.cell_coords[c];
            const int32_t expected = grid.cell_at(k[0] + s[0], k[1] + s[1], k[2] + s[2]);
            EXPECT_EQ(n, expected);
            if (n >= 0) {
                EXPECT_EQ(grid.neighbor[d ^ 1][n], static_cast<int32_t>(c));
            }
        }
    }
    ASSERT_EQ(grid.boundary_links.size(), 6u * 64u);
    for (const VoxelLink& link : grid.boundary_links) {
        EXPECT_NEAR(link.fraction, 0.5, 1e-9);
        const Eigen::Vector3d x = crossing(grid, link);
        EXPECT_TRUE(tet_contains(scene.mesh, link.tet, x));
        // q is linear on the boundary, so its interpolation on the crossed face is exact.
        const auto expected = linear_q(x);
        for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(link.q[ch], expected[ch], 1e-9);
    }
    // Model units: 2 mm per unit halves the cells per axis.
    EXPECT_EQ(voxelize(scene.problem(2.0), 0.5).dims, (std::array<int, 3>{16, 16, 16}));
}

TEST(VoxelGrid, BallCellsAreTheCentresInsideAndCrossingsLieOnTheSurface) {
    const Scene scene(test::make_ball_mesh(2, 3000, 10.0));
    const VoxelGrid grid = voxelize(scene.problem(), 1.3);
    size_t inside_voxels = 0;
    for (int k = 0; k < grid.dims[2]; ++k)
        for (int j = 0; j < grid.dims[1]; ++j)
            for (int i = 0; i < grid.dims[0]; ++i) {
                const Eigen::Vector3d c =
                    grid.origin + (Eigen::Vector3d(i, j, k) + Eigen::Vector3d::Constant(0.5)) * grid.cell_size;
                const int32_t cell = grid.cell_at(i, j, k);
                // The mesh's surface is an icosphere inscribed in r = 10 (level 2: within 0.4 of it).
                if (c.norm() < 9.5) {
                    EXPECT_GE(cell, 0);
                }
                if (c.norm() > 10.0) {
                    EXPECT_LT(cell, 0);
                }
                if (cell >= 0) {
                    ++inside_voxels;
                    EXPECT_TRUE(tet_contains(scene.mesh, grid.cell_tet[cell], c));
                }
            }
    EXPECT_EQ(inside_voxels, grid.cell_count());
    ASSERT_FALSE(grid.boundary_links.empty());
    for (const VoxelLink& link : grid.boundary_links) {
        EXPECT_GT(link.fraction, 0);
        EXPECT_LE(link.fraction, 1);
        const double r = crossing(grid, link).norm();
        EXPECT_GT(r, 9.5);
        EXPECT_LT(r, 10.0 + 1e-9);
        EXPECT_TRUE(tet_contains(scene.mesh, link.tet, crossing(grid, link)));
        EXPECT_LT(grid.neighbor[link.direction][link.cell], 0);
    }
}

TEST(VoxelGrid, CrackBetweenPiecesSeparatesCells) {
    // Two boxes with coincident faces on x = 2 (a fracture's crack in the rest frame): both sides
    // have cells next to the crack, and no link joins them.
    const TetMesh left = make_box_mesh({2, 4, 4}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 4, 4));
    const TetMesh right = make_box_mesh({2, 4, 4}, Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(4, 4, 4));
    const Scene scene(join_meshes(left, right));
    const VoxelGrid grid = voxelize(scene.problem(), 0.5);
    ASSERT_EQ(grid.cell_count(), 512u);
    int crack_links = 0;
    for (const VoxelLink& link : grid.boundary_links) {
        const Eigen::Vector3d x = crossing(grid, link);
        if (std::abs(x.x() - 2) > 1e-9) continue;
        ++crack_links;
        EXPECT_NEAR(link.fraction, 0.5, 1e-9);
        // The crossed face belongs to the cell's own side.
        const bool cell_left = grid.cell_centre(link.cell).x() < 2;
        EXPECT_EQ(static_cast<size_t>(link.tet) < left.tet_count(), cell_left);
    }
    EXPECT_EQ(crack_links, 2 * 64);
    for (size_t c = 0; c < grid.cell_count(); ++c) {
        const int32_t n = grid.neighbor[0][c];
        if (n >= 0) {
            EXPECT_EQ(grid.cell_centre(static_cast<int32_t>(c)).x() < 2, grid.cell_centre(n).x() < 2);
        }
    }
}

TEST(VoxelGrid, SlitNarrowerThanACellSeparatesCellsOnlyWhereItIs) {
    const Scene scene(test::make_slit_box(2.0));
    ASSERT_EQ(scene.connectivity.component_count, 1);
    const VoxelGrid grid = voxelize(scene.problem(), 0.5);
    for (size_t c = 0; c < grid.cell_count(); ++c) {
        const Eigen::Vector3d centre = grid.cell_centre(static_cast<int32_t>(c));
        if (std::abs(centre.x() - 1.75) > 1e-9) continue;  // the cells just left of the plane x = 2
        const bool across_slit = centre.y() < 2;
        EXPECT_EQ(grid.neighbor[0][c] < 0, across_slit) << "cell at y " << centre.y();
    }
}

TEST(VoxelGrid, SamplingReproducesLinearFieldsAtEveryVertex) {
    // Trilinear inside, a linear fit near the faces and corners: both exact for a linear field.
    const Scene scene(make_box_mesh({4, 4, 4}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(4)));
    const VoxelGrid grid = voxelize(scene.problem(), 0.5);
    const auto field = [](const Eigen::Vector3d& p) { return std::array<double, 3>{5 + p.x(), 5 - p.y(), 5 + p.x() + p.z()}; };
    std::vector<std::array<double, 3>> values(grid.cell_count());
    for (size_t c = 0; c < values.size(); ++c) values[c] = field(grid.cell_centre(static_cast<int32_t>(c)));
    VertexSamplingStats stats;
    const auto phi = sample_at_vertices(grid, scene.problem(), values, &stats);
    for (size_t v = 0; v < phi.size(); ++v)
        for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(phi[v][ch], field(scene.mesh.positions[v])[ch], 1e-9);
    EXPECT_EQ(stats.trilinear, 27u);  // the interior vertices of the 4^3 box
    EXPECT_EQ(stats.fitted, 125u - 27u);
    EXPECT_EQ(stats.nearest + stats.unsampled, 0u);
    EXPECT_THROW(sample_at_vertices(grid, scene.problem(), {}, nullptr), InvalidArgumentError);
}

TEST(VoxelGrid, SamplingDoesNotLeakAcrossCracksOrSlits) {
    // Cells left of x = 2 carry 1, right of it 2: each vertex sees only its own side where the two are
    // separated (the crack everywhere, the slit for y < 2).
    const TetMesh left = make_box_mesh({2, 4, 4}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 4, 4));
    const TetMesh right = make_box_mesh({2, 4, 4}, Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(4, 4, 4));
    for (const bool crack : {true, false}) {
        const Scene scene(crack ? join_meshes(left, right) : test::make_slit_box(2.0));
        const VoxelGrid grid = voxelize(scene.problem(), 0.5);
        std::vector<std::array<double, 3>> values(grid.cell_count());
        for (size_t c = 0; c < values.size(); ++c) {
            const double side = grid.cell_centre(static_cast<int32_t>(c)).x() < 2 ? 1.0 : 2.0;
            values[c] = {side, side, side};
        }
        const auto phi = sample_at_vertices(grid, scene.problem(), values);
        for (size_t t = 0; t < scene.mesh.tet_count(); ++t) {
            double x = 0;
            for (int32_t v : scene.mesh.tets[t]) x += scene.mesh.positions[v].x() / 4;
            for (int32_t v : scene.mesh.tets[t]) {
                const Eigen::Vector3d& p = scene.mesh.positions[v];
                if (!crack && p.y() > 1.2) continue;  // within a cell of the slit's end both sides mix
                EXPECT_NEAR(phi[v][0], x < 2 ? 1.0 : 2.0, 1e-9) << "vertex " << v << " crack " << crack;
            }
        }
    }
}

TEST(VoxelGrid, PartThinnerThanACellIsReportedUnsampled) {
    // A plate between two planes of cell centres, apart from a box: no cell of its own.
    const TetMesh box = make_box_mesh({4, 4, 4}, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 4, 4));
    const TetMesh plate = make_box_mesh({4, 4, 1}, Eigen::Vector3d(0, 0, 4.3), Eigen::Vector3d(4, 4, 4.45));
    const Scene scene(join_meshes(box, plate));
    const VoxelGrid grid = voxelize(scene.problem(), 0.5);
    for (size_t c = 0; c < grid.cell_count(); ++c) EXPECT_LT(static_cast<size_t>(grid.cell_tet[c]), box.tet_count());
    const std::vector<std::array<double, 3>> values(grid.cell_count(), {1, 1, 1});
    VertexSamplingStats stats;
    const auto phi = sample_at_vertices(grid, scene.problem(), values, &stats);
    EXPECT_EQ(stats.unsampled, plate.vertex_count());
    for (size_t v = box.vertex_count(); v < phi.size(); ++v) EXPECT_EQ(phi[v][0], 0.0);
    for (size_t v = 0; v < box.vertex_count(); ++v) EXPECT_NEAR(phi[v][0], 1.0, 1e-12);
}

TEST(VoxelGrid, RejectsBadCellSizes) {
    const Scene scene(make_box_mesh({1, 1, 1}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(1)));
    for (const double size : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()})
        EXPECT_THROW(voxelize(scene.problem(), size), InvalidArgumentError) << size;
    EXPECT_THROW(voxelize(scene.problem(), 1e-3), InvalidArgumentError);  // 10^9 voxels
    // 8 cells at 0.5 mm: a cap of 7 refuses them and names a size that fits.
    EXPECT_EQ(voxelize(scene.problem(), 0.5, 8).cell_count(), 8u);
    try {
        voxelize(scene.problem(), 0.5, 7);
        ADD_FAILURE() << "no error";
    } catch (const InvalidArgumentError& e) {
        EXPECT_NE(std::string(e.what()).find("gives 8 cells inside the volume, more than 7; use 0.52"), std::string::npos)
            << e.what();
    }
    const std::vector<std::array<double, 3>> short_q(3);
    EXPECT_THROW(voxelize(MethodProblem{scene.mesh, scene.connectivity, scene.materials, short_q, 1.0}, 0.5),
                 InvalidArgumentError);
    try {
        voxelize(scene.problem(), -1);
    } catch (const InvalidArgumentError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("voxel grid: ", 0), 0u);
    }
}

}  // namespace
}  // namespace waxwork
