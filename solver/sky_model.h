// The built-in environment: a clear sky (Preetham, Shirley and Smits 1999, "A Practical Analytic
// Model for Daylight", the Perez distribution of their Eq. 3 with the coefficients of their
// Appendix A.2) above a grey ground, and the sun as a directional light, so a scene can be lit by
// daylight without an HDR file. The sun stays out of the sky image: a disk half a degree wide
// would need a map of thousands of pixels, and its sharp shadow a transfer basis of far higher
// order than the sky's smooth gradient; as a directional light it gets one exact shadow ray.
//
// Units are relative, like every Waxwork light: the sun gives irradiance 1 on a surface facing it
// when it stands at the zenith (less and redder towards the horizon, through the air mass), and
// the sky keeps Preetham's luminance relative to it, scaled so that a zenith sun's sky gives a
// horizontal surface kZenithSkyIrradiance.
#pragma once

#include "solver/environment_map.h"
#include "solver/rgb.h"

#include <Eigen/Core>

namespace waxwork {

struct SkySettings {
    double sun_elevation_degrees = 45;  // above the horizon, (0, 90]
    double sun_azimuth_degrees = 30;    // from +z (the model's front) towards +x
    double turbidity = 3;               // haze: 2 (very clear) to 10 (hazy), the model's fitted range
};

// The horizontal irradiance of the sky dome with the sun at the zenith, relative to the sun's.
inline constexpr double kZenithSkyIrradiance = 0.15;
// The ground's albedo: the lower hemisphere shows the sun and sky reflected by a grey, diffuse ground.
inline constexpr double kGroundAlbedo = 0.2;

// Throws InvalidArgumentError for an elevation outside (0, 90], a non-finite azimuth or a turbidity
// outside [2, 10].
void validate(const SkySettings& sky);

// The unit direction from the model towards the sun.
Eigen::Vector3d sun_direction(const SkySettings& sky);

// The sky and ground as an equirectangular map (environment_map.h) of width x height pixels.
EnvironmentMap make_sky_map(const SkySettings& sky, int width = 256, int height = 128);

// The irradiance the sun gives a surface facing it, through the air mass of its elevation: the
// directional light travelling along -sun_direction that stands for it.
Rgb sun_irradiance(const SkySettings& sky);

}  // namespace waxwork
