#include "solver/environment_map.h"

#include "base/error.h"
#include "solver/lighting.h"
#include "solver/spherical_harmonics.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace waxwork {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kMaxEnvironmentSide = 65536;
// 8192 x 4096, the largest HDRIs in common use; beyond it the map's memory (24 bytes a pixel) and its
// projection time grow without changing the light of a diffuse transfer.
constexpr size_t kMaxEnvironmentPixels = size_t{8192} * 4096;

}  // namespace

EnvironmentMap::EnvironmentMap(int width, int height, std::vector<Rgb> radiance, std::string name)
    : width_(width), height_(height), radiance_(std::move(radiance)), name_(std::move(name)) {
    if (width <= 0 || height <= 0 || width > kMaxEnvironmentSide || height > kMaxEnvironmentSide)
        throw InvalidArgumentError(name_ + ": environment image is " + std::to_string(width) + " x " +
                                   std::to_string(height) + " pixels; each side must be 1 to 65536");
    if (static_cast<size_t>(width) * static_cast<size_t>(height) > kMaxEnvironmentPixels)
        throw InvalidArgumentError(name_ + ": environment image is " + std::to_string(width) + " x " +
                                   std::to_string(height) + " pixels; at most 8192 x 4096 (33.5M pixels) are taken");
    if (radiance_.size() != static_cast<size_t>(width) * static_cast<size_t>(height))
        throw InvalidArgumentError(name_ + ": " + std::to_string(radiance_.size()) + " pixels for a " +
                                   std::to_string(width) + " x " + std::to_string(height) + " image");
    for (size_t i = 0; i < radiance_.size(); ++i) {
        for (const double value : radiance_[i]) {
            if (!(value >= 0 && value <= kMaxLightIntensity)) {
                throw InvalidArgumentError(name_ + ": pixel (" + std::to_string(i % width) + ", " +
                                           std::to_string(i / width) + ") is " +
                                           (std::isnan(value) ? std::string("NaN")
                                            : value < 0      ? "negative"
                                                             : "beyond 1e15 or infinite") +
                                           "; radiance must be finite and non-negative");
            }
        }
    }
}

Eigen::Vector3d EnvironmentMap::direction(double u, double v) {
    const double theta = kPi * v;
    const double phi = 2 * kPi * u - kPi;
    return {std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
}

std::array<int, 2> EnvironmentMap::pixel_of(const Eigen::Vector3d& w) const {
    const double theta = std::acos(std::clamp(w.y(), -1.0, 1.0));
    const double phi = std::atan2(w.x(), -w.z());  // (-pi, pi]
    const int x = std::clamp(static_cast<int>(std::floor((phi + kPi) / (2 * kPi) * width_)), 0, width_ - 1);
    const int y = std::clamp(static_cast<int>(std::floor(theta / kPi * height_)), 0, height_ - 1);
    return {x, y};
}

const Rgb& EnvironmentMap::radiance(const Eigen::Vector3d& w) const {
    const auto [x, y] = pixel_of(w);
    return pixel(x, y);
}

double EnvironmentMap::pixel_solid_angle(int y) const {
    return 2 * kPi / width_ * (std::cos(kPi * y / height_) - std::cos(kPi * (y + 1) / height_));
}

std::vector<Rgb> EnvironmentMap::project_to_sh(int order) const {
    const size_t count = static_cast<size_t>(sh_coefficient_count(order));
    using Sums = std::vector<Rgb>;
    return tbb::parallel_reduce(
        tbb::blocked_range<int>(0, height_), Sums(count, Rgb{0, 0, 0}),
        [&](const tbb::blocked_range<int>& rows, Sums sums) {
            std::vector<double> basis(count);
            for (int y = rows.begin(); y != rows.end(); ++y) {
                const double solid_angle = pixel_solid_angle(y);
                for (int x = 0; x < width_; ++x) {
                    const Rgb& value = pixel(x, y);
                    if (value[0] == 0 && value[1] == 0 && value[2] == 0) continue;
                    evaluate_sh(order, direction((x + 0.5) / width_, (y + 0.5) / height_), basis);
                    for (size_t k = 0; k < count; ++k)
                        for (int c = 0; c < 3; ++c) sums[k][c] += value[c] * basis[k] * solid_angle;
                }
            }
            return sums;
        },
        [](Sums a, const Sums& b) {
            for (size_t k = 0; k < a.size(); ++k)
                for (int c = 0; c < 3; ++c) a[k][c] += b[k][c];
            return a;
        });
}

EnvironmentSampler::EnvironmentSampler(const EnvironmentMap& map) : map_(&map) {
    const int w = map.width(), h = map.height();
    weight_.resize(static_cast<size_t>(w) * h);
    column_cdf_.resize(static_cast<size_t>(w + 1) * h);
    row_cdf_.assign(h + 1, 0.0);
    for (int y = 0; y < h; ++y) {
        const double solid_angle = map.pixel_solid_angle(y);
        double* cdf = column_cdf_.data() + static_cast<size_t>(y) * (w + 1);
        cdf[0] = 0;
        for (int x = 0; x < w; ++x) {
            const double weight = luminance(map.pixel(x, y)) * solid_angle;
            weight_[static_cast<size_t>(y) * w + x] = weight;
            cdf[x + 1] = cdf[x] + weight;
        }
        row_cdf_[y + 1] = row_cdf_[y] + cdf[w];
        if (cdf[w] > 0)
            for (int x = 1; x <= w; ++x) cdf[x] /= cdf[w];
    }
    total_ = row_cdf_[h];
    if (total_ > 0)
        for (double& c : row_cdf_) c /= total_;
}

namespace {

// The interval [cdf[i], cdf[i + 1]) that holds u (skipping empty ones), and u's place in it.
int invert_cdf(const double* cdf, int n, double u, double& offset) {
    const int i = std::clamp(static_cast<int>(std::upper_bound(cdf, cdf + n + 1, u) - cdf) - 1, 0, n - 1);
    const double width = cdf[i + 1] - cdf[i];
    offset = width > 0 ? std::clamp((u - cdf[i]) / width, 0.0, 1.0) : 0.5;
    return i;
}

}  // namespace

Eigen::Vector3d EnvironmentSampler::sample(double u1, double u2, double& pdf) const {
    const int w = map_->width(), h = map_->height();
    double dv = 0, du = 0;
    const int y = invert_cdf(row_cdf_.data(), h, u1, dv);
    const int x = invert_cdf(column_cdf_.data() + static_cast<size_t>(y) * (w + 1), w, u2, du);
    // Uniform in solid angle within the pixel: cos(theta) uniform between the row's edges.
    const double cos_top = std::cos(kPi * y / h), cos_bottom = std::cos(kPi * (y + 1) / h);
    const double cos_theta = cos_top + dv * (cos_bottom - cos_top);
    const double sin_theta = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
    const double phi = 2 * kPi * (x + du) / w - kPi;
    pdf = weight_[static_cast<size_t>(y) * w + x] / total_ / map_->pixel_solid_angle(y);
    return {sin_theta * std::sin(phi), cos_theta, -sin_theta * std::cos(phi)};
}

double EnvironmentSampler::pdf(const Eigen::Vector3d& w) const {
    if (!(total_ > 0)) return 0;
    const auto [x, y] = map_->pixel_of(w);
    return weight_[static_cast<size_t>(y) * map_->width() + x] / total_ / map_->pixel_solid_angle(y);
}

}  // namespace waxwork
