// The environment as the renderer draws it: behind the model (a reduced copy of the map) and in the
// surface's specular reflection (the map convolved with the GGX lobe of the surface's roughness).
//
// The reflection uses the split-sum approximation (Karis 2013, "Real Shading in Unreal Engine 4",
// Eqs. 4-5): the integral of L(l) f(l, v) (n . l) over the hemisphere is split into the environment
// averaged over the lobe, prefiltered here once per map and roughness with n = v = r, times the
// integral of the BRDF against a white environment, which the shader takes from an analytic fit. The
// first factor is
//
//   L_pre(r) = sum_k L(l_k) (n . l_k) / sum_k (n . l_k),   l_k drawn from the GGX lobe about r,
//
// Karis's Eq. 5 estimator, with filtered importance sampling (Krivanek and Colbert 2008, "Real-time
// Shading with Filtered Importance Sampling", Eq. 13) reading each sample from the level of a box
// pyramid whose texels cover the sample's share of the lobe, so 64 samples give a smooth result.
//
// Hand-written: no Debian-packaged library prefilters equirectangular maps (cmft, IBLBaker and
// Filament's cmgen are not packaged), and the work is one small loop over texels.
#pragma once

#include "solver/environment_map.h"

#include <array>
#include <vector>

namespace waxwork {

// An equirectangular image in the environment map's convention (environment_map.h), linear RGB.
struct EnvironmentTexture {
    int width = 0;
    int height = 0;
    std::vector<std::array<float, 3>> texels;  // row-major, row 0 at the zenith
};

// The map box-filtered by halving until it is at most `max_width` wide (each texel the mean of the
// pixels it covers); the map itself when already that narrow. InvalidArgumentError for max_width < 1.
EnvironmentTexture reduce_environment(const EnvironmentMap& map, int max_width);
// The same from a texture already reduced (halving is deterministic, so reducing a reduction gives
// what reducing the map further would).
EnvironmentTexture reduce_environment(const EnvironmentTexture& texture, int max_width);

// L_pre above for GGX roughness `roughness` (alpha = roughness^2, as the renderer's highlight), on a
// `width` by width / 2 texture with `samples` lobe directions per texel. InvalidArgumentError for a
// roughness outside (0, 1], width < 2 or samples < 1.
inline constexpr int kPrefilterWidth = 256;
inline constexpr int kPrefilterSamples = 64;
EnvironmentTexture prefilter_environment(const EnvironmentMap& map, float roughness, int width = kPrefilterWidth,
                                         int samples = kPrefilterSamples);
// The same from a reduction of the map (reduce_environment, at least 512 wide or the map's own
// width): the renderer prefilters the background texture it has just reduced instead of reducing the
// full map a second time. Equal to the map's prefilter bit for bit.
EnvironmentTexture prefilter_environment(const EnvironmentTexture& source, float roughness,
                                         int width = kPrefilterWidth, int samples = kPrefilterSamples);

}  // namespace waxwork
