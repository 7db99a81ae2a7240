// A structured tet mesh of a box: the reference geometry of tests, studies and benchmarks, where a
// surface mesher would add nothing but noise. Each cell is split into the six Kuhn tets (one per
// permutation of the axes, all sharing the cell's main diagonal), so neighbouring cells match without
// flipping and a cubic cell gives dihedral angles of 45-90 degrees. Refining by 2 keeps every vertex:
// vertex (i, j, k) of the coarse mesh is vertex (2i, 2j, 2k) of the fine one (box_vertex_index).
#pragma once

#include "tetops/tet_mesh.h"

#include <array>

namespace waxwork {

// The box [lo, hi] in cells[0] x cells[1] x cells[2] cells. Throws InvalidArgumentError for a
// non-positive cell count, more than 2^31 vertices, or lo not strictly below hi on every axis.
TetMesh make_box_mesh(const std::array<int, 3>& cells, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

// The index of grid point (i, j, k) in make_box_mesh(cells, ...).
inline int32_t box_vertex_index(const std::array<int, 3>& cells, int i, int j, int k) {
    return static_cast<int32_t>((static_cast<int64_t>(k) * (cells[1] + 1) + j) * (cells[0] + 1) + i);
}

}  // namespace waxwork
