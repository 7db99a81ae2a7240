// The mesh-size and tolerance study (bench/studies/resolution_study.h) on a small case.
#include "bench/studies/resolution_study.h"

#include "base/error.h"

#include <gtest/gtest.h>

namespace waxwork {
namespace {

Image flat_image(int width, int height, std::array<uint8_t, 3> colour) {
    Image image{width, height, std::vector<uint8_t>(static_cast<size_t>(width) * height * 4, 255)};
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) std::copy(colour.begin(), colour.end(), image.pixel(x, y));
    return image;
}

TEST(RelativeImageError, ComparesLinearRgbOverTheObjectOnly) {
    const std::array<uint8_t, 3> background{38, 40, 46};
    Image reference = flat_image(4, 4, background);
    Image image = reference;
    EXPECT_EQ(relative_image_error(image, reference, background), 0.0);
    // Background pixels do not count, even when they differ.
    std::fill_n(image.pixel(0, 0), 3, uint8_t{0});
    EXPECT_EQ(relative_image_error(image, reference, background), 0.0);
    // One object pixel of linear value 1 against 0.5 (sRGB 188 is ~0.5 linear): error ~1.
    std::fill_n(reference.pixel(1, 1), 3, uint8_t{188});
    std::fill_n(image.pixel(1, 1), 3, uint8_t{255});
    EXPECT_NEAR(relative_image_error(image, reference, background), 1.0, 0.02);
    EXPECT_THROW(relative_image_error(flat_image(2, 2, background), reference, background), InvalidArgumentError);
}

TEST(ResolutionStudy, ReferenceSettingsReproduceTheReferenceAndLooserOnesCostAccuracy) {
    ResolutionStudyOptions options;
    options.surface = WAXWORK_ASSET_DIR "/meshes/spot.obj";
    options.mm_per_unit = 3;  // a small cow: the default mesh is coarse (D/25), so this stays fast
    options.width = 160;
    options.height = 120;
    options.size_factors = {2.0, 1.0};
    options.tolerances = {0.3, 1e-6};
    options.reference_size_factor = 1.0;
    options.reference_tolerance = 1e-6;
    const ResolutionStudy study = run_resolution_study(options);
    ASSERT_EQ(study.samples.size(), 4u);
    const ResolutionSample& coarse_loose = study.samples[0];
    const ResolutionSample& same_as_reference = study.samples[3];
    EXPECT_EQ(same_as_reference.tets, study.reference_tets);
    EXPECT_EQ(same_as_reference.image_error, 0.0);  // deterministic meshing, solve and render
    EXPECT_LT(coarse_loose.tets, study.reference_tets);
    EXPECT_GT(coarse_loose.image_error, 0.0);
    EXPECT_GT(study.samples[3].iterations, study.samples[2].iterations);  // tighter tolerance, more work
    EXPECT_GE(study.recommended, 0);
    EXPECT_EQ(study.shipped_default, -1);  // tolerance 1e-3 was not sampled
}

TEST(ResolutionStudy, RejectsBadOptions) {
    ResolutionStudyOptions options;
    options.surface = WAXWORK_ASSET_DIR "/meshes/spot.obj";
    options.tolerances = {};
    EXPECT_THROW(run_resolution_study(options), InvalidArgumentError);
    options.tolerances = {2.0};
    EXPECT_THROW(run_resolution_study(options), InvalidArgumentError);
    options.tolerances = {1e-3};
    options.size_factors = {-1};
    EXPECT_THROW(run_resolution_study(options), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
