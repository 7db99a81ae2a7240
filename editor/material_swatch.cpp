#include "editor/material_swatch.h"

#include "render/srgb.h"
#include "solver/material.h"

#include <algorithm>

namespace waxwork {

std::array<float, 3> swatch_colour(const TetMaterial& material) {
    const std::array<double, 3> rd = diffuse_reflectance(material);
    std::array<float, 3> srgb{};
    for (int c = 0; c < 3; ++c) {
        srgb[c] = static_cast<float>(srgb_encode(std::clamp(rd[c], 0.0, 1.0)));
    }
    return srgb;
}

}  // namespace waxwork
