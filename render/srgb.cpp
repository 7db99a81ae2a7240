#include "render/srgb.h"

#include <algorithm>
#include <cmath>

namespace waxwork {

double srgb_encode(double linear) {
    return linear < 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
}

double srgb_decode(double encoded) {
    return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

uint8_t srgb_byte(double linear) {
    if (!(linear > 0)) return 0;
    return static_cast<uint8_t>(std::lround(255 * srgb_encode(std::min(linear, 1.0))));
}

std::array<uint8_t, 3> srgb_bytes(const std::array<double, 3>& linear) {
    return {srgb_byte(linear[0]), srgb_byte(linear[1]), srgb_byte(linear[2])};
}

}  // namespace waxwork
