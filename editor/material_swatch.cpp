#include "editor/material_swatch.h"

#include "solver/material.h"

#include <algorithm>
#include <cmath>

namespace waxwork {

std::array<float, 3> swatch_colour(const TetMaterial& material) {
    const std::array<double, 3> rd = diffuse_reflectance(material);
    std::array<float, 3> srgb{};
    for (int c = 0; c < 3; ++c) {
        const double x = std::clamp(rd[c], 0.0, 1.0);
        srgb[c] = static_cast<float>(x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055);
    }
    return srgb;
}

}  // namespace waxwork
