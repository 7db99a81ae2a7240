#include "solver/methods/dipole_profile.h"

#include "solver/material.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace waxwork {
namespace {

// (exp(-sigma a) - exp(-sigma b)) / sigma for b >= a, continuous at sigma = 0 (where it is b - a).
double exp_difference_over_sigma(double sigma, double a, double b) {
    if (sigma <= 0) return b - a;
    return -std::exp(-sigma * a) * std::expm1(-sigma * (b - a)) / sigma;
}

}  // namespace

DipoleProfile::DipoleProfile(double mua, double musp, double eta) {
    const double sigma_t = mua + musp;
    alpha_ = musp / sigma_t;
    d_ = waxwork::diffusion_coefficient(mua, musp);
    sigma_ = effective_transport_coefficient(mua, musp);
    z_r_ = 1.0 / sigma_t;
    z_v_ = z_r_ + 4.0 * boundary_reflection_parameter(eta) * d_;
}

double DipoleProfile::reflectance(double r) const {
    const double dr = std::hypot(r, z_r_), dv = std::hypot(r, z_v_);
    return alpha_ / (4 * std::numbers::pi) *
           (z_r_ * (1 + sigma_ * dr) * std::exp(-sigma_ * dr) / (dr * dr * dr) +
            z_v_ * (1 + sigma_ * dv) * std::exp(-sigma_ * dv) / (dv * dv * dv));
}

double DipoleProfile::reflectance_tail(double r) const {
    const double dr = std::hypot(r, z_r_), dv = std::hypot(r, z_v_);
    return 0.5 * alpha_ * (z_r_ * std::exp(-sigma_ * dr) / dr + z_v_ * std::exp(-sigma_ * dv) / dv);
}

double DipoleProfile::disk_mean_reflectance(double rho) const {
    if (rho <= 0) return reflectance(0);
    return (reflectance_tail(0) - reflectance_tail(rho)) / (std::numbers::pi * rho * rho);
}

double DipoleProfile::fluence(double d_real, double d_virtual) const {
    return alpha_ / (4 * std::numbers::pi * d_) *
           (std::exp(-sigma_ * d_real) / d_real - std::exp(-sigma_ * d_virtual) / d_virtual);
}

double DipoleProfile::relative_fluence_tail(double r) const {
    // The surface fluence integrates to 2 pi alpha' / (4 pi D) (exp(-sigma d_r) - exp(-sigma d_v)) / sigma.
    return exp_difference_over_sigma(sigma_, std::hypot(r, z_r_), std::hypot(r, z_v_)) /
           exp_difference_over_sigma(sigma_, z_r_, z_v_);
}

double DipoleProfile::cutoff_radius(double tolerance, double cap) const {
    const double total = total_reflectance();
    const auto outside = [&](double r) {
        return reflectance_tail(r) <= tolerance * total && relative_fluence_tail(r) <= tolerance;
    };
    // Both tails fall monotonically: bracket, then bisect.
    double lo = 0, hi = z_v_;
    while (!outside(hi)) {
        if (hi >= cap) return cap;
        lo = hi;
        hi = std::min(2 * hi, cap);
    }
    for (int k = 0; k < 60 && hi - lo > 1e-9 * hi; ++k) {
        const double mid = 0.5 * (lo + hi);
        (outside(mid) ? hi : lo) = mid;
    }
    return hi;
}

}  // namespace waxwork
