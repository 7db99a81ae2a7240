// The exact fluence in a homogeneous ball under the diffusion equation with TransCut's Robin boundary
// (../shared/seeds README, "analytic reference"): the reference every solver path is measured against.
//
// In a ball of radius R with kappa = 1 / (3 (mu_a + mu_s')) and sigma = sqrt(mu_a / kappa), the
// solution of div(kappa grad phi) - mu_a phi = 0 with phi + 2 A kappa dphi/dr = 4 q / (1 - F_dr) at
// r = R and q(theta) = sum_l q_l P_l(cos theta) is
//     phi(r, theta) = sum_l a_l i_l(sigma r) P_l(cos theta),
//     a_l = (4 / (1 - F_dr)) q_l / (i_l(sigma R) + 2 A kappa sigma i_l'(sigma R)),
// with i_l the modified spherical Bessel functions of the first kind. For mu_a = 0 (sigma = 0) only
// the l = 0 term survives a uniform light and phi is the constant 4 q_0 / (1 - F_dr).
#pragma once

#include "solver/diffusion_solve.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace waxwork {

// Modified spherical Bessel function of the first kind i_l(x), x >= 0, and its derivative.
double spherical_bessel_i(int l, double x);
double spherical_bessel_i_derivative(int l, double x);

// P_0(mu) .. P_lmax(mu) by the three-term recurrence.
std::vector<double> legendre_polynomials(int lmax, double mu);

// The series above for one channel; the ball is centred at the origin, the light axis is +z.
class AnalyticBall {
public:
    // radius in mm, coefficients in 1/mm; q_l: Legendre coefficients of the incident light q.
    // Throws InvalidArgumentError for a non-positive radius, mu_s' or invalid eta, negative mu_a or
    // an empty q_l.
    AnalyticBall(double radius, double mua, double musp, double eta, std::vector<double> q_l);

    // phi at a point (mm) inside the ball.
    double operator()(const Eigen::Vector3d& p) const;

    double radius() const { return radius_; }

private:
    double radius_ = 0;
    double sigma_ = 0;
    std::vector<double> a_;
};

// q(mu) = max(mu, 0) F_t(mu, eta): a directional light travelling along -z seen at the boundary point
// with outward normal cosine mu to +z.
double directional_ball_light(const Eigen::Vector3d& boundary_point, double eta);

// Legendre coefficients of directional_ball_light up to lmax (composite Simpson on [0, 1], where the
// function is smooth).
std::vector<double> directional_ball_light_coefficients(int lmax, double eta);

enum class BallLight {
    Uniform,      // q = 1 everywhere on the boundary
    Directional,  // directional_ball_light (a light travelling along -z)
};

// q per volume vertex for the ball's light (on boundary vertices; zero inside).
std::vector<std::array<double, 3>> ball_light(const TetMesh& mesh, const TetConnectivity& connectivity, BallLight light,
                                              double eta);

// The relative L2 error of channel 0 of `phi` (per volume vertex) against the series, weighted by the
// lumped vertex volume: the measure every accuracy test and study reports.
double ball_relative_error(const TetMesh& mesh, const TetConnectivity& connectivity, const TetMaterial& material,
                           double radius_mm, BallLight light, double mm_per_unit,
                           const std::vector<std::array<double, 3>>& phi);

struct BallComparison {
    double relative_error = 0;  // channel 0, relative L2 weighted by lumped vertex volume
    DiffusionSolution solution;
};

// Solves the ball problem on `mesh` (a ball centred at the origin whose radius is radius_mm in mm,
// i.e. radius_mm / options.mm_per_unit model units) with one homogeneous material and compares
// channel 0 with the series (60 Legendre terms for the directional light). The reference every
// accuracy test and study uses. Throws what solve_diffusion throws.
BallComparison compare_with_analytic_ball(const TetMesh& mesh, const TetConnectivity& connectivity,
                                          const TetMaterial& material, double radius_mm, BallLight light,
                                          const DiffusionOptions& options);

}  // namespace waxwork
