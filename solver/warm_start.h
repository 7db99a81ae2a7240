// A warm start carried across an edit of the volume (beyond the paper, which restarts after a cut).
//
// Carrying: an edit reports where its vertices went (a vertex map: cuts, welds, undo) or where every
// vertex after comes from (origins: exact cuts, fractures), and per-vertex values follow.
//
// Extending over the vertices an edit gave no value (undoing a cut restores the vertices it removed;
// undoing a weld restores the crack copies it merged): a start of zero there is a hole the solver has
// to fill from scratch, while the neighbouring values are usually close, because phi is smooth inside
// a piece. Breadth-first from the vertices with a value, each vertex takes the mean of its matrix
// neighbours that already have one, so a restored region starts from its border's values.
// The solver corrects the rest; this only shortens the way there.
#pragma once

#include "solver/diffusion_matrix.h"
#include "tetops/cut.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

// Three channels of per-vertex values after an edit, and which vertices got one.
struct CarriedValues {
    std::array<std::vector<double>, 3> values;  // zero where nothing was carried
    std::vector<uint8_t> known;                 // 1 where a value was carried
};

// Through a vertex map: before holds one value per vertex before the edit (per channel), new_of_old
// per vertex before its index after or -1 (ChangeReport::old_to_new_vertex). Entries outside
// [0, vertices_after) carry nothing. Throws InvalidArgumentError when the map's size is not before's.
CarriedValues carry_through_vertex_map(const std::array<std::vector<double>, 3>& before,
                                       std::span<const int32_t> new_of_old, size_t vertices_after);

// Through origins, one per vertex after (VertexOrigin): a vertex kept from v takes v's value, one made
// at parameter t of edge ab takes (1 - t) value_a + t value_b, exact for values linear along the edge,
// which phi nearly is at the scale of one edge. An index below before's size names a vertex before;
// an index at or above it names a vertex after with a lower index than the one it places (a
// fracture's crack copies and walls across earlier walls), so origins are read in index order. An
// origin naming a vertex with no value (out of range, or not yet placed) carries nothing.
CarriedValues carry_through_origins(const std::array<std::vector<double>, 3>& before,
                                    std::span<const VertexOrigin> origins);

// values: per channel, one entry per row of `matrix`; known: 1 where values hold a value. Every vertex
// without one that a known vertex reaches through the matrix's pattern gets the mean of its neighbours
// known one breadth-first level earlier (deterministic, O(entries)); the others keep their values.
// Returns how many vertices were filled. Throws InvalidArgumentError when the sizes do not match.
size_t extend_to_unknown_vertices(const DiffusionMatrix& matrix, std::span<const uint8_t> known,
                                  std::array<std::vector<double>, 3>& values);

}  // namespace waxwork
