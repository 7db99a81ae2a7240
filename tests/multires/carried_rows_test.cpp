// What a rebuild compares before copying a row (multires/carried_rows.h).
#include "multires/carried_rows.h"

#include <gtest/gtest.h>

namespace waxwork {
namespace {

TEST(CarriedRows, AVertexMapKeepsTheOrderWhenTheSurvivorsIncrease) {
    EXPECT_TRUE(keeps_vertex_order(std::vector<int32_t>{}));
    EXPECT_TRUE(keeps_vertex_order(std::vector<int32_t>{0, -1, 1, -1, 4}));  // a cut's compaction
    EXPECT_FALSE(keeps_vertex_order(std::vector<int32_t>{1, 0}));
    EXPECT_FALSE(keeps_vertex_order(std::vector<int32_t>{0, -1, 0}));  // two vertices onto one
}

// Two rows of a one-array operator: the previous row 1 is {0: 1.0, 2: 2.0, 3: 3.0}; after an edit that
// removed the previous vertex 1, the new columns 0, 1, 2 are the previous 0, 2, 3.
struct TwoRows {
    std::vector<int32_t> old_offsets{0, 1, 4};
    std::vector<int32_t> old_columns{0, 0, 2, 3};
    std::vector<double> old_values{9.0, 1.0, 2.0, 3.0};
    std::vector<int32_t> old_of_new{0, 2, 3, -1};  // new vertex 3 has no previous vertex

    RowChange change(const std::vector<int32_t>& columns, const std::vector<double>& values) const {
        const std::vector<int32_t> offsets{0, static_cast<int32_t>(columns.size())};
        return row_change<1>({offsets, columns, {&values}}, 0, {old_offsets, old_columns, {&old_values}}, 1, old_of_new);
    }
};

TEST(CarriedRows, ARowChangeTellsAPatternChangeFromAValueChange) {
    const TwoRows rows;
    EXPECT_EQ(rows.change({0, 1, 2}, {1.0, 2.0, 3.0}), RowChange::None);
    EXPECT_EQ(rows.change({0, 1, 2}, {1.0, 2.5, 3.0}), RowChange::Values);
    // A value differs before the column that differs: still a pattern change.
    EXPECT_EQ(rows.change({0, 1, 3}, {1.5, 2.0, 3.0}), RowChange::Pattern);  // new vertex 3
    EXPECT_EQ(rows.change({0, 2, 1}, {1.0, 2.0, 3.0}), RowChange::Pattern);  // not in the previous order
    EXPECT_EQ(rows.change({0, 1}, {1.0, 2.0}), RowChange::Pattern);          // shorter
}

TEST(CarriedRows, AMatrixRowChangesWhenAnyChannelDoes) {
    const std::vector<int32_t> offsets{0, 2}, columns{0, 1};
    const std::array<std::vector<double>, 3> old_values{std::vector<double>{4, -1}, std::vector<double>{5, -1},
                                                        std::vector<double>{6, -1}};
    const std::vector<int32_t> identity{0, 1};
    std::array<std::vector<double>, 3> values = old_values;
    const OperatorRows<3> now = matrix_rows(offsets, columns, values), before = matrix_rows(offsets, columns, old_values);
    EXPECT_EQ(row_change(now, 0, before, 0, identity), RowChange::None);
    values[2][1] = -1.5;  // the blue channel's off-diagonal entry only
    EXPECT_EQ(row_change(now, 0, before, 0, identity), RowChange::Values);
}

}  // namespace
}  // namespace waxwork
