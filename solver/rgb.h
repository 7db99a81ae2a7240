// Per-channel light values (irradiance, radiance, q): linear RGB in double.
#pragma once

#include <array>

namespace waxwork {

using Rgb = std::array<double, 3>;

// Luminance of linear RGB with the Rec. 709 / sRGB primaries.
inline double luminance(const Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

}  // namespace waxwork
