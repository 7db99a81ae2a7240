// Extending a warm start over the vertices an edit gave no value (undoing a cut restores the vertices
// it removed; undoing a weld restores the crack copies it merged): a start of zero there is a hole the
// solver has to fill from scratch, while the neighbouring values are usually close, because phi is
// smooth inside a piece. Breadth-first from the vertices with a value, each vertex takes the mean of
// its matrix neighbours that already have one, so a restored region starts from its border's values.
// The solver corrects the rest; this only shortens the way there.
#pragma once

#include "solver/diffusion_matrix.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

// values: per channel, one entry per row of `matrix`; known: 1 where values hold a value. Every vertex
// without one that a known vertex reaches through the matrix's pattern gets the mean of its neighbours
// known one breadth-first level earlier (deterministic, O(entries)); the others keep their values.
// Returns how many vertices were filled. Throws InvalidArgumentError when the sizes do not match.
size_t extend_to_unknown_vertices(const DiffusionMatrix& matrix, std::span<const uint8_t> known,
                                  std::array<std::vector<double>, 3>& values);

}  // namespace waxwork
