#include "base/error.h"
#include "tetops/test_meshes.h"
#include "tetops/tet_mesh.h"
#include "tetops/vertex_map.h"

#include <gtest/gtest.h>

#include <vector>

namespace waxwork {
namespace {

TEST(VertexPieces, EachVertexTakesThePieceOfItsTets) {
    // Two cubes side by side as pieces 0 and 1; a vertex no tet names has no piece.
    TetMesh mesh = join_meshes(testing::make_cube_mesh(1), testing::make_cube_mesh(1, Eigen::Vector3d(2, 0, 0)));
    const size_t first = testing::make_cube_mesh(1).vertex_count();
    mesh.piece_transforms.resize(2);
    for (size_t t = testing::make_cube_mesh(1).tet_count(); t < mesh.tet_count(); ++t) mesh.piece_ids[t] = 1;
    mesh.positions.emplace_back(5, 5, 5);
    const std::vector<int32_t> pieces = vertex_pieces(mesh);
    ASSERT_EQ(pieces.size(), mesh.vertex_count());
    for (size_t v = 0; v + 1 < pieces.size(); ++v) EXPECT_EQ(pieces[v], v < first ? 0 : 1) << v;
    EXPECT_EQ(pieces.back(), -1);
    // Without one piece id per tet no vertex has a piece.
    mesh.piece_ids.clear();
    EXPECT_EQ(vertex_pieces(mesh), std::vector<int32_t>(mesh.vertex_count(), -1));
}

TEST(VertexPieces, AVertexSharedByTwoPiecesIsAnError) {
    TetMesh mesh = testing::make_cube_mesh(2);
    mesh.piece_transforms.resize(2);
    mesh.piece_ids[0] = 1;  // tet 0 shares its vertices with tets of piece 0
    EXPECT_THROW(vertex_pieces(mesh), InvalidMeshError);
}

}  // namespace
}  // namespace waxwork
