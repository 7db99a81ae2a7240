// Extending a warm start over vertices without a value (solver/warm_start.h).
#include "solver/warm_start.h"
#include "tetops/error.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace waxwork {
namespace {

// The pattern of a path 0 - 1 - ... - (n-1) plus, when `split`, a second path that touches no other.
DiffusionMatrix path_pattern(int n, int split = 0) {
    DiffusionMatrix m;
    const int total = n + split;
    for (int v = 0; v < total; ++v) {
        const int first = v < n ? 0 : n, last = v < n ? n - 1 : total - 1;
        if (v > first) m.columns.push_back(v - 1);
        m.diagonal.push_back(static_cast<int32_t>(m.columns.size()));
        m.columns.push_back(v);
        if (v < last) m.columns.push_back(v + 1);
        m.offsets.push_back(static_cast<int32_t>(m.columns.size()));
    }
    return m;
}

std::array<std::vector<double>, 3> filled_with(size_t n, double value) {
    return {std::vector<double>(n, value), std::vector<double>(n, value), std::vector<double>(n, value)};
}

TEST(WarmStart, UnknownVerticesTakeTheirKnownNeighboursValuesBreadthFirst) {
    // Known: 0 (value 1, 2, 3) and 6 (value 7, 8, 9); 1..5 unknown, 7..8 a separate unknown path.
    const DiffusionMatrix m = path_pattern(7, 2);
    std::vector<uint8_t> known(9, 0);
    known[0] = known[6] = 1;
    auto values = filled_with(9, -5.0);
    for (size_t c = 0; c < 3; ++c) {
        values[c][0] = 1.0 + static_cast<double>(c);
        values[c][6] = 7.0 + static_cast<double>(c);
    }
    EXPECT_EQ(extend_to_unknown_vertices(m, known, values), 5u);
    for (size_t c = 0; c < 3; ++c) {
        const double a = values[c][0], b = values[c][6];
        EXPECT_EQ(values[c][1], a);  // pass 1: from 0 alone
        EXPECT_EQ(values[c][5], b);  // pass 1: from 6 alone
        EXPECT_EQ(values[c][2], a);  // pass 2: from 1
        EXPECT_EQ(values[c][4], b);
        EXPECT_EQ(values[c][3], 0.5 * (a + b));  // pass 3: from 2 and 4, both of pass 2
        EXPECT_EQ(values[c][7], -5.0);  // no known vertex reaches the second path
        EXPECT_EQ(values[c][8], -5.0);
    }
    // Known values never change, and a constant stays constant.
    auto constant = filled_with(9, 0.0);
    for (auto& channel : constant) channel[0] = channel[6] = 2.5;
    extend_to_unknown_vertices(m, known, constant);
    for (size_t v = 0; v < 7; ++v) EXPECT_EQ(constant[1][v], 2.5) << v;
}

TEST(WarmStart, NothingKnownOrEverythingKnownChangesNothingAndSizesAreChecked) {
    const DiffusionMatrix m = path_pattern(5);
    auto values = filled_with(5, 3.0);
    EXPECT_EQ(extend_to_unknown_vertices(m, std::vector<uint8_t>(5, 0), values), 0u);
    EXPECT_EQ(extend_to_unknown_vertices(m, std::vector<uint8_t>(5, 1), values), 0u);
    for (const auto& channel : values) EXPECT_TRUE(std::all_of(channel.begin(), channel.end(), [](double x) { return x == 3.0; }));
    EXPECT_THROW(extend_to_unknown_vertices(m, std::vector<uint8_t>(4, 0), values), InvalidArgumentError);
    auto short_values = filled_with(4, 0.0);
    EXPECT_THROW(extend_to_unknown_vertices(m, std::vector<uint8_t>(5, 1), short_values), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
