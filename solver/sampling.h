// Deterministic sample patterns and the warps that place them, for the integrals over directions
// and emitters the lighting estimates with a fixed number of samples.
#pragma once

#include <Eigen/Core>

#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace waxwork {

// The van der Corput radical inverse in base 2 of j, in [0, 1): with (j + 1/2) / N the two
// coordinates of point j of an N-point Hammersley set.
inline double radical_inverse(uint32_t j) {
    j = (j << 16) | (j >> 16);
    j = ((j & 0x00ff00ffu) << 8) | ((j & 0xff00ff00u) >> 8);
    j = ((j & 0x0f0f0f0fu) << 4) | ((j & 0xf0f0f0f0u) >> 4);
    j = ((j & 0x33333333u) << 2) | ((j & 0xccccccccu) >> 2);
    j = ((j & 0x55555555u) << 1) | ((j & 0xaaaaaaaau) >> 1);
    return j * 0x1p-32;
}

inline double fraction(double x) { return x - std::floor(x); }

// Two numbers in [0, 1) that depend only on the bits of `p` (splitmix64 over its coordinates): a
// Cranley-Patterson shift of a sample pattern that is the same for a point wherever and however
// often it is evaluated, and unrelated between neighbouring points.
inline Eigen::Vector2d position_shift(const Eigen::Vector3d& p) {
    uint64_t h = 0x9e3779b97f4a7c15ull;
    const auto mix = [](uint64_t z) {
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    };
    for (int k = 0; k < 3; ++k) h = mix(h + std::bit_cast<uint64_t>(p[k] + 0.0) + 0x9e3779b97f4a7c15ull);  // -0 as 0
    return {(h >> 11) * 0x1p-53, (mix(h) >> 11) * 0x1p-53};
}

// An orthonormal frame (t, b, n) around unit n (Duff et al. 2017, "Building an Orthonormal Basis,
// Revisited", Listing 3): continuous everywhere but at one pole, and no normalisation needed.
inline void orthonormal_basis(const Eigen::Vector3d& n, Eigen::Vector3d& t, Eigen::Vector3d& b) {
    const double sign = std::copysign(1.0, n.z());
    const double a = -1.0 / (sign + n.z());
    const double c = n.x() * n.y() * a;
    t = {1.0 + sign * n.x() * n.x() * a, sign * c, -sign * n.x()};
    b = {c, sign + n.y() * n.y() * a, -n.y()};
}

// The concentric map of the unit square onto the unit disk (Shirley and Chiu 1997): area-preserving
// up to a constant and continuous, so a stratified pattern stays stratified on the disk.
inline Eigen::Vector2d concentric_disk(double u, double v) {
    const double x = 2 * u - 1, y = 2 * v - 1;
    if (x == 0 && y == 0) return {0, 0};
    constexpr double quarter = std::numbers::pi / 4;
    if (std::abs(x) > std::abs(y)) {
        const double phi = quarter * (y / x);
        return {x * std::cos(phi), x * std::sin(phi)};
    }
    const double phi = 2 * quarter - quarter * (x / y);
    return {y * std::cos(phi), y * std::sin(phi)};
}

}  // namespace waxwork
