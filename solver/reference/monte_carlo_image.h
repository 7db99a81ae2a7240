// The Monte Carlo image: exitant radiance per pixel traced from the camera into the volume, the
// physical answer the live image (Eq. 3 from the diffusion's phi) approximates (docs/monte_carlo.md).
//
// A camera ray hits the boundary, refracts in with the Fresnel transmittance (the reflected part, the
// highlight, is not traced: the comparison is of the subsurface term) and walks through the per-tet
// coefficients as the photon tracer does (monte_carlo.h: tet-by-tet traversal, Henyey-Greenstein with
// mu_s = mu_s' / (1 - g), continuous absorption, Russian roulette, Fresnel reflection at the boundary).
// At every scattering event it connects to each direct light (next-event estimation): the straight path
// to the boundary that refracts exactly into the light's direction at the face it reaches (found by
// iterating the refraction at the reached face; exact on a flat face), attenuated by exp(-int mu_t),
// the light's transmitted q there (photon_sources: with its shadows from every piece) over cos theta_t
// as the beam's irradiance inside, and the phase function. Single scattering is therefore included.
// The diffuse component (ambient, environment) is collected where the walk meets the boundary inside
// the cone that refracts out: the photon tracer enters it cosine-distributed outside and refracted, so
// its radiance inside is eta^2 q / pi there. Radiance leaves through the boundary as
// L_o = F_t(theta_o) L_i / eta^2 (radiance over eta^2 is conserved across a refracting surface).
//
// Units: radiance in units of q per steradian, as the live image's E (radiance.h).
#pragma once

#include "base/progress.h"
#include "solver/lighting.h"
#include "solver/reference/camera_rays.h"
#include "solver/reference/monte_carlo.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace waxwork {

struct MonteCarloImage {
    RadianceImage image;  // mean radiance and coverage per pixel
    // Per pixel and channel: the standard error of the mean radiance (from the spread of its passes).
    std::vector<std::array<double, 3>> radiance_error;
    // Per channel: |radiance_error| / |radiance| (2-norms over the pixels the object covers).
    std::array<double, 3> relative_error{};
    int64_t passes = 0;  // samples per pixel
    int64_t paths = 0;   // camera paths per channel that entered the volume
    int64_t lost_paths = 0;
    double seconds = 0;
    std::string stop_reason;  // "photons" (the path budget), "seconds", "error", or "no light"
};

// Traces the image seen by `camera`. Options as for trace_fluence, read as: max_photons the camera
// paths per channel that enter the volume, min_batches the passes before the error target is trusted
// (batch_photons is not used: a pass is one jittered sample per pixel). Each pixel and pass draws from
// its own random stream derived from (seed, pass, pixel), so the image is bit-identical on any thread
// count. Parallel over rows (TBB); progress after each round of passes, cancel checked before every row
// (CancelledError). `grid` is surface_hit_grid(surface). Throws as trace_fluence.
MonteCarloImage trace_camera_image(const TetMesh& mesh, const TetConnectivity& connectivity,
                                   const std::vector<TetMaterial>& materials, const BoundarySurface& surface,
                                   const FirstHitGrid& grid, const std::vector<PhotonSource>& sources,
                                   const PixelCamera& camera, const MonteCarloOptions& options,
                                   const std::function<void(const MonteCarloProgress&)>& progress = {},
                                   const Progress* cancel = nullptr);

}  // namespace waxwork
