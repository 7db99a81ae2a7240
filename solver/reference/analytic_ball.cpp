#include "solver/reference/analytic_ball.h"

#include "base/error.h"
#include "solver/diffusion_matrix.h"
#include "solver/material.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace waxwork {

double spherical_bessel_i(int l, double x) {
    if (x < 1e-8) {  // i_l(x) ~ x^l / (2l+1)!! near 0, where the Bessel formula divides by x
        double double_factorial = 1;
        for (int k = 1; k <= 2 * l + 1; k += 2) double_factorial *= k;
        return std::pow(x, l) / double_factorial;
    }
    return std::sqrt(std::numbers::pi / (2 * x)) * std::cyl_bessel_i(l + 0.5, x);
}

double spherical_bessel_i_derivative(int l, double x) {
    if (l == 0) return spherical_bessel_i(1, x);
    if (x < 1e-8) return l == 1 ? 1.0 / 3.0 : 0.0;
    return spherical_bessel_i(l - 1, x) - (l + 1) / x * spherical_bessel_i(l, x);
}

std::vector<double> legendre_polynomials(int lmax, double mu) {
    std::vector<double> p(static_cast<size_t>(lmax) + 1);
    p[0] = 1;
    if (lmax > 0) p[1] = mu;
    for (int l = 2; l <= lmax; ++l) p[l] = ((2 * l - 1) * mu * p[l - 1] - (l - 1) * p[l - 2]) / l;
    return p;
}

AnalyticBall::AnalyticBall(double radius, double mua, double musp, double eta, std::vector<double> q_l)
    : radius_(radius) {
    if (!(radius > 0) || !std::isfinite(radius)) throw InvalidArgumentError("analytic ball: radius must be positive");
    if (q_l.empty()) throw InvalidArgumentError("analytic ball: no light coefficients");
    TetMaterial material{{mua, mua, mua}, {musp, musp, musp}, eta};
    validate_material(material);
    const double kappa = diffusion_coefficient(mua, musp);
    sigma_ = std::sqrt(mua / kappa);
    const double fdr = diffuse_fresnel_reflectance(eta);
    const double big_a = boundary_reflection_parameter(eta);
    for (size_t l = 0; l < q_l.size(); ++l) {
        const int li = static_cast<int>(l);
        const double x = sigma_ * radius;
        a_.push_back(4.0 / (1.0 - fdr) * q_l[l] /
                     (spherical_bessel_i(li, x) + 2 * big_a * kappa * sigma_ * spherical_bessel_i_derivative(li, x)));
    }
}

double AnalyticBall::operator()(const Eigen::Vector3d& p) const {
    const double r = p.norm();
    const double mu = r > 0 ? p.z() / r : 1.0;
    const std::vector<double> pl = legendre_polynomials(static_cast<int>(a_.size()) - 1, mu);
    double phi = 0;
    for (size_t l = 0; l < a_.size(); ++l) phi += a_[l] * spherical_bessel_i(static_cast<int>(l), sigma_ * r) * pl[l];
    return phi;
}

double directional_ball_light(const Eigen::Vector3d& boundary_point, double eta) {
    const double mu = boundary_point.z() / boundary_point.norm();
    return std::max(mu, 0.0) * fresnel_transmittance(mu, eta);
}

std::vector<double> directional_ball_light_coefficients(int lmax, double eta) {
    const int n = 4000;
    std::vector<double> q(static_cast<size_t>(lmax) + 1, 0.0);
    for (int k = 0; k <= n; ++k) {
        const double mu = static_cast<double>(k) / n;
        const double w = (k == 0 || k == n ? 1.0 : (k % 2 ? 4.0 : 2.0)) / (3.0 * n);
        const std::vector<double> p = legendre_polynomials(lmax, mu);
        const double value = mu * fresnel_transmittance(mu, eta);
        for (int l = 0; l <= lmax; ++l) q[l] += (2 * l + 1) / 2.0 * w * value * p[l];
    }
    return q;
}

std::vector<std::array<double, 3>> ball_light(const TetMesh& mesh, const TetConnectivity& connectivity, BallLight light,
                                              double eta) {
    std::vector<std::array<double, 3>> q(mesh.vertex_count(), {0, 0, 0});
    for (int32_t v : connectivity.boundary_vertices) {
        const double value = light == BallLight::Uniform ? 1.0 : directional_ball_light(mesh.positions[v], eta);
        q[v] = {value, value, value};
    }
    return q;
}

double ball_relative_error(const TetMesh& mesh, const TetConnectivity& connectivity, const TetMaterial& material,
                           double radius_mm, BallLight light, double mm_per_unit,
                           const std::vector<std::array<double, 3>>& phi) {
    constexpr int kLegendreTerms = 60;
    const AnalyticBall exact(radius_mm, material.mua[0], material.musp[0], material.eta,
                             light == BallLight::Uniform ? std::vector<double>{1.0}
                                                         : directional_ball_light_coefficients(kLegendreTerms, material.eta));
    const std::vector<TetMaterial> materials(mesh.tet_count(), material);
    AssemblyOptions assembly;
    assembly.mm_per_unit = mm_per_unit;
    const std::vector<double> volumes =
        lumped_vertex_volumes(assemble_diffusion_matrix(mesh, connectivity, materials, assembly), connectivity);
    double error = 0, norm = 0;
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        const double reference = exact(mesh.positions[v] * mm_per_unit);
        const double difference = phi[v][0] - reference;
        error += volumes[v] * difference * difference;
        norm += volumes[v] * reference * reference;
    }
    return std::sqrt(error / norm);
}

BallComparison compare_with_analytic_ball(const TetMesh& mesh, const TetConnectivity& connectivity,
                                          const TetMaterial& material, double radius_mm, BallLight light,
                                          const DiffusionOptions& options) {
    const std::vector<std::array<double, 3>> q = ball_light(mesh, connectivity, light, material.eta);
    const std::vector<TetMaterial> materials(mesh.tet_count(), material);
    BallComparison comparison;
    comparison.solution = solve_diffusion(mesh, connectivity, materials, q, options);
    comparison.relative_error =
        ball_relative_error(mesh, connectivity, material, radius_mm, light, options.mm_per_unit, comparison.solution.phi);
    return comparison;
}

}  // namespace waxwork
