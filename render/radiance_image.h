// A linear radiance image (solver/reference/camera_rays.h: the Monte Carlo image, or the live image's
// subsurface term on the CPU) exposed and tone-mapped into a picture as the renderer's shaders do, and
// the measures the studies compare two of them by.
#pragma once

#include "io/image_io.h"
#include "render/srgb.h"
#include "solver/reference/camera_rays.h"

#include <array>
#include <cstdint>

namespace waxwork {

// automatic_exposure's rule (render_input.h) on the pixels: the 95th percentile of the luminance of
// the covered pixels maps to kExposureTarget; 1 when none is lit.
float radiance_image_exposure(const RadianceImage& image);

// ACES (Narkowicz's fit) of the exposed radiance, sRGB-encoded, over `background` by coverage (the
// renderer's multisample resolve blends encoded colours too). Throws InvalidArgumentError for an image
// whose arrays do not match its size.
Image tone_mapped_image(const RadianceImage& image, float exposure, std::array<uint8_t, 3> background = kViewBackground);

// How far `image` is from `reference` over the pixels both cover fully, over the three channels:
//   relative_l2        sqrt(sum |I - R|^2 / sum |R|^2) in linear radiance;
//   scaled_relative_l2 the same after scaling I by the one factor that fits R best (least squares):
//                      the error of the light's distribution, whatever the overall brightness (which
//                      the automatic exposure hides from the viewer);
//   scale              R over I in that fit;
//   psnr_db            the PSNR of the two as they are shown, each tone-mapped with its own exposure
//                      (peak 1 in [0, 1] sRGB).
struct ImageDifference {
    double relative_l2 = 0;
    double scaled_relative_l2 = 0;
    double scale = 1;
    double psnr_db = 0;
    int64_t pixels = 0;
};
ImageDifference compare_radiance_images(const RadianceImage& image, float image_exposure,
                                        const RadianceImage& reference, float reference_exposure);

}  // namespace waxwork
