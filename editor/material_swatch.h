// The colour a material shows under white light, for the material panel's swatches: its total diffuse
// reflectance (diffuse_reflectance, solver/material.h), the same diffusion theory the solver uses, so a
// swatch ranks materials as the renders do (skim milk pale and bluish, ketchup dark red).
#pragma once

#include "tetops/tet_mesh.h"

#include <array>

namespace waxwork {

// R_d encoded to sRGB in [0, 1] (what an ImGui colour swatch takes).
std::array<float, 3> swatch_colour(const TetMaterial& material);

}  // namespace waxwork
