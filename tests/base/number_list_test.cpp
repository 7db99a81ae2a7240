#include "base/number_list.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace waxwork {
namespace {

TEST(NumberList, TightListsRefuseBlanks) {
    std::vector<double> v;
    ASSERT_TRUE(parse_number_list("1,-2.5,+3e2", v));
    EXPECT_EQ(v, (std::vector<double>{1, -2.5, 300}));
    for (const std::string bad : {"", "1,,2", "1,2,", "1,2x", "1, 2", " 1", "1 ", "0x10", "+-1", "++1"})
        EXPECT_FALSE(parse_number_list(bad, v)) << bad;
}

TEST(NumberList, BlanksMayStandAroundEachNumber) {
    std::vector<double> v;
    ASSERT_TRUE(parse_number_list(" 1, 0 ,\t-2 ", v, NumberSpacing::Blanks));
    EXPECT_EQ(v, (std::vector<double>{1, 0, -2}));
    ASSERT_TRUE(parse_number_list("inf", v, NumberSpacing::Blanks));  // ranges are the caller's
    EXPECT_TRUE(std::isinf(v[0]));
    // Blanks end a number, they do not join or replace one.
    for (const std::string bad : {"1 2", "1, ,2", " ", "1,", "+ 1", "1e400"})
        EXPECT_FALSE(parse_number_list(bad, v, NumberSpacing::Blanks)) << bad;
}

}  // namespace
}  // namespace waxwork
