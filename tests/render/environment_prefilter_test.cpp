#include "base/error.h"
#include "render/environment_prefilter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace waxwork {
namespace {

// A width x width / 2 map whose radiance is `radiance(direction)` at each pixel's centre.
template <typename F>
EnvironmentMap map_of(int width, F radiance) {
    const int height = width / 2;
    std::vector<Rgb> pixels;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) pixels.push_back(radiance(EnvironmentMap::direction((x + 0.5) / width, (y + 0.5) / height)));
    return EnvironmentMap(width, height, std::move(pixels), "test map");
}

// The prefiltered value in direction w (the texel it falls in).
float value_at(const EnvironmentTexture& t, const Eigen::Vector3d& w, int channel = 0) {
    const double theta = std::acos(std::clamp(w.y(), -1.0, 1.0));
    const double phi = std::atan2(w.x(), -w.z());
    const int x = std::clamp(static_cast<int>((phi + std::numbers::pi) / (2 * std::numbers::pi) * t.width), 0, t.width - 1);
    const int y = std::clamp(static_cast<int>(theta / std::numbers::pi * t.height), 0, t.height - 1);
    return t.texels[static_cast<size_t>(y) * t.width + x][channel];
}

TEST(EnvironmentPrefilter, AConstantEnvironmentStaysConstant) {
    const EnvironmentMap map = map_of(64, [](const Eigen::Vector3d&) { return Rgb{0.7, 1.5, 3.0}; });
    for (const float roughness : {0.05f, 0.35f, 1.0f}) {
        const EnvironmentTexture t = prefilter_environment(map, roughness, 32, 32);
        ASSERT_EQ(t.width, 32);
        ASSERT_EQ(t.height, 16);
        for (const auto& texel : t.texels) {
            EXPECT_NEAR(texel[0], 0.7f, 1e-5f);
            EXPECT_NEAR(texel[1], 1.5f, 1e-5f);
            EXPECT_NEAR(texel[2], 3.0f, 2e-5f);
        }
    }
}

// A bright cap of 10 degrees around the zenith: a smooth surface reflects it as it is, and a rougher one
// spreads it, dimmer at the zenith and brighter 25 degrees away.
TEST(EnvironmentPrefilter, TheLobeWidensWithRoughness) {
    const double cap = std::cos(10 * std::numbers::pi / 180);
    const EnvironmentMap map = map_of(512, [&](const Eigen::Vector3d& w) { return w.y() > cap ? Rgb{1, 1, 1} : Rgb{0, 0, 0}; });
    const Eigen::Vector3d zenith(0, 1, 0);
    const double off = 25 * std::numbers::pi / 180;
    const Eigen::Vector3d aside(std::sin(off), std::cos(off), 0);
    float previous_zenith = 2, previous_aside = -1;
    for (const float roughness : {0.1f, 0.3f, 0.5f, 0.8f}) {
        const EnvironmentTexture t = prefilter_environment(map, roughness, 128, 128);
        const float at_zenith = value_at(t, zenith), at_aside = value_at(t, aside);
        EXPECT_LT(at_zenith, previous_zenith) << "roughness " << roughness;
        EXPECT_GT(at_aside, previous_aside) << "roughness " << roughness;
        if (roughness == 0.1f) {
            EXPECT_GT(at_zenith, 0.97f);
            EXPECT_LT(at_aside, 0.01f);
        }
        previous_zenith = at_zenith;
        previous_aside = at_aside;
    }
}

TEST(EnvironmentPrefilter, ReducingKeepsTheMeanWithinTheWidth) {
    const EnvironmentMap map = map_of(300, [](const Eigen::Vector3d& w) { return Rgb{1 + w.x(), 2 + w.y(), 0.5}; });
    const EnvironmentTexture same = reduce_environment(map, 300);
    EXPECT_EQ(same.width, 300);
    EXPECT_EQ(same.height, 150);
    const EnvironmentTexture reduced = reduce_environment(map, 100);
    EXPECT_EQ(reduced.width, 75);  // 300 -> 150 -> 75
    EXPECT_EQ(reduced.height, 38);
    // The smooth map survives the box filter: every texel is close to the value at its centre.
    for (int y = 1; y < reduced.height - 1; ++y)
        for (int x = 0; x < reduced.width; ++x) {
            const Eigen::Vector3d w = EnvironmentMap::direction((x + 0.5) / reduced.width, (y + 0.5) / reduced.height);
            EXPECT_NEAR(reduced.texels[static_cast<size_t>(y) * reduced.width + x][1], 2 + w.y(), 0.05) << x << "," << y;
        }
}

// The renderer prefilters its background texture instead of the map: the same texels, because a
// reduction of a reduction is the reduction.
TEST(EnvironmentPrefilter, PrefilteringAReductionEqualsPrefilteringTheMap) {
    const EnvironmentMap map = map_of(1536, [](const Eigen::Vector3d& w) {
        return Rgb{0.2 + std::max(0.0, w.y()), 0.5 + 0.3 * w.x(), 1.0 + 0.5 * std::sin(3 * w.z())};
    });
    const EnvironmentTexture background = reduce_environment(map, 1024);
    ASSERT_EQ(background.width, 768);
    for (const float roughness : {0.2f, 0.7f}) {
        const EnvironmentTexture direct = prefilter_environment(map, roughness, 64, 16);
        const EnvironmentTexture shared = prefilter_environment(background, roughness, 64, 16);
        EXPECT_EQ(shared.texels, direct.texels) << "roughness " << roughness;
    }
    EXPECT_EQ(reduce_environment(background, 384).texels, reduce_environment(map, 384).texels);
}

TEST(EnvironmentPrefilter, RejectsBadArguments) {
    const EnvironmentMap map = map_of(8, [](const Eigen::Vector3d&) { return Rgb{1, 1, 1}; });
    EXPECT_THROW(prefilter_environment(map, 0.0f), InvalidArgumentError);
    EXPECT_THROW(prefilter_environment(map, 1.5f), InvalidArgumentError);
    EXPECT_THROW(prefilter_environment(map, std::nanf("")), InvalidArgumentError);
    EXPECT_THROW(prefilter_environment(map, 0.3f, 1), InvalidArgumentError);
    EXPECT_THROW(prefilter_environment(map, 0.3f, 16, 0), InvalidArgumentError);
    EXPECT_THROW(reduce_environment(map, 0), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
