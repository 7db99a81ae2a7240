// The environment light: distant radiance from every direction (an HDR image or the built-in sky),
// rotated about the up axis and scaled, and its incident light q at a boundary point,
//
//   q_env(x) = integral over the hemisphere of n of L(R^-1 w) V(x, w) F_t(n . w, eta) (n . w) dw,
//
// the environment's share of the boundary source of the diffusion equation (lighting.h). Two ways to
// evaluate it live here: the sampled integral (the reference: multiple importance sampling of the
// cosine and the environment's luminance), and the transfer of environment_transfer.h, which
// projects everything but L onto spherical harmonics once per geometry so that rotating or
// rescaling the environment is a dot product per vertex.
#pragma once

#include "solver/environment_map.h"
#include "solver/rgb.h"
#include "solver/sky_model.h"

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace waxwork {

// The spherical-harmonics order of the environment's projection and of every transfer vector. 81
// coefficients: on spot under a studio softbox 40 by 25 degrees wide the transfer is within 1.6% (L2)
// of the sampled integral at order 8 and 2.4% at order 6, and a sky dome is at the 0.5% floor of the
// 256-ray sampling from order 4 (`waxwork bench --only environment`); a relight still costs well under
// a millisecond per 10K vertices.
inline constexpr int kDefaultTransferOrder = 8;

struct EnvironmentLight {
    std::shared_ptr<const EnvironmentMap> map;
    // The map's projection onto bands 0..sh_order, unrotated and unscaled (environment_light below
    // computes it once per map).
    std::shared_ptr<const std::vector<Rgb>> sh;
    int sh_order = kDefaultTransferOrder;
    // Set for the built-in sky: its sun joins the lights as a directional light (lighting.h:
    // direct_lights), rotated and scaled with the sky.
    std::optional<SkySettings> sky;
    // Where the map came from, as a session or the command line names it: the .hdr file's path, or
    // empty for the sky.
    std::string file;
    double rotation_degrees = 0;  // about +y, right-handed
    double intensity = 1;         // scales the radiance (and the sun)
    bool background = true;       // drawn behind the model
};

// The environment of an HDR image or the sky, with its projection computed.
EnvironmentLight environment_light(std::shared_ptr<const EnvironmentMap> map, int sh_order = kDefaultTransferOrder);
EnvironmentLight sky_environment_light(const SkySettings& sky, int sh_order = kDefaultTransferOrder);

// Throws InvalidArgumentError for a missing map or projection, a non-finite rotation, or an
// intensity negative, non-finite or beyond 1e15.
void validate(const EnvironmentLight& environment);

// The projection rotated by the environment's rotation and scaled by its intensity: the vector every
// transfer is dotted with.
std::vector<Rgb> environment_sh(const EnvironmentLight& environment);

// The radiance arriving from world direction w (rotation and intensity applied).
Rgb environment_radiance(const EnvironmentLight& environment, const Eigen::Vector3d& w);

// "FILE.hdr[:ROT_DEG[:INTENSITY]]" or "sky:SUN_ELEV_DEG,SUN_AZIM_DEG[,TURBIDITY][:ROT_DEG[:INTENSITY]]",
// as `--env` takes it; the file is not read here (scene/environment_loading.h loads it).
struct EnvironmentSpec {
    std::string file;                // empty for the sky
    std::optional<SkySettings> sky;  // set for the sky
    double rotation_degrees = 0;
    double intensity = 1;
};
// Throws InvalidArgumentError("bad environment spec 'SPEC': WHY").
EnvironmentSpec parse_environment_spec(std::string_view spec);

}  // namespace waxwork
