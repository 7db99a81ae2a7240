// The classical dipole of Jensen et al. 2001 ("A Practical Model for Subsurface Light Transport",
// Sec. 2.4-2.5): the diffusion solution in a homogeneous semi-infinite medium lit at one surface point,
// the diffusion profile R_d(r) that Maisch & Ropinski's Spatial Adjacency Maps (seed paper 003, Sec. 2.3
// and Eq. 5) integrate over the surface.
//
// Light entering at a surface point becomes a real point source of power alpha' (per unit transmitted
// flux) at depth z_r = 1 / sigma_t' and a negative virtual source at height z_v = z_r + 4 A D above the
// surface, so that the fluence vanishes on the extrapolated boundary 2 A D outside it (the linear
// extrapolation of the Robin boundary phi + 2 A D dphi/dn = 0 of the shared physics, D = kappa):
//   phi(x)  = alpha' / (4 pi D) [ exp(-sigma d_r) / d_r - exp(-sigma d_v) / d_v ],
//   R_d(r)  = alpha' / (4 pi) [ z_r (1 + sigma d_r) exp(-sigma d_r) / d_r^3 + z_v (1 + sigma d_v) exp(-sigma d_v) / d_v^3 ],
// d_r, d_v the distances to the two sources (at the surface, sqrt(r^2 + z_r^2) and sqrt(r^2 + z_v^2)),
// sigma = sigma_tr = sqrt(mu_a / D). R_d is the flux leaving the surface at distance r (Fick's law at the
// surface), per unit area and per unit flux entering.
//
// Both kernels integrate over the surface plane in closed form (d/dr [exp(-sigma d) / d] =
// -(1 + sigma d) exp(-sigma d) r / d^3), which gives the exact share of a source's light that falls
// beyond a radius: the cut-off of the method.
#pragma once

#include <Eigen/Core>

namespace waxwork {

class DipoleProfile {
public:
    // Coefficients per mm, eta the relative index of refraction (material.h).
    DipoleProfile(double mua, double musp, double eta);

    // R_d at surface distance r (mm), per mm^2.
    double reflectance(double r) const;
    // The integral of R_d(r') 2 pi r' dr' from r to infinity: the flux leaving beyond r.
    double reflectance_tail(double r) const;
    // reflectance_tail(0): the total diffuse reflectance of the half-space (material.h diffuse_reflectance).
    double total_reflectance() const { return reflectance_tail(0.0); }
    // The mean of R_d over a disk of radius rho centred on the source: the self term of a vertex whose
    // surface area is pi rho^2.
    double disk_mean_reflectance(double rho) const;

    // Fluence at a point whose distances to the real and virtual sources are d_real and d_virtual (mm).
    double fluence(double d_real, double d_virtual) const;
    // The integral of the surface fluence (z = 0) over the plane beyond r, relative to its total.
    double relative_fluence_tail(double r) const;

    // The smallest radius beyond which at most `tolerance` of both the exitance (R_d) and the surface
    // fluence of a source fall, capped at `cap` (mm).
    double cutoff_radius(double tolerance, double cap) const;

    double depth_real() const { return z_r_; }      // z_r, mm below the surface
    double height_virtual() const { return z_v_; }  // z_v, mm above the surface
    double sigma_tr() const { return sigma_; }
    double diffusion_coefficient() const { return d_; }
    double reduced_albedo() const { return alpha_; }

private:
    double alpha_ = 0, d_ = 0, sigma_ = 0, z_r_ = 0, z_v_ = 0;
};

}  // namespace waxwork
