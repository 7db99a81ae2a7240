// Exitant radiance at the surface from the fluence (Li et al. 2013, Eq. 3, after Arbree et al. 2011),
// with the factor 1 / eta^2 of crossing the boundary:
//     L_o = F_t(theta_o) / (4 pi eta^2) [ (1 + 1/A) phi - 4 q / (1 + F_dr) ].
// The bracket over 4 pi is the diffusion's radiance just inside the surface. Leaving a medium of index
// eta into air, radiance over the squared index is what a refracting surface conserves (times F_t):
// the solid angle widens by eta^2 (the n^2 law of radiance; Veach 1997, Sec. 5.2). Eq. 3 as printed
// omits it; the Monte Carlo image (solver/reference/monte_carlo_image.h), which transports radiance
// across the boundary, measured the live image eta^2 too bright wherever diffusion holds
// (docs/diffusion_vs_transport.md).
// Everything but F_t(theta_o) is independent of the view: it is computed once per boundary vertex and
// channel (exitant_radiance_factor) and a fragment shader multiplies it by F_t(theta_o) per pixel.
//
// Negative values. In the continuous problem the bracket is non-negative; the discrete solution can
// dip slightly below zero next to shadow edges (phi is interpolated linearly while q jumps). Those
// values are discretisation noise and would show as black speckles or, in HDR, as negative light, so
// the factor is clamped at zero by default (RadianceOptions::clamp_negative).
#pragma once

#include "solver/shading_surface.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <vector>

namespace waxwork {

// The factor is linear in phi and q: E = phi_weight phi - q_weight q (before the clamp). The GPU's
// radiance pass takes the two weights per vertex.
struct ExitantRadianceWeights {
    double phi_weight = 0;
    double q_weight = 0;
};
ExitantRadianceWeights exitant_radiance_weights(double eta);

// The view-independent factor for one vertex and channel.
double exitant_radiance_factor(double phi, double q, double eta, bool clamp_negative = true);

// L_o for a view direction at angle acos(cos_view) to the outward normal.
double exitant_radiance(double phi, double q, double eta, double cos_view, bool clamp_negative = true);

// Per vertex, the relative index of refraction seen by its boundary faces: the area-weighted mean of
// the eta of the tets owning them (painted volumes may differ per face); 1 at interior vertices.
std::vector<double> boundary_vertex_eta(const TetMesh& mesh, const TetConnectivity& connectivity,
                                        const std::vector<TetMaterial>& materials);

struct RadianceOptions {
    bool clamp_negative = true;
};

// exitant_radiance_factor at every vertex (zero at interior vertices), per channel, in float for upload.
std::vector<std::array<float, 3>> exitant_radiance_factors(const TetMesh& mesh, const TetConnectivity& connectivity,
                                                           const std::vector<TetMaterial>& materials,
                                                           const std::vector<std::array<double, 3>>& phi,
                                                           const std::vector<std::array<double, 3>>& q,
                                                           const RadianceOptions& options = {});

// E per shading vertex (shading_surface.h): phi of its volume vertex (surface.vertices of its surface
// vertex), its own q (ShadingLight::q) and its surface vertex's eta. Equal to exitant_radiance_factors
// at the copies of vertices that are not split. Throws InvalidArgumentError for mismatched sizes.
std::vector<std::array<float, 3>> shading_radiance_factors(const BoundarySurface& surface,
                                                           const ShadingSurface& shading,
                                                           const std::vector<std::array<double, 3>>& phi,
                                                           const std::vector<std::array<double, 3>>& shading_q,
                                                           const RadianceOptions& options = {});

}  // namespace waxwork
