// Per-vertex maps of a TetMesh: the piece each vertex moves with, and the vertex maps of edits read
// the other way round.
#pragma once

#include "tetops/tet_mesh.h"

#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

// Per vertex: the piece (TetMesh::piece_ids) of the tets that hold it; -1 for a vertex in no tet, and
// for every vertex of a mesh without one piece id per tet. A vertex belongs to one piece (fracture
// gives each piece its own copy of the vertices along a crack), so one transform moves it: throws
// InvalidMeshError naming the vertex when tets of different pieces share it.
std::vector<int32_t> vertex_pieces(const TetMesh& mesh);

// A vertex map the other way: per vertex after an edit, its vertex before (-1: none maps there), from
// old_to_new (per vertex before, its index after or -1; CutResult::old_to_new_vertex and the maps of
// other edits). Entries of old_to_new must be below vertices_after.
std::vector<int32_t> inverse_vertex_map(std::span<const int32_t> old_to_new, size_t vertices_after);

}  // namespace waxwork
