#include "render/environment_prefilter.h"

#include "base/error.h"
#include "solver/sampling.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace waxwork {

namespace {

constexpr double kPi = std::numbers::pi;

// The prefilter reads a pyramid built from a copy no wider than this: the lobes it serves are wider
// than this copy's texels (about 0.7 degrees) at every roughness the renderer accepts but the
// smallest, and the copy keeps the pyramid's cost independent of the file's size.
constexpr int kPrefilterSourceWidth = 512;

EnvironmentTexture texture_of(const EnvironmentMap& map) {
    EnvironmentTexture t;
    t.width = map.width();
    t.height = map.height();
    t.texels.resize(static_cast<size_t>(t.width) * t.height);
    for (int y = 0; y < t.height; ++y)
        for (int x = 0; x < t.width; ++x) {
            const Rgb& c = map.pixel(x, y);
            t.texels[static_cast<size_t>(y) * t.width + x] = {static_cast<float>(c[0]), static_cast<float>(c[1]),
                                                               static_cast<float>(c[2])};
        }
    return t;
}

// Half the size (rounded up), each texel the mean of the up to 2 x 2 texels it covers. Plain means
// rather than solid-angle weights: the result is a filter for lookups, not an integral.
EnvironmentTexture halve(const EnvironmentTexture& in) {
    EnvironmentTexture out;
    out.width = std::max(1, (in.width + 1) / 2);
    out.height = std::max(1, (in.height + 1) / 2);
    out.texels.resize(static_cast<size_t>(out.width) * out.height);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) {
            std::array<double, 3> sum = {0, 0, 0};
            int count = 0;
            for (int sy = 2 * y; sy < std::min(2 * y + 2, in.height); ++sy)
                for (int sx = 2 * x; sx < std::min(2 * x + 2, in.width); ++sx) {
                    const auto& c = in.texels[static_cast<size_t>(sy) * in.width + sx];
                    for (int k = 0; k < 3; ++k) sum[k] += c[k];
                    ++count;
                }
            for (int k = 0; k < 3; ++k)
                out.texels[static_cast<size_t>(y) * out.width + x][k] = static_cast<float>(sum[k] / count);
        }
    return out;
}

// Bilinear lookup of direction w: wraps across the seam in longitude, clamps at the poles.
std::array<double, 3> bilinear(const EnvironmentTexture& t, const Eigen::Vector3d& w) {
    const double theta = std::acos(std::clamp(w.y(), -1.0, 1.0));
    const double phi = std::atan2(w.x(), -w.z());
    const double x = (phi + kPi) / (2 * kPi) * t.width - 0.5;
    const double y = std::clamp(theta / kPi * t.height - 0.5, 0.0, t.height - 1.0);
    const double x_floor = std::floor(x), y_floor = std::floor(y);
    const double fx = x - x_floor, fy = y - y_floor;
    const int x0 = ((static_cast<int>(x_floor) % t.width) + t.width) % t.width;
    const int x1 = (x0 + 1) % t.width;
    const int y0 = static_cast<int>(y_floor);
    const int y1 = std::min(y0 + 1, t.height - 1);
    const auto at = [&](int px, int py) -> const std::array<float, 3>& {
        return t.texels[static_cast<size_t>(py) * t.width + px];
    };
    std::array<double, 3> c{};
    for (int k = 0; k < 3; ++k)
        c[k] = (1 - fy) * ((1 - fx) * at(x0, y0)[k] + fx * at(x1, y0)[k]) + fy * ((1 - fx) * at(x0, y1)[k] + fx * at(x1, y1)[k]);
    return c;
}

}  // namespace

EnvironmentTexture reduce_environment(const EnvironmentTexture& texture, int max_width) {
    if (max_width < 1) throw InvalidArgumentError("reduce_environment: the width must be at least 1");
    if (texture.width <= max_width) return texture;
    EnvironmentTexture t = halve(texture);
    while (t.width > max_width) t = halve(t);
    return t;
}

EnvironmentTexture reduce_environment(const EnvironmentMap& map, int max_width) {
    return reduce_environment(texture_of(map), max_width);
}

