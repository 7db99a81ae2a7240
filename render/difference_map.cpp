#include "render/difference_map.h"

#include "base/error.h"
#include "solver/rgb.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

namespace waxwork {

namespace {

// The weights of luminance() (solver/rgb.h), for the variance of a luminance.
constexpr std::array<double, 3> kLuminance{0.2126, 0.7152, 0.0722};
constexpr int kMaxFilterRadius = 64;

void check_arrays(const RadianceImage& image, const char* what) {
    const size_t pixels = static_cast<size_t>(std::max(image.width, 0)) * std::max(image.height, 0);
    if (image.radiance.size() != pixels || image.coverage.size() != pixels)
        throw InvalidArgumentError(std::string("difference map: the ") + what + "'s pixel arrays do not match its size");
}

void check_options(const DifferenceMapOptions& o) {
    if (!(std::isfinite(o.scale) && o.scale > 0))
        throw InvalidArgumentError("difference map: the scale must be positive and finite");
    if (!(std::isfinite(o.full_scale) && o.full_scale > 0))
        throw InvalidArgumentError("difference map: the full scale must be positive and finite");
    if (o.filter_radius < 0 || o.filter_radius > kMaxFilterRadius)
        throw InvalidArgumentError("difference map: the filter radius must be in [0, " + std::to_string(kMaxFilterRadius) + "]");
    if (!(std::isfinite(o.significance) && o.significance >= 0))
        throw InvalidArgumentError("difference map: the significance must be zero or positive");
}

std::array<uint8_t, 3> mix(const std::array<double, 3>& a, const std::array<double, 3>& b, double t) {
    std::array<uint8_t, 3> out{};
    for (int c = 0; c < 3; ++c) out[c] = static_cast<uint8_t>(std::lround(a[c] + t * (b[c] - a[c])));
    return out;
}

}  // namespace

std::array<uint8_t, 3> difference_colour(double d) {
    // From near white at no difference to ColorBrewer's RdBu ends: readable for most colour-blind
    // viewers, and the sign is the hue.
    constexpr std::array<double, 3> pale{240, 240, 240}, red{202, 0, 32}, blue{5, 113, 176};
    const double t = std::clamp(d, -1.0, 1.0);
    return t >= 0 ? mix(pale, red, t) : mix(pale, blue, -t);
}

std::array<uint8_t, 3> insignificant_difference_colour() { return {110, 110, 110}; }

Image difference_map(const RadianceImage& image, const RadianceImage& reference,
                     const std::vector<std::array<double, 3>>& reference_error, const DifferenceMapOptions& options,
                     std::array<uint8_t, 3> background) {
    check_arrays(image, "image");
    check_arrays(reference, "reference");
    if (image.width != reference.width || image.height != reference.height)
        throw InvalidArgumentError("difference map: the images differ in size");
    if (!reference_error.empty() && reference_error.size() != reference.radiance.size())
        throw InvalidArgumentError("difference map: the reference's errors do not match its pixels");
    check_options(options);

    const int w = image.width, h = image.height;
    const size_t pixels = static_cast<size_t>(w) * h;
    std::vector<double> shown(pixels, 0.0), truth(pixels, 0.0), variance(pixels, 0.0);
    std::vector<char> covered(pixels, 0);
    for (size_t p = 0; p < pixels; ++p) {
        covered[p] = image.coverage[p] > 0 && reference.coverage[p] > 0;
        if (!covered[p]) continue;
        shown[p] = options.scale * luminance(image.radiance[p]);
        truth[p] = luminance(reference.radiance[p]);
        if (!reference_error.empty())
            for (int c = 0; c < 3; ++c) variance[p] += kLuminance[c] * kLuminance[c] * reference_error[p][c] * reference_error[p][c];
    }

    Image out;
    out.width = w;
    out.height = h;
    out.rgba.assign(4 * pixels, 255);
    const int r = options.filter_radius;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t p = static_cast<size_t>(y) * w + x;
            std::array<uint8_t, 3> colour = background;
            if (covered[p]) {
                // The window's means; the pixels' errors are independent (each has its own random stream).
                double sum_shown = 0, sum_truth = 0, sum_variance = 0;
                int n = 0;
                for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
                    for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u) {
                        const size_t q = static_cast<size_t>(v) * w + u;
                        if (!covered[q]) continue;
                        sum_shown += shown[q];
                        sum_truth += truth[q];
                        sum_variance += variance[q];
                        ++n;
                    }
                const double difference = (sum_shown - sum_truth) / n;
                const double noise = std::sqrt(sum_variance) / n;
                if (std::abs(difference) <= options.significance * noise || (sum_shown == 0 && sum_truth == 0))
                    colour = insignificant_difference_colour();
                else if (sum_truth <= 0)
                    colour = difference_colour(1);  // light where the reference has none
                else
                    colour = difference_colour(difference / (sum_truth / n) / options.full_scale);
            }
            for (int c = 0; c < 3; ++c) out.rgba[4 * p + c] = colour[c];
        }
    return out;
}

}  // namespace waxwork
