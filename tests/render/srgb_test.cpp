// srgb_encode and srgb_byte against the sRGB standard's (IEC 61966-2-1) values and the renderer's
// conventions: clamp to [0, 1], round to the nearest code.
#include "render/srgb.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace waxwork {
namespace {

TEST(Srgb, EncodesAsTheStandard) {
    EXPECT_DOUBLE_EQ(srgb_encode(0), 0);
    EXPECT_DOUBLE_EQ(srgb_encode(1), 1);
    EXPECT_DOUBLE_EQ(srgb_encode(0.001), 0.01292);                         // the linear segment
    EXPECT_NEAR(srgb_encode(0.5), 0.735356983, 1e-9);                      // the power segment
    EXPECT_NEAR(srgb_encode(0.0031308), 0.0404499, 1e-7);                  // the two meet here
    EXPECT_NEAR(srgb_encode(0.0031308 - 1e-12), 0.0404499, 1e-7);
}

TEST(Srgb, BytesClampAndRoundToTheNearestCode) {
    EXPECT_EQ(srgb_byte(0), 0);
    EXPECT_EQ(srgb_byte(1), 255);
    EXPECT_EQ(srgb_byte(0.5), 188);   // 187.52
    EXPECT_EQ(srgb_byte(0.18), 118);  // 117.65: middle grey
    EXPECT_EQ(srgb_byte(0.001), 3);   // 3.29
    EXPECT_EQ(srgb_byte(7.5), 255);
    EXPECT_EQ(srgb_byte(-0.2), 0);
    EXPECT_EQ(srgb_byte(std::numeric_limits<double>::quiet_NaN()), 0);
    EXPECT_EQ(srgb_bytes({0, 0.5, 1}), (std::array<uint8_t, 3>{0, 188, 255}));
}

}  // namespace
}  // namespace waxwork
