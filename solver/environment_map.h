// A distant radiance field stored as an equirectangular (latitude-longitude) image: the environment
// light. Pixel values are linear RGB radiance, constant over each pixel, which is the function every
// consumer integrates: the spherical-harmonics projection sums pixels, the importance sampler draws
// pixels in proportion to their power, and a lookup returns the pixel a direction falls in, so the
// projection, the sampled reference and the background agree on one function.
//
// Convention (y up): row 0 is the zenith, theta = pi (y + 0.5) / height from +y; column x covers
// phi = 2 pi (x + 0.5) / width - pi measured from -z towards +x, so the image centre lies along -z,
// behind a model that faces +z, and the left and right edges along +z.
#pragma once

#include "solver/rgb.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace waxwork {

class EnvironmentMap {
public:
    EnvironmentMap() = default;
    // Throws InvalidArgumentError naming `name` (the file or the generator) for a zero or absurd
    // size (beyond 65536 a side or 8192 x 4096 pixels), a pixel count that disagrees with the size, a non-finite or
    // negative value (with its pixel), or a value beyond kMaxLightIntensity.
    EnvironmentMap(int width, int height, std::vector<Rgb> radiance, std::string name);

    int width() const { return width_; }
    int height() const { return height_; }
    const std::string& name() const { return name_; }
    const Rgb& pixel(int x, int y) const { return radiance_[static_cast<size_t>(y) * width_ + x]; }

    // The radiance arriving from unit direction `w` (the pixel it falls in).
    const Rgb& radiance(const Eigen::Vector3d& w) const;
    // The pixel (x, y) that direction `w` falls in.
    std::array<int, 2> pixel_of(const Eigen::Vector3d& w) const;
    // The unit direction of image coordinates (u, v) in [0, 1]^2 (u across, v down).
    static Eigen::Vector3d direction(double u, double v);
    // The solid angle of a pixel of row y.
    double pixel_solid_angle(int y) const;

    // Coefficients of bands 0..order of the radiance (spherical_harmonics.h), per channel: the exact
    // integral of each basis function over each pixel's solid angle approximated by its centre value.
    std::vector<Rgb> project_to_sh(int order) const;

private:
    int width_ = 0;
    int height_ = 0;
    std::vector<Rgb> radiance_;  // row-major, row 0 at the zenith
    std::string name_;
};

// Draws directions from an environment map in proportion to each pixel's luminance times its solid
// angle (a piecewise-constant 2D distribution: a marginal over rows and a conditional per row, as in
// pbrt-v4's PiecewiseConstant2D), the sampling density that makes a bright sun cheap to integrate.
// Hand-written: the standard library's discrete distributions neither invert a given uniform number
// (the stratified, reproducible samples the incident light uses) nor report densities.
class EnvironmentSampler {
public:
    explicit EnvironmentSampler(const EnvironmentMap& map);

    // False for a black map: nothing to sample.
    bool valid() const { return total_ > 0; }
    // The direction for the uniform pair (u1, u2) in [0, 1)^2, with its density per steradian.
    Eigen::Vector3d sample(double u1, double u2, double& pdf) const;
    // The density per steradian sample() draws `w` with.
    double pdf(const Eigen::Vector3d& w) const;

private:
    const EnvironmentMap* map_;
    std::vector<double> row_cdf_;     // height + 1 entries, 0 .. 1
    std::vector<double> column_cdf_;  // height rows of width + 1 entries, 0 .. 1 within each row
    std::vector<double> weight_;      // luminance times solid angle per pixel
    double total_ = 0;
};

}  // namespace waxwork
