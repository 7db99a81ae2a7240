// LinkUnion reads a row back either from the bitmap's span of words (links close together) or, when
// that span is long against the row's links, by walking the links again and sorting. Both must give
// the sorted union without repeats and leave the bitmap clear for the next row.
#include "multires/link_union.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

namespace waxwork {
namespace {

struct Links {
    std::vector<int32_t> offsets{0}, links;
};

// `vertices` link lists of 1 to 6 links each, drawn from [centre - spread, centre + spread] clamped to
// [0, columns) with repeats.
Links random_links(size_t vertices, int32_t columns, int32_t centre, int32_t spread, std::mt19937& rng) {
    Links l;
    std::uniform_int_distribution<int> count(1, 6);
    std::uniform_int_distribution<int32_t> offset(-spread, spread);
    for (size_t v = 0; v < vertices; ++v) {
        for (int k = count(rng); k > 0; --k) l.links.push_back(std::clamp(centre + offset(rng), 0, columns - 1));
        l.offsets.push_back(static_cast<int32_t>(l.links.size()));
    }
    return l;
}

std::vector<int32_t> expected_union(const Links& l, const std::vector<int32_t>& row, int32_t skip) {
    std::set<int32_t> all;
    for (int32_t v : row)
        for (int32_t q = l.offsets[static_cast<size_t>(v)]; q < l.offsets[static_cast<size_t>(v) + 1]; ++q)
            if (l.links[static_cast<size_t>(q)] != skip) all.insert(l.links[static_cast<size_t>(q)]);
    return {all.begin(), all.end()};
}

TEST(LinkUnion, SortedUnionWithoutRepeatsForNearAndFarLinks) {
    constexpr int32_t columns = 200000;
    std::mt19937 rng(3);
    LinkUnion scratch(columns);
    // Spreads of 50 columns (read back from the bitmap) and of the whole range (walked and sorted),
    // alternated so that each kind follows the other on the same scratch; the near rows all share one
    // region, where bits left set by an earlier row would show.
    for (int round = 0; round < 40; ++round) {
        const int32_t spread = round % 2 == 0 ? 50 : columns;
        const Links l = random_links(30, columns, 5000, spread, rng);
        std::vector<int32_t> row(12);
        std::uniform_int_distribution<int32_t> vertex(0, 29);
        for (int32_t& v : row) v = vertex(rng);  // vertices may repeat in a row too
        const int32_t skip = round % 3 == 0 ? -1 : l.links[static_cast<size_t>(l.offsets[static_cast<size_t>(row[0])])];
        std::vector<int32_t> out{-7};  // appended after what is there
        scratch.append(row, l.offsets.data(), l.links.data(), skip, out);
        ASSERT_EQ(out.front(), -7);
        const std::vector<int32_t> got(out.begin() + 1, out.end());
        EXPECT_EQ(got, expected_union(l, row, skip)) << "round " << round << ", spread " << spread;
    }
    // A row without links appends nothing.
    const Links empty{{0, 0, 0}, {}};
    std::vector<int32_t> out;
    scratch.append(std::vector<int32_t>{0, 1}, empty.offsets.data(), empty.links.data(), -1, out);
    EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace waxwork
