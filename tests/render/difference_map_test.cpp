// The difference map of two radiance images (render/difference_map.h): its colours follow the sign and
// size of the relative difference, noise within the reference's error reads as agreement, and bad
// input is refused.
#include "render/difference_map.h"

#include "base/error.h"

#include <gtest/gtest.h>

#include <array>
#include <limits>
#include <vector>

namespace waxwork {
namespace {

// w x h pixels of radiance `value` (grey), all covered except the first column.
RadianceImage flat_image(int w, int h, double value) {
    RadianceImage image;
    image.width = w;
    image.height = h;
    image.radiance.assign(static_cast<size_t>(w) * h, {value, value, value});
    image.coverage.assign(image.radiance.size(), 1.0f);
    for (int y = 0; y < h; ++y) image.coverage[static_cast<size_t>(y) * w] = 0.0f;
    return image;
}

std::array<uint8_t, 3> colour_at(const Image& image, int x, int y) {
    const uint8_t* p = image.pixel(x, y);
    return {p[0], p[1], p[2]};
}

TEST(DifferenceMap, BrighterIsRedDarkerIsBlueAndEqualIsPale) {
    const RadianceImage reference = flat_image(8, 6, 1.0);
    const std::vector<std::array<double, 3>> no_noise;
    const Image brighter = difference_map(flat_image(8, 6, 2.0), reference, no_noise, {});
    const Image darker = difference_map(flat_image(8, 6, 0.5), reference, no_noise, {});
    const Image slightly = difference_map(flat_image(8, 6, 1.1), reference, no_noise, {});
    // +100 % and -50 % are beyond the full scale (50 %): the map's end colours.
    EXPECT_EQ(colour_at(brighter, 4, 3), difference_colour(1));
    EXPECT_EQ(colour_at(darker, 4, 3), difference_colour(-1));
    // +10 % is a fifth of the way from pale to red.
    EXPECT_EQ(colour_at(slightly, 4, 3), difference_colour(0.2));
    EXPECT_GT(colour_at(slightly, 4, 3)[0], colour_at(slightly, 4, 3)[2]);
    // Equal images: no difference is significant without noise either (zero difference is not above 0).
    EXPECT_EQ(colour_at(difference_map(reference, reference, no_noise, {}), 4, 3), insignificant_difference_colour());
    // Uncovered pixels show the background.
    EXPECT_EQ(colour_at(brighter, 0, 2), kViewBackground);
}

TEST(DifferenceMap, TheScaleComparesTheLightsShapeAlone) {
    DifferenceMapOptions options;
    options.scale = 0.5;  // the image is twice as bright everywhere: after scaling, no difference
    const Image map = difference_map(flat_image(8, 6, 2.0), flat_image(8, 6, 1.0), {}, options);
    for (int y = 0; y < 6; ++y)
        for (int x = 1; x < 8; ++x) EXPECT_EQ(colour_at(map, x, y), insignificant_difference_colour()) << x << "," << y;
}

TEST(DifferenceMap, DifferencesWithinTheReferencesNoiseAreGrey) {
    const RadianceImage reference = flat_image(9, 9, 1.0), image = flat_image(9, 9, 1.2);
    DifferenceMapOptions options;
    options.filter_radius = 1;  // 9 pixels averaged: the mean's error is a third of a pixel's
    // An error of 0.9 per channel is 0.67 in luminance (the Rec. 709 weights' 2-norm is 0.75); the
    // window mean's is 0.22, and two of them (0.45) cover the difference of 0.2.
    const std::vector<std::array<double, 3>> noisy(reference.radiance.size(), {0.9, 0.9, 0.9});
    EXPECT_EQ(colour_at(difference_map(image, reference, noisy, options), 4, 4), insignificant_difference_colour());
    // An error of 0.15: two of the mean's (0.075) no longer cover it.
    const std::vector<std::array<double, 3>> quiet(reference.radiance.size(), {0.15, 0.15, 0.15});
    EXPECT_EQ(colour_at(difference_map(image, reference, quiet, options), 4, 4), difference_colour(0.4));
}

TEST(DifferenceMap, AveragesOverTheWindowSoOnePixelsNoiseDoesNotShow) {
    const RadianceImage reference = flat_image(9, 9, 1.0);
    RadianceImage image = flat_image(9, 9, 1.0);
    image.radiance[4 * 9 + 4] = {2.0, 2.0, 2.0};  // one pixel twice as bright
    DifferenceMapOptions options;
    options.filter_radius = 0;
    EXPECT_EQ(colour_at(difference_map(image, reference, {}, options), 4, 4), difference_colour(1));
    options.filter_radius = 2;  // 25 pixels: +4 %
    EXPECT_EQ(colour_at(difference_map(image, reference, {}, options), 4, 4), difference_colour(0.04 / 0.5));
}

TEST(DifferenceMap, RefusesMismatchedImagesAndBadOptions) {
    const RadianceImage a = flat_image(4, 4, 1.0), b = flat_image(5, 4, 1.0);
    EXPECT_THROW(difference_map(a, b, {}, {}), InvalidArgumentError);
    RadianceImage broken = a;
    broken.coverage.pop_back();
    EXPECT_THROW(difference_map(broken, a, {}, {}), InvalidArgumentError);
    EXPECT_THROW(difference_map(a, a, std::vector<std::array<double, 3>>(3), {}), InvalidArgumentError);
    for (double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
        DifferenceMapOptions scale, full;
        scale.scale = bad;
        full.full_scale = bad;
        EXPECT_THROW(difference_map(a, a, {}, scale), InvalidArgumentError) << bad;
        EXPECT_THROW(difference_map(a, a, {}, full), InvalidArgumentError) << bad;
    }
    DifferenceMapOptions radius, significance;
    radius.filter_radius = -1;
    significance.significance = -1;
    EXPECT_THROW(difference_map(a, a, {}, radius), InvalidArgumentError);
    EXPECT_THROW(difference_map(a, a, {}, significance), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
