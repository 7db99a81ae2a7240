#include "editor/material_swatch.h"

#include "solver/material.h"

#include <algorithm>
#include <cmath>

namespace waxwork {

std::array<double, 3> diffuse_reflectance(const TetMaterial& material) {
    const double a = boundary_reflection_parameter(material.eta);
    std::array<double, 3> rd{};
    for (int c = 0; c < 3; ++c) {
        const double extinction = material.mua[c] + material.musp[c];
        const double albedo = extinction > 0 ? material.musp[c] / extinction : 0.0;
        const double root = std::sqrt(3 * (1 - albedo));
        rd[c] = 0.5 * albedo * (1 + std::exp(-4.0 / 3.0 * a * root)) * std::exp(-root);
    }
    return rd;
}

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