EnvironmentTexture prefilter_environment(const EnvironmentMap& map, float roughness, int width, int samples) {
    return prefilter_environment(reduce_environment(map, kPrefilterSourceWidth), roughness, width, samples);
}

EnvironmentTexture prefilter_environment(const EnvironmentTexture& source, float roughness, int width, int samples) {
    if (!(roughness > 0.0f && roughness <= 1.0f))
        throw InvalidArgumentError("prefilter_environment: roughness must be in (0, 1]");
    if (width < 2 || samples < 1)
        throw InvalidArgumentError("prefilter_environment: the width must be at least 2 and the samples at least 1");
    if (source.width < 1 || source.height < 1 || source.texels.size() != static_cast<size_t>(source.width) * source.height)
        throw InvalidArgumentError("prefilter_environment: the source texture is empty or its size is inconsistent");
    std::vector<EnvironmentTexture> pyramid{reduce_environment(source, kPrefilterSourceWidth)};
    while (pyramid.back().width > 1 || pyramid.back().height > 1) pyramid.push_back(halve(pyramid.back()));
    const auto top = static_cast<double>(pyramid.size() - 1);
    const double texel_solid_angle = 4 * kPi / (static_cast<double>(pyramid[0].width) * pyramid[0].height);

    const double alpha = static_cast<double>(roughness) * roughness;
    const double alpha2 = alpha * alpha;
    EnvironmentTexture out;
    out.width = width;
    out.height = std::max(1, width / 2);
    out.texels.resize(static_cast<size_t>(out.width) * out.height);
    tbb::parallel_for(tbb::blocked_range<int>(0, out.height), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y != rows.end(); ++y)
            for (int x = 0; x < out.width; ++x) {
                const Eigen::Vector3d r = EnvironmentMap::direction((x + 0.5) / out.width, (y + 0.5) / out.height);
                Eigen::Vector3d t, b;
                orthonormal_basis(r, t, b);
                std::array<double, 3> sum = {0, 0, 0};
                double weight = 0;
                for (int k = 0; k < samples; ++k) {
                    // A Hammersley point warped to the GGX distribution of half vectors about r
                    // (Walter et al. 2007, Eqs. 35-36).
                    const double u1 = (k + 0.5) / samples, u2 = radical_inverse(static_cast<uint32_t>(k));
                    const double cos_h = std::sqrt((1 - u2) / (1 + (alpha2 - 1) * u2));
                    const double sin_h = std::sqrt(std::max(0.0, 1 - cos_h * cos_h));
                    const double phi = 2 * kPi * u1;
                    const Eigen::Vector3d h = sin_h * std::cos(phi) * t + sin_h * std::sin(phi) * b + cos_h * r;
                    const Eigen::Vector3d l = 2 * r.dot(h) * h - r;
                    const double cos_l = r.dot(l);
                    if (!(cos_l > 0)) continue;
                    // With n = v = r the density of l is D(h) / 4; the level whose texels cover the
                    // sample's solid angle 1 / (samples pdf), one level blurrier (Krivanek and Colbert).
                    const double d = cos_h * cos_h * (alpha2 - 1) + 1;
                    const double pdf = alpha2 / (kPi * d * d) / 4;
                    const double level =
                        std::clamp(0.5 * std::log2(1 / (samples * pdf * texel_solid_angle)) + 1, 0.0, top);
                    const auto lower = static_cast<size_t>(level);
                    const size_t upper = std::min(lower + 1, pyramid.size() - 1);
                    const double f = level - static_cast<double>(lower);
                    const std::array<double, 3> a = bilinear(pyramid[lower], l), c = bilinear(pyramid[upper], l);
                    for (int ch = 0; ch < 3; ++ch) sum[ch] += cos_l * ((1 - f) * a[ch] + f * c[ch]);
                    weight += cos_l;
                }
                auto& texel = out.texels[static_cast<size_t>(y) * out.width + x];
                for (int ch = 0; ch < 3; ++ch) texel[ch] = weight > 0 ? static_cast<float>(sum[ch] / weight) : 0.0f;
            }
    });
    return out;
}

}  // namespace waxwork
