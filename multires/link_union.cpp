#include "multires/link_union.h"

#include <algorithm>
#include <bit>
#include <limits>

namespace waxwork {

void LinkUnion::append(std::span<const int32_t> row, const int32_t* link_offsets, const int32_t* links, int32_t skip,
                       std::vector<int32_t>& out) {
    uint64_t* const bits = bits_.data();  // a local: stores into `out` would otherwise reload it
    int32_t lowest = std::numeric_limits<int32_t>::max(), highest = -1, count = 0;
    for (int32_t v : row)
        for (int32_t q = link_offsets[v]; q < link_offsets[v + 1]; ++q) {
            const int32_t k = links[q];
            bits[k >> 6] |= uint64_t{1} << (k & 63);
            lowest = std::min(lowest, k);
            highest = std::max(highest, k);
            ++count;
        }
    if (highest < 0) return;  // no links
    if (skip >= 0) bits[skip >> 6] &= ~(uint64_t{1} << (skip & 63));
    const int32_t first_word = lowest >> 6, last_word = highest >> 6;
    // A word read back costs about as much as one element of a small sort.
    if (last_word - first_word <= 8 * count + 64) {
        for (int32_t w = first_word; w <= last_word; ++w) {
            for (uint64_t word = bits[w]; word != 0; word &= word - 1) out.push_back(w * 64 + std::countr_zero(word));
            bits[w] = 0;
        }
        return;
    }
    const size_t first = out.size();
    for (int32_t v : row)
        for (int32_t q = link_offsets[v]; q < link_offsets[v + 1]; ++q) {
            const int32_t k = links[q];
            const uint64_t bit = uint64_t{1} << (k & 63);
            if (bits[k >> 6] & bit) {
                bits[k >> 6] &= ~bit;
                out.push_back(k);
            }
        }
    std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());
}

}  // namespace waxwork
