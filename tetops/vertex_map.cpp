#include "tetops/vertex_map.h"

#include "base/error.h"

#include <string>

namespace waxwork {

std::vector<int32_t> vertex_pieces(const TetMesh& mesh) {
    std::vector<int32_t> vertex_piece(mesh.vertex_count(), -1);
    if (mesh.piece_ids.size() != mesh.tet_count()) return vertex_piece;
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const int32_t piece = mesh.piece_ids[t];
        for (int32_t v : mesh.tets[t]) {
            if (vertex_piece[v] == -1) {
                vertex_piece[v] = piece;
            } else if (vertex_piece[v] != piece) {
                throw InvalidMeshError("vertex " + std::to_string(v) + " is shared by pieces " +
                                       std::to_string(vertex_piece[v]) + " and " + std::to_string(piece));
            }
        }
    }
    return vertex_piece;
}

std::vector<int32_t> inverse_vertex_map(std::span<const int32_t> old_to_new, size_t vertices_after) {
    std::vector<int32_t> new_to_old(vertices_after, -1);
    for (size_t v = 0; v < old_to_new.size(); ++v)
        if (old_to_new[v] >= 0) new_to_old[static_cast<size_t>(old_to_new[v])] = static_cast<int32_t>(v);
    return new_to_old;
}

}  // namespace waxwork
