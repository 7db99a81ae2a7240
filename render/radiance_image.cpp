#include "render/radiance_image.h"

#include "base/error.h"
#include "render/render_input.h"
#include "render/srgb.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace waxwork {

namespace {

void check_sizes(const RadianceImage& image) {
    const size_t pixels = static_cast<size_t>(std::max(image.width, 0)) * std::max(image.height, 0);
    if (image.radiance.size() != pixels || image.coverage.size() != pixels)
        throw InvalidArgumentError("radiance image: the pixel arrays do not match the image size");
}

double aces(double x) { return std::clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0); }

// The displayed value in [0, 1] of one channel.
double displayed(double radiance, float exposure) { return srgb_encode(aces(std::max(0.0, radiance * exposure))); }

}  // namespace

float radiance_image_exposure(const RadianceImage& image) {
    check_sizes(image);
    std::vector<double> luminance;
    for (size_t p = 0; p < image.radiance.size(); ++p) {
        if (!(image.coverage[p] > 0)) continue;
        const auto& l = image.radiance[p];
        luminance.push_back(0.2126 * l[0] + 0.7152 * l[1] + 0.0722 * l[2]);
    }
    if (luminance.empty()) return 1.0f;
    const auto nth = luminance.begin() + static_cast<std::ptrdiff_t>(kExposurePercentile * (luminance.size() - 1));
    std::nth_element(luminance.begin(), nth, luminance.end());
    if (!(*nth > 0) || !std::isfinite(*nth)) return 1.0f;
    return static_cast<float>(std::min(kExposureTarget / *nth, 1e30));
}

Image tone_mapped_image(const RadianceImage& image, float exposure, std::array<uint8_t, 3> background) {
    check_sizes(image);
    Image out;
    out.width = image.width;
    out.height = image.height;
    out.rgba.resize(4 * image.radiance.size());
    for (size_t p = 0; p < image.radiance.size(); ++p) {
        const double coverage = std::clamp(static_cast<double>(image.coverage[p]), 0.0, 1.0);
        for (int c = 0; c < 3; ++c) {
            const double value = coverage * displayed(image.radiance[p][c], exposure) + (1 - coverage) * background[c] / 255.0;
            out.rgba[4 * p + c] = static_cast<uint8_t>(std::lround(std::clamp(value, 0.0, 1.0) * 255));
        }
        out.rgba[4 * p + 3] = 255;
    }
    return out;
}

ImageDifference compare_radiance_images(const RadianceImage& image, float image_exposure,
                                        const RadianceImage& reference, float reference_exposure) {
    check_sizes(image);
    check_sizes(reference);
    if (image.width != reference.width || image.height != reference.height)
        throw InvalidArgumentError("radiance image: the images to compare differ in size");
    double difference2 = 0, reference2 = 0, image2 = 0, cross = 0, squared_error = 0;
    ImageDifference result;
    for (size_t p = 0; p < image.radiance.size(); ++p) {
        if (image.coverage[p] < 1 || reference.coverage[p] < 1) continue;
        ++result.pixels;
        for (int c = 0; c < 3; ++c) {
            const double a = image.radiance[p][c], b = reference.radiance[p][c];
            difference2 += (a - b) * (a - b);
            reference2 += b * b;
            image2 += a * a;
            cross += a * b;
            const double e = displayed(a, image_exposure) - displayed(b, reference_exposure);
            squared_error += e * e;
        }
    }
    if (reference2 > 0) {
        result.relative_l2 = std::sqrt(difference2 / reference2);
        result.scale = image2 > 0 ? cross / image2 : 0.0;
        // |s I - R|^2 at the least-squares s = <I, R> / |I|^2 is |R|^2 - <I, R>^2 / |I|^2.
        const double residual = image2 > 0 ? std::max(0.0, reference2 - cross * cross / image2) : reference2;
        result.scaled_relative_l2 = std::sqrt(residual / reference2);
    }
    const double mse = result.pixels > 0 ? squared_error / (3.0 * result.pixels) : 0.0;
    result.psnr_db = mse > 0 ? 10 * std::log10(1.0 / mse) : std::numeric_limits<double>::infinity();
    return result;
}

}  // namespace waxwork
