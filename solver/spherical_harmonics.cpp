#include "solver/spherical_harmonics.h"

#include "base/error.h"

#include <cmath>
#include <numbers>
#include <string>

namespace waxwork {

namespace {

// K_l^m = sqrt((2l + 1) / (4 pi) (l - m)! / (l + m)!), times sqrt 2 for m > 0, for every band up to
// kMaxShOrder; index l (l + 1) + m.
const std::array<double, sh_coefficient_count(kMaxShOrder)>& normalisation() {
    static const auto table = [] {
        std::array<double, sh_coefficient_count(kMaxShOrder)> k{};
        for (int l = 0; l <= kMaxShOrder; ++l) {
            for (int m = 0; m <= l; ++m) {
                double ratio = 1.0;  // (l - m)! / (l + m)!
                for (int i = l - m + 1; i <= l + m; ++i) ratio /= i;
                const double value = std::sqrt((2 * l + 1) / (4 * std::numbers::pi) * ratio);
                k[l * (l + 1) + m] = m == 0 ? value : std::sqrt(2.0) * value;
            }
        }
        return k;
    }();
    return table;
}

}  // namespace

void evaluate_sh(int order, const Eigen::Vector3d& w, std::span<double> out) {
    if (order < 0 || order > kMaxShOrder)
        throw InvalidArgumentError("spherical harmonics order " + std::to_string(order) + " is outside [0, " +
                                   std::to_string(kMaxShOrder) + "]");
    if (out.size() < static_cast<size_t>(sh_coefficient_count(order)))
        throw InvalidArgumentError("evaluate_sh: " + std::to_string(out.size()) + " outputs for order " +
                                   std::to_string(order));
    const auto& k = normalisation();
    const double z = w.y();  // cos(theta) about the up axis
    // C_m + i S_m = (w.z + i w.x)^m = sin^m(theta) (cos m phi + i sin m phi): the azimuthal factors
    // with the sin^m of the associated Legendre function folded in, so no trigonometry is needed.
    double c = 1.0, s = 0.0;
    double q_mm = 1.0;  // Q_m^m = (2m - 1)!!, where P_l^m = sin^m(theta) Q_l^m
    for (int m = 0; m <= order; ++m) {
        if (m > 0) {
            const double c_next = c * w.z() - s * w.x();
            s = c * w.x() + s * w.z();
            c = c_next;
            q_mm *= 2 * m - 1;
        }
        double q_previous = 0.0, q = q_mm;
        for (int l = m; l <= order; ++l) {
            if (l == m + 1) {
                q_previous = q;
                q = z * (2 * m + 1) * q_mm;
            } else if (l > m + 1) {
                const double q_next = ((2 * l - 1) * z * q - (l + m - 1) * q_previous) / (l - m);
                q_previous = q;
                q = q_next;
            }
            const int centre = l * (l + 1);
            if (m == 0) {
                out[centre] = k[centre] * q;
            } else {
                out[centre + m] = k[centre + m] * q * c;
                out[centre - m] = k[centre + m] * q * s;
            }
        }
    }
}

std::vector<std::array<double, 3>> rotate_sh_about_up(std::span<const std::array<double, 3>> coefficients,
                                                      int order, double radians) {
    if (coefficients.size() != static_cast<size_t>(sh_coefficient_count(order)))
        throw InvalidArgumentError("rotate_sh_about_up: " + std::to_string(coefficients.size()) +
                                   " coefficients for order " + std::to_string(order));
    std::vector<std::array<double, 3>> rotated(coefficients.begin(), coefficients.end());
    for (int m = 1; m <= order; ++m) {
        // f(phi - alpha): a cos m phi + b sin m phi becomes
        // (a cos m alpha - b sin m alpha) cos m phi + (a sin m alpha + b cos m alpha) sin m phi.
        const double cos_m = std::cos(m * radians), sin_m = std::sin(m * radians);
        for (int l = m; l <= order; ++l) {
            const int centre = l * (l + 1);
            for (int c = 0; c < 3; ++c) {
                const double a = coefficients[centre + m][c], b = coefficients[centre - m][c];
                rotated[centre + m][c] = a * cos_m - b * sin_m;
                rotated[centre - m][c] = a * sin_m + b * cos_m;
            }
        }
    }
    return rotated;
}

int sh_order_of(size_t count) {
    const auto root = static_cast<size_t>(std::llround(std::sqrt(static_cast<double>(count))));
    if (root == 0 || root * root != count)
        throw InvalidArgumentError(std::to_string(count) + " spherical harmonics coefficients: not (order + 1)^2");
    return static_cast<int>(root) - 1;
}

}  // namespace waxwork
