#include "solver/sky_model.h"

#include "base/error.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace waxwork {

namespace {

constexpr double kPi = std::numbers::pi;

double radians(double degrees) { return degrees * kPi / 180; }

// The Perez function F(theta, gamma) = (1 + A e^(B / cos theta)) (1 + C e^(D gamma) + E cos^2 gamma),
// Preetham et al. Eq. 3; theta is the view direction's zenith angle, gamma its angle to the sun.
struct Perez {
    double a, b, c, d, e;
    double operator()(double cos_theta, double gamma) const {
        // The horizon is the fit's singularity (1 / cos theta); directions just above it take its limit.
        const double cos_t = std::max(cos_theta, 1e-3);
        const double cos_g = std::cos(gamma);
        return (1 + a * std::exp(b / cos_t)) * (1 + c * std::exp(d * gamma) + e * cos_g * cos_g);
    }
};

// Luminance Y (kcd/m^2) and chromaticity (x, y) of the clear sky: Appendix A.2 of Preetham et al.
struct PreethamSky {
    Perez luminance, x, y;
    double zenith_luminance, zenith_x, zenith_y;
    double theta_sun;
    Eigen::Vector3d sun;

    PreethamSky(const Eigen::Vector3d& sun_direction, double t) : sun(sun_direction) {
        luminance = {0.1787 * t - 1.4630, -0.3554 * t + 0.4275, -0.0227 * t + 5.3251, 0.1206 * t - 2.5771,
                     -0.0670 * t + 0.3703};
        x = {-0.0193 * t - 0.2592, -0.0665 * t + 0.0008, -0.0004 * t + 0.2125, -0.0641 * t - 0.8989,
             -0.0033 * t + 0.0452};
        y = {-0.0167 * t - 0.2608, -0.0950 * t + 0.0092, -0.0079 * t + 0.2102, -0.0441 * t - 1.6537,
             -0.0109 * t + 0.0529};
        theta_sun = std::acos(std::clamp(sun.y(), -1.0, 1.0));
        const double s = theta_sun, s2 = s * s, s3 = s2 * s, t2 = t * t;
        const double chi = (4.0 / 9.0 - t / 120.0) * (kPi - 2 * s);
        // The fit goes negative for a very hazy sky low on the horizon; a dim positive floor keeps it a sky.
        zenith_luminance = std::max((4.0453 * t - 4.9710) * std::tan(chi) - 0.2155 * t + 2.4192, 0.05);
        zenith_x = (0.00166 * s3 - 0.00375 * s2 + 0.00209 * s) * t2 +
                   (-0.02903 * s3 + 0.06377 * s2 - 0.03202 * s + 0.00394) * t +
                   (0.11693 * s3 - 0.21196 * s2 + 0.06052 * s + 0.25886);
        zenith_y = (0.00275 * s3 - 0.00610 * s2 + 0.00317 * s) * t2 +
                   (-0.04214 * s3 + 0.08970 * s2 - 0.04153 * s + 0.00516) * t +
                   (0.15346 * s3 - 0.26756 * s2 + 0.06670 * s + 0.26688);
    }

    // Linear sRGB radiance (relative units: Y in kcd/m^2) towards the sky direction w (w.y >= 0).
    Rgb radiance(const Eigen::Vector3d& w) const {
        const double cos_theta = w.y();
        const double gamma = std::acos(std::clamp(w.dot(sun), -1.0, 1.0));
        const double big_y = zenith_luminance * luminance(cos_theta, gamma) / luminance(1.0, theta_sun);
        const double cx = zenith_x * x(cos_theta, gamma) / x(1.0, theta_sun);
        const double cy = zenith_y * y(cos_theta, gamma) / y(1.0, theta_sun);
        // xyY to XYZ to linear sRGB (IEC 61966-2-1, D65 white).
        const double big_x = cx * big_y / cy, big_z = (1 - cx - cy) * big_y / cy;
        return {std::max(0.0, 3.2404542 * big_x - 1.5371385 * big_y - 0.4985314 * big_z),
                std::max(0.0, -0.9692660 * big_x + 1.8760108 * big_y + 0.0415560 * big_z),
                std::max(0.0, 0.0556434 * big_x - 0.2040259 * big_y + 1.0572252 * big_z)};
    }
};

// The sky's irradiance luminance on an upward horizontal surface (midpoint rule in theta and phi).
double horizontal_sky_irradiance(const PreethamSky& sky) {
    constexpr int kTheta = 64, kPhi = 128;
    double sum = 0;
    for (int i = 0; i < kTheta; ++i) {
        const double theta = (i + 0.5) * (kPi / 2) / kTheta;
        for (int j = 0; j < kPhi; ++j) {
            const double phi = (j + 0.5) * 2 * kPi / kPhi;
            const Eigen::Vector3d w(std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi));
            sum += luminance(sky.radiance(w)) * std::cos(theta) * std::sin(theta);
        }
    }
    return sum * (kPi / 2 / kTheta) * (2 * kPi / kPhi);
}

