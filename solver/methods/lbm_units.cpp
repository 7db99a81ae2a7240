#include "solver/methods/lbm_units.h"

#include <algorithm>

namespace waxwork {

// c_s^2 of the D3Q6 lattice: sum_i w_i c_ix^2 with w_i = 1/6 and two of the six c_i along x.
constexpr double kSoundSpeedSquared = 1.0 / 3.0;

double lbm_time_step(double kappa_mm, double dx_mm, double tau) {
    return (tau - 0.5) * kSoundSpeedSquared * dx_mm * dx_mm / kappa_mm;
}

LbmRelaxation lbm_relaxation(double kappa_mm, double mua_per_mm, double dt, double dx_mm) {
    return {0.5 + kappa_mm * dt / (kSoundSpeedSquared * dx_mm * dx_mm), mua_per_mm * dt};
}

std::array<double, 2> lbm_collision(const LbmRelaxation& relaxation, bool explicit_absorption) {
    const double omega = 1.0 / relaxation.tau, a = relaxation.absorption;
    // Eq. 5 with sigma_s -> omega, sigma_a -> a: f*_i = (1 - omega - a) f_i + omega rho / 6.
    if (explicit_absorption) return {1.0 - omega - a, omega};
    // f*_i = (f_i - omega (f_i - rho / 6)) / (1 + b): the absorbed fraction taken from the state after the
    // step (backward Euler in the absorption term), which keeps f* >= 0 for every b when tau >= 1.
    // Dividing by 1 + b also slows the relaxation of the fluxes, which changes the lattice's diffusion
    // by O(b); b is chosen so that the steady state's decay rate (the lattice dispersion relation
    // cosh(lambda) = ..., expanded to lambda^2) equals sigma_tr dx:
    //     b (b + omega)^2 / ((1 + b) (2 + b - omega)) = a omega^2 / (2 - omega),
    // the left side increasing in b. At tau = 1, b = a.
    const double target = a * omega * omega / (2.0 - omega);
    auto lhs = [&](double b) { return b * (b + omega) * (b + omega) / ((1.0 + b) * (2.0 + b - omega)); };
    double lo = 0, hi = std::max(a, 1.0);
    while (lhs(hi) < target) hi *= 2;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
        const double mid = 0.5 * (lo + hi);
        (lhs(mid) < target ? lo : hi) = mid;
    }
    const double b = 0.5 * (lo + hi);
    return {(1.0 - omega) / (1.0 + b), omega / (1.0 + b)};
}

double lbm_boundary_reflection(double robin_length_cells, double fraction, double tau) {
    const double l = robin_length_cells + fraction;
    return (l - tau) / (l + tau - 1.0);
}

double lbm_boundary_curvature_gain(double reflection, double robin_length_cells, double fraction) {
    // (1 - r) K is below 2 tau - 1 <= 1 for tau <= 1; at larger tau the full gain makes the lagged
    // correction amplify checkerboard modes (the iteration diverged on the ball at tau = 3).
    return -std::min((1.0 - reflection) * robin_length_cells, 1.0) * (fraction - 0.5) / 6.0;
}

double lbm_boundary_source(double reflection, double q, double fresnel_dr) {
    return (1.0 - reflection) * 4.0 * q / (1.0 - fresnel_dr) / 6.0;
}

}  // namespace waxwork
