// Rows of a hierarchy operator that a rebuild copies from the previous hierarchy instead of computing
// them again (rebuild_multires_hierarchy, beyond the paper). Used by the interpolation (Eq. 16, rows
// are fine vertices), the coarse graph and the coarse matrix (Eq. 17, rows are coarse vertices).
//
// A row may be copied only when everything it is computed from is unchanged up to renumbering: the
// caller decides that from what the edit touched. The copy renumbers the row's coarse columns; with an
// order-preserving renumbering (a cut compacts vertices in order, and coarse vertices keep their fine
// order) the copy equals the computed row bit for bit, in the same column order.
#pragma once

#include <cstdint>
#include <span>

namespace waxwork {

// True when the vertices that survive an edit keep their order (new index increasing with the old
// one; -1: removed): then every level's renumbering keeps it too, and copied rows equal computed ones
// bit for bit.
inline bool keeps_vertex_order(std::span<const int32_t> new_of_old) {
    int32_t last = -1;
    for (const int32_t v : new_of_old) {
        if (v < 0) continue;
        if (v <= last) return false;
        last = v;
    }
    return true;
}

struct CarriedRows {
    std::span<const uint8_t> keep;               // per row: 1 to copy the previous row
    std::span<const int32_t> previous_row;       // per row: its row in the previous operator (where kept)
    std::span<const int32_t> new_of_old_column;  // previous coarse index -> new (>= 0 for every copied column)

    bool kept(size_t row) const { return keep[row] != 0; }
};

}  // namespace waxwork