// Transmittance of the atmosphere along the sun's path relative to the zenith's: per channel
// exp(-tau (m - 1)) with the relative air mass m of Kasten and Young (1989) and optical depths of
// Rayleigh scattering at 680, 550 and 450 nm plus a grey aerosol term growing with turbidity.
Rgb sun_transmittance(const SkySettings& sky) {
    const double e = sky.sun_elevation_degrees;
    const double air_mass = 1 / (std::sin(radians(e)) + 0.50572 * std::pow(e + 6.07995, -1.6364));
    const double aerosol = 0.03 * (sky.turbidity - 1);
    const Rgb rayleigh = {0.044, 0.098, 0.22};
    Rgb t;
    for (int c = 0; c < 3; ++c) t[c] = std::exp(-(rayleigh[c] + aerosol) * (air_mass - 1));
    return t;
}

}  // namespace

void validate(const SkySettings& sky) {
    if (!(sky.sun_elevation_degrees > 0 && sky.sun_elevation_degrees <= 90))
        throw InvalidArgumentError("sky: sun elevation must be above 0 and at most 90 degrees");
    if (!std::isfinite(sky.sun_azimuth_degrees)) throw InvalidArgumentError("sky: sun azimuth must be finite");
    if (!(sky.turbidity >= 2 && sky.turbidity <= 10))
        throw InvalidArgumentError("sky: turbidity must be between 2 and 10 (the model's fitted range)");
}

Eigen::Vector3d sun_direction(const SkySettings& sky) {
    const double e = radians(sky.sun_elevation_degrees), a = radians(sky.sun_azimuth_degrees);
    return {std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)};
}

Rgb sun_irradiance(const SkySettings& sky) {
    validate(sky);
    return sun_transmittance(sky);
}

EnvironmentMap make_sky_map(const SkySettings& sky, int width, int height) {
    validate(sky);
    const PreethamSky model(sun_direction(sky), sky.turbidity);
    const double scale = kZenithSkyIrradiance /
                         horizontal_sky_irradiance(PreethamSky(Eigen::Vector3d::UnitY(), sky.turbidity));
    // The ground reflects the sun and sky falling on it, diffusely.
    const Rgb sun = sun_irradiance(sky);
    const double sky_irradiance = scale * horizontal_sky_irradiance(model);
    const double sin_elevation = std::sin(radians(sky.sun_elevation_degrees));
    Rgb ground;
    for (int c = 0; c < 3; ++c)
        ground[c] = kGroundAlbedo / kPi * (sun[c] * sin_elevation + sky_irradiance);

    std::vector<Rgb> pixels(static_cast<size_t>(width) * std::max(height, 0));
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const Eigen::Vector3d w = EnvironmentMap::direction((x + 0.5) / width, (y + 0.5) / height);
            Rgb& p = pixels[static_cast<size_t>(y) * width + x];
            if (w.y() < 0) {
                p = ground;
            } else {
                p = model.radiance(w);
                for (double& c : p) c *= scale;
            }
        }
    }
    return EnvironmentMap(width, height, std::move(pixels),
                          "sky:" + std::to_string(sky.sun_elevation_degrees) + "," +
                              std::to_string(sky.sun_azimuth_degrees));
}

}  // namespace waxwork
