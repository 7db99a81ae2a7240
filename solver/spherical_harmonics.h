// Real spherical harmonics about the model's up axis (+y), for the environment light's transfer
// (precomputed radiance transfer, Sloan, Kautz and Snyder 2002): a radiance field L(w) and a
// per-vertex transfer T(w) projected onto the same orthonormal basis give the integral of their
// product as the dot product of their coefficient vectors (Eq. 5 there), so relighting costs one
// dot product per vertex.
//
// Hand-written: no Debian-packaged C++ library offers real SH evaluation and rotation (Eigen has
// none; Boost.Math has complex, normalised Y_l^m one degree and order at a time, without the
// recurrences over every (l, m) that make evaluation cheap).
//
// The basis is the real orthonormal one (Y_l^0, sqrt 2 K cos(m phi) P_l^m, sqrt 2 K sin(|m| phi)
// P_l^|m|) with the polar axis along +y and phi measured in the z-x plane, so that rotating the
// environment about the up axis only mixes each (l, m) with (l, -m). Coefficient (l, m) is stored
// at index l (l + 1) + m. No Condon-Shortley phase: the basis only has to agree with itself.
#pragma once

#include <Eigen/Core>

#include <array>
#include <span>
#include <vector>

namespace waxwork {

// The number of coefficients of bands 0..order: (order + 1)^2.
constexpr int sh_coefficient_count(int order) { return (order + 1) * (order + 1); }

// The highest band evaluated: beyond it the recurrences lose digits in double and the transfer's
// sampling cannot resolve the bands anyway.
inline constexpr int kMaxShOrder = 16;

// Evaluates every basis function of bands 0..order at the unit direction `w`, into
// out[0 .. sh_coefficient_count(order)). Throws InvalidArgumentError for an order outside
// [0, kMaxShOrder] or an `out` too short.
void evaluate_sh(int order, const Eigen::Vector3d& w, std::span<double> out);

// Coefficients of the function f(R^-1 w), where R rotates by `radians` about +y (right-handed):
// the rotated field, for per-channel coefficient vectors of bands 0..order.
std::vector<std::array<double, 3>> rotate_sh_about_up(std::span<const std::array<double, 3>> coefficients,
                                                      int order, double radians);

// The order of a coefficient vector of `count` entries; throws InvalidArgumentError when count is
// not a square.
int sh_order_of(size_t count);

}  // namespace waxwork
