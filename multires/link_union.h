// The union of the link lists of a row's vertices, sorted and without repeats: the pattern of one row
// of a sparse product whose right factor is given as per-vertex link lists (columns only). Two
// products of the hierarchy have this shape: the coarse graph (row i of G^l times the links of Eq.
// 16's interpolation, independent_set.h) and the multigrid's A P (multigrid_preconditioner.h).
//
// Why by hand: Eigen's sparse product forms values as well and sorts each row of the result; these
// callers need the pattern of only some rows, per thread, in a layout they fill themselves.
//
// How. The links are set as bits in a bitmap of the columns (columns / 8 bytes: it stays in L1 where a
// tag array of ints does not), which removes the repeats, and the row's span of words is read back in
// order, which sorts it. The hierarchy's vertex orders are spatially coherent (coarse indices keep the
// fine order), so that span is short for most rows (coarse graph of spot at 97K fine vertices: a
// median of 10 words); a row whose span is long against its link count is instead read back by
// walking its links again and sorting them. For the coarse graph this takes less than half the time
// of a tag array and std::sort per row (all levels at 487K tets).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

// Scratch for one thread (the bitmap is all zero between calls).
class LinkUnion {
public:
    explicit LinkUnion(size_t columns) : bits_((columns + 63) / 64, 0) {}

    // Appends to `out` the links links[link_offsets[v] .. link_offsets[v + 1]) of every v in `row`,
    // ascending and each once, leaving out `skip` (-1: nothing). Columns must be below the
    // constructor's count.
    void append(std::span<const int32_t> row, const int32_t* link_offsets, const int32_t* links, int32_t skip,
                std::vector<int32_t>& out);

private:
    std::vector<uint64_t> bits_;
};

}  // namespace waxwork
