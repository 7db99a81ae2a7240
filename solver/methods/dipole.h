// The `dipole` method: surface-only translucency after Maisch & Ropinski, "Spatial Adjacency Maps for
// Translucency Simulation under General Illumination" (seed paper 003), with the classical dipole
// profile of Jensen et al. 2001 (dipole_profile.h).
//
// The paper's radiance (Eq. 5) is a surface integral of the diffusion profile against the light that
// enters: for every boundary vertex x_o, the radiant exitance
//     M(x_o) = sum_i K_oi q_i,   K_oi ~ integral over the area of x_i of R_d(|x - x_o|)   (Eqs. 8-11)
// over every boundary vertex x_i within the cut-off radius (a kd-tree, nanoflann), where q_i is the
// incident light already through the Fresnel transmittance (lighting.h), i.e. the flux entering per
// unit area: the paper's L_d (Eq. 4). The paper splits each sum into the front side A_+ (a surface blur)
// and the back side A_- of x_o (Eqs. 6-7, the translucency), with the back side defined by Eqs. 13-14;
// here both are evaluated with the same profile over Euclidean distance (the paper's ground truth,
// Sec. 5.1), or the back side with the SAM's n strongest samples (Eq. 12, back_side_samples), and the
// back-side share is reported.
//
// From exitance to fluence. In the shared physics the bracket of the exitant radiance is 4 J+, with
// J+ = phi/4 - (D/2) dphi/dn the outgoing partial current just inside the surface: eliminating dphi/dn
// with the Robin boundary gives J+ = (1/4) [ (1 + 1/A) phi - 4 q / (1 + F_dr) ], so that
// L_o = F_t / (4 pi) [ ... ] = F_t J+ / pi. Of J+ the boundary lets (1 - F_dr) J+ out (the rest is the
// reflected F_dr J+ of the same boundary condition), and the radiance render draws (with its 1 / eta^2,
// radiance.h), integrated over the hemisphere, carries that flux out (to 0.2%, the fit of F_dr). The
// dipole's R_d is that escaping flux (Fick's law at the extrapolated boundary, where the inward current
// is F_dr J+). So M = (1 - F_dr) J+, and
//     phi = [ 4 M / (1 - F_dr) + 4 q / (1 + F_dr) ] / (1 + 1/A) = 2 (A M + q),
// using 1 + 1/A = 2 / (1 + F_dr) and A (1 - F_dr) = 1 + F_dr. Without absorption R_d integrates to 1,
// and a uniformly lit half-space gets phi = 2 (A + 1) q = 4 q / (1 - F_dr): the exact Robin solution.
// With absorption the dipole (a source at depth 1 / sigma_t' and an extrapolated boundary) differs from
// the Robin half-space by a few percent (docs/method_dipole.md).
//
// Interior vertices get the dipole's own fluence at depth: the sum over boundary vertices of
// q_i area_i phi_dipole(x), with each source's dipole placed along its inward normal. It is the only
// interior field the method has; near the surface it is lower than 2 (A M + q) (the dipole's fluence
// holds no uncollided light), deep inside it decays like the Robin solution, 13% above it (docs).
//
// Where it fails: thin parts (the profile assumes a semi-infinite medium: light through a slab thinner
// than a few diffusion lengths is far too dark) and concave regions (Euclidean distances cross air).
// Thin parts are measured and warned about; pairs whose light would cross air are left out (a ray cast
// between the dipoles' real sources) and their share is warned about (DipoleDiagnostics,
// docs/method_dipole.md).
#pragma once

#include "solver/methods/method_problem.h"

namespace waxwork {

struct DipoleOptions {
    // The resolution knob besides the mesh: the share of each source's exitance and surface fluence
    // allowed to fall beyond the cut-off radius (DipoleProfile::cutoff_radius). Smaller is more
    // accurate and slower (the pairs grow with the radius squared). In (0, 0.5].
    double profile_tolerance = 1e-3;
    // A boundary vertex is thin when its nearest back-side vertex (Eqs. 13-14) is closer than this many
    // diffusion lengths (the longest over channels and materials). The paper (Sec. 6) notes that the
    // nearest back-side sample approximates the local thickness. Positive.
    double thin_diffusion_lengths = 3.0;
    // A warning is issued when the thin vertices cover more than this share of the surface area, or when
    // more than this share of the exitance would cross air. In [0, 1].
    double warning_fraction = 0.05;
    // Leave out pairs whose light would cross air (concave regions, facing surfaces); false keeps them,
    // as a plain Euclidean profile sum does (for comparisons).
    bool leave_out_air_crossings = true;
    // 0: every back-side vertex within the cut-off contributes (the paper's ground truth, Sec. 5.1).
    // n > 0: only the n back-side vertices of largest form factor K_oi, as a Spatial Adjacency Map
    // stores them (Eq. 12; the paper uses n = 3); the front side is still summed in full (the paper's
    // surface blur). Non-negative.
    int back_side_samples = 0;
};

struct DipoleDiagnostics {
    double cutoff_radius_mm = 0;
    double thin_area_fraction = 0;   // boundary area thinner than thin_diffusion_lengths
    double thin_length_mm = 0;       // that thickness in mm
    double back_side_share = 0;      // share of the exitance from back-side vertices (Eq. 7), channel 0
    double through_air_share = 0;    // share of the exitance dropped as crossing air, channel 0
    size_t pairs = 0;                // vertex pairs evaluated (boundary-boundary and interior-boundary)
};

// phi at every vertex of problem.mesh from the dipole (above). Throws InvalidArgumentError
// ("dipole: ...") for mismatched sizes, invalid materials or scale, a volume without boundary or bad
// options, and CancelledError when problem.progress asks to stop.
MethodSolution solve_dipole(const MethodProblem& problem, const DipoleOptions& options = {},
                            DipoleDiagnostics* diagnostics = nullptr);

}  // namespace waxwork
