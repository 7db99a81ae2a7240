// Rows of a hierarchy operator that a rebuild copies from the previous hierarchy instead of computing
// them again (rebuild_multires_hierarchy, beyond the paper). Used by the interpolation (Eq. 16, rows
// are fine vertices), the coarse graph and the coarse matrix (Eq. 17, rows are coarse vertices), and
// by the multigrid's rebuilt Galerkin operators (MultigridPreconditioner).
//
// A row may be copied only when everything it is computed from is unchanged up to renumbering: the
// caller decides that from what the edit touched. The copy renumbers the row's coarse columns; with an
// order-preserving renumbering (a cut compacts vertices in order, and coarse vertices keep their fine
// order) the copy equals the computed row bit for bit, in the same column order.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

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

// How a rebuilt level's coarse vertices correspond to the previous hierarchy's. A coarse vertex is its
// fine parent (HierarchyLevel::parent_vertex), so previous coarse vertex c is the new coarse vertex
// whose parent is the new vertex of c's parent, or none (-1) when that parent was removed or is no
// longer retained. new_of_old_fine: per previous fine vertex, its new one or -1; new_coarse_of_fine:
// per new fine vertex, its coarse index or -1 (coarse_vertex_index). Returns per previous coarse
// vertex its new one (the next level's new_of_old_fine).
inline std::vector<int32_t> new_of_old_coarse_vertices(std::span<const int32_t> old_parent,
                                                       std::span<const int32_t> new_of_old_fine,
                                                       std::span<const int32_t> new_coarse_of_fine) {
    std::vector<int32_t> new_of_old(old_parent.size(), -1);
    for (size_t c = 0; c < old_parent.size(); ++c) {
        const int32_t v = new_of_old_fine[static_cast<size_t>(old_parent[c])];
        if (v >= 0) new_of_old[c] = new_coarse_of_fine[static_cast<size_t>(v)];
    }
    return new_of_old;
}

// One compressed-row operator as row_change reads it: offsets, columns and `Arrays` value arrays with
// one value per entry (a matrix's three channels, an interpolation's weights).
template <size_t Arrays>
struct OperatorRows {
    const std::vector<int32_t>& offsets;
    const std::vector<int32_t>& columns;
    std::array<const std::vector<double>*, Arrays> values;
};

// The rows of a three-channel matrix (a DiffusionMatrix, a hierarchy or multigrid level).
inline OperatorRows<3> matrix_rows(const std::vector<int32_t>& offsets, const std::vector<int32_t>& columns,
                                   const std::array<std::vector<double>, 3>& values) {
    return {offsets, columns, {&values[0], &values[1], &values[2]}};
}

// How row `row` of an operator differs from row `old_row` of the previous one. Pattern: another
// length, or columns that do not correspond under `old_of_new_column` (per new column, the previous
// one or -1) in order. Values: the same pattern, another value in some array. What decides whether a
// rebuild may copy what was computed from the row (None), and, for a matrix row, whether the graph
// row under it changed (Pattern: the graph row is the pattern without the diagonal).
enum class RowChange { None, Values, Pattern };

template <size_t Arrays>
RowChange row_change(const OperatorRows<Arrays>& now, size_t row, const OperatorRows<Arrays>& before, size_t old_row,
                     std::span<const int32_t> old_of_new_column) {
    const auto begin = static_cast<size_t>(now.offsets[row]), end = static_cast<size_t>(now.offsets[row + 1]);
    const auto old_begin = static_cast<size_t>(before.offsets[old_row]);
    if (end - begin != static_cast<size_t>(before.offsets[old_row + 1]) - old_begin) return RowChange::Pattern;
    RowChange change = RowChange::None;
    for (size_t k = begin, o = old_begin; k < end; ++k, ++o) {
        if (old_of_new_column[static_cast<size_t>(now.columns[k])] != before.columns[o]) return RowChange::Pattern;
        for (size_t a = 0; a < Arrays && change == RowChange::None; ++a)
            if ((*now.values[a])[k] != (*before.values[a])[o]) change = RowChange::Values;
    }
    return change;
}

struct CarriedRows {
    std::span<const uint8_t> keep;               // per row: 1 to copy the previous row
    std::span<const int32_t> previous_row;       // per row: its row in the previous operator (where kept)
    std::span<const int32_t> new_of_old_column;  // previous coarse index -> new (>= 0 for every copied column)

    bool kept(size_t row) const { return keep[row] != 0; }
};

}  // namespace waxwork
