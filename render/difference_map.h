// Where two radiance images of one view differ, as a picture: the live image against the Monte Carlo
// reference (the editor's "Render reference"). Per pixel the signed relative difference of luminance,
// (s I - R) / R, averaged over a small window so that the reference's per-pixel noise does not paint
// the whole map, and drawn grey where that difference is within the reference's own noise.
#pragma once

#include "io/image_io.h"
#include "render/srgb.h"
#include "solver/reference/camera_rays.h"

#include <array>
#include <vector>

namespace waxwork {

struct DifferenceMapOptions {
    // I is multiplied by this first (ImageDifference::scale compares the light's distribution alone).
    double scale = 1;
    // The relative difference drawn at full colour (larger ones are clamped): 0.5 is +-50 %.
    double full_scale = 0.5;
    // The window averaged around each pixel is (2 r + 1)^2 pixels, over the pixels both images cover.
    int filter_radius = 2;
    // Grey where |s I - R| is under this many standard errors of the window's mean of R.
    double significance = 2;
};

// Red where `image` is brighter than `reference`, blue where it is darker, grey where they agree
// within the noise, `background` where either image leaves the pixel uncovered. `reference_error`
// is the standard error per pixel and channel (MonteCarloImage::radiance_error) or empty (no noise).
// Throws InvalidArgumentError for images of different sizes, arrays that do not match them, or
// options out of range (a non-finite or non-positive scale or full scale, a radius outside [0, 64],
// a negative significance).
Image difference_map(const RadianceImage& image, const RadianceImage& reference,
                     const std::vector<std::array<double, 3>>& reference_error, const DifferenceMapOptions& options,
                     std::array<uint8_t, 3> background = kViewBackground);

// The map's colour for a relative difference d (already clamped to [-1, 1] of the full scale) that
// is significant, and for one that is not: what a legend draws.
std::array<uint8_t, 3> difference_colour(double d);
std::array<uint8_t, 3> insignificant_difference_colour();

}  // namespace waxwork
