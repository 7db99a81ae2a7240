// Where the live image can be trusted against radiative transport. The diffusion approximation behind
// it (TransCut's phi through Eq. 3) was measured against the camera-ray Monte Carlo image over
// materials, sizes, thin plates and cut cross-sections (docs/diffusion_vs_transport.md): its light
// distribution stays within about 20% of transport where the reduced albedo mu_s' / (mu_a + mu_s') is
// at least 0.99 in every channel, and is off by 13-73% below that (skin in green and blue, ketchup).
// The editor shows the warning this gives on views outside that regime.
#pragma once

#include "tetops/tet_mesh.h"

#include <span>
#include <string>

namespace waxwork {

inline constexpr double kTrustedReducedAlbedo = 0.99;

// The lowest reduced albedo over the materials and their channels, and the material it belongs to.
struct ReducedAlbedoFloor {
    double reduced_albedo = 1;
    int channel = 0;           // 0 red, 1 green, 2 blue
    TetMaterial material;
};
// Materials come in long runs (presets, painted regions): a run is looked at once. Empty input: 1.
ReducedAlbedoFloor lowest_reduced_albedo(std::span<const TetMaterial> materials);

// One line for the user when some material is under kTrustedReducedAlbedo (naming it: its preset, else
// its coefficients, and the channel), empty when every material is within the trusted regime.
std::string diffusion_trust_warning(std::span<const TetMaterial> materials);

}  // namespace waxwork
