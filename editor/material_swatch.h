// The colour a material shows under white light, for the material panel's swatches: the total diffuse
// reflectance R_d of a semi-infinite slab in the dipole approximation (Jensen et al. 2001, Eq. 5 with
// the reduced albedo alpha' = mu_s' / (mu_a + mu_s')), the same diffusion theory the solver uses, so a
// swatch ranks materials as the renders do (skim milk pale and bluish, ketchup dark red). Closed form,
// per channel, independent of scale.
#pragma once

#include "tetops/tet_mesh.h"

#include <array>

namespace waxwork {

// R_d per rgb channel, linear, in [0, 1).
std::array<double, 3> diffuse_reflectance(const TetMaterial& material);

// R_d encoded to sRGB in [0, 1] (what an ImGui colour swatch takes).
std::array<float, 3> swatch_colour(const TetMaterial& material);

}  // namespace waxwork
