// Lattice units of the `lbm` method (solver/methods/lbm.h): how the relaxation time, the lattice spacing
// and the time step of the D3Q6 lattice (Bernabei et al., seed 004, Eqs. 4-5) relate to kappa and mu_a,
// and the boundary link coefficients that impose TransCut's Robin condition.
//
// Lattice units. The D3Q6 lattice has sound speed c_s^2 = 1/3 (lattice spacing dx = cell size, time
// step dt). The BGK collision with relaxation time tau diffuses with (Chapman-Enskog)
//     D = c_s^2 (tau - 1/2) dx^2 / dt,
// so a material of diffusion coefficient kappa (mm) gets tau = 1/2 + 3 kappa dt / dx^2 and absorbs
// mu_a dt per step. Only the steady state is wanted, so dt is free: Waxwork picks it so that the most
// diffusive material (and channel) has the relaxation time LbmOptions::tau,
//     dt = (tau - 1/2) dx^2 / (3 kappa_max),
// and every other material gets a tau in (1/2, LbmOptions::tau]. The absorption per step is then
// mu_a dt = (tau - 1/2) (sigma_tr dx)^2 / 3.
//
// Stability and positivity of one collision (f* = keep f + equilibrium rho / 6 per cell):
// - tau <= 1/2: the non-equilibrium part is multiplied by 1 - 1/tau <= -1 every step: it alternates in
//   sign without decaying (tau = 1/2, and D = 0) or grows (divergence). Waxwork rejects such a tau
//   (InvalidArgumentError).
// - 1/2 < tau < 1: stable, but 1 - 1/tau < 0 (over-relaxation): populations and phi go negative while
//   iterating; near 1/2 the alternation is barely damped and, as D -> 0 per step, convergence needs
//   ~1/(tau - 1/2) times more steps. Waxwork warns.
// - tau large: stable and positive, but the lattice then resolves a mean free path of ~tau cells, and
//   the O(dx^2) error grows with tau; Waxwork warns above kLbmLargeTau.
// - Absorption per step a: with the paper's explicit absorption (Eq. 5: keep = 1 - 1/tau - a)
//   populations go negative when a > 1 - 1/tau and the run diverges when a > 2 - 1/tau. Waxwork
//   instead removes the absorbed fraction implicitly, keep = (1 - 1/tau) / (1 + b),
//   equilibrium = 1 / (tau (1 + b)) (the collision's backward-Euler form), which is positive for every
//   b >= 0 and tau >= 1; b = a at tau = 1 and is matched to the decay rate sigma_tr otherwise
//   (lbm_collision). The explicit
//   form stays available (LbmOptions::explicit_absorption) to reproduce the paper: unstable settings are
//   rejected, non-positive ones warned.
#pragma once

#include <array>

namespace waxwork {

// tau above this draws a warning (measured accuracy loss on the ball, docs/method_lbm.md).
inline constexpr double kLbmLargeTau = 2.0;
// Materials whose tau falls below this (strong contrast of kappa in one scene) draw a warning.
inline constexpr double kLbmSmallTau = 0.55;

// dt (in the pseudo-time of d phi / dt = div(kappa grad phi) - mu_a phi, mm) that gives relaxation
// time tau to diffusion coefficient kappa_mm on cells of dx_mm.
double lbm_time_step(double kappa_mm, double dx_mm, double tau);

// Relaxation time and absorption per step of one material channel.
struct LbmRelaxation {
    double tau = 1;
    double absorption = 0;  // mu_a dt
};
LbmRelaxation lbm_relaxation(double kappa_mm, double mua_per_mm, double dt, double dx_mm);

// The collision coefficients (keep, equilibrium) for a relaxation, implicit or explicit absorption.
std::array<double, 2> lbm_collision(const LbmRelaxation& relaxation, bool explicit_absorption);

// The reflection r of a boundary link so that the lattice's steady state satisfies the Robin condition
// phi + (2 A kappa / cos_n) d phi / d s = 4 q / (1 - F_dr) at the crossing point, a distance
// fraction * dx from the cell centre along the link (s along the link, cos_n the cosine between the
// link and the outward normal, which makes the link carry its share cos_n of the normal flux). With
// L = 2 A kappa / (cos_n dx) + fraction (in cells), matching f_in = r f*_out + s to the linear steady
// state f_i = rho / 6 - tau c_i . grad rho / 6 gives r = (L - tau) / (L + tau - 1), exact for linear
// phi. r < 0 (L < tau: cells coarser than the Robin length) is returned as is; the caller clamps.
double lbm_boundary_reflection(double robin_length_cells, double fraction, double tau);
// The reflection is exact for linear phi; where phi curves (absorption, a curved boundary) the
// populations carry the gradient half a cell out, not at the crossing, an O(dx) error in the boundary
// flux when fraction != 1/2. The gain of the second difference along the link that moves it there:
// K d phi/ds at the crossing = K (d phi/ds at half a cell + (fraction - 1/2) d2 phi/ds2), so the source
// gains -(1 - r) K (fraction - 1/2) d2 rho / 6 (K = robin_length_cells), with (1 - r) K capped at 1
// (it is below 2 tau - 1 anyway for tau <= 1) so the lagged correction stays stable at large tau.
double lbm_boundary_curvature_gain(double reflection, double robin_length_cells, double fraction);
// The matching source per link: s = (1 - r) (4 q / (1 - F_dr)) / 6.
double lbm_boundary_source(double reflection, double q, double fresnel_dr);

}  // namespace waxwork
