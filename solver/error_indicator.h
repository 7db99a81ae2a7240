// Where the discrete fluence is least accurate: a per-tet a posteriori error indicator of the diffusion
// solution, to choose which tets to refine (tetops/refine.h) within a budget.
//
// Kelly, Gago, Zienkiewicz and Babuska 1983 ("A posteriori error analysis and adaptive processes in the
// finite element method: Part I", IJNME 19), the estimator of deal.II's KellyErrorEstimator: phi is
// linear per tet, so its flux kappa grad(phi) is constant per tet and jumps across faces, where the
// exact flux is continuous. The jump's normal component J_F = (kappa_T grad(phi_T) - kappa_U grad(phi_U))
// . n_F measures the local error, and
//     eta_T^2 = sum over the interior faces F of T of (h_F / 24) |F| J_F^2
// with h_F the face's longest edge and |F| its area (the integral of the constant J_F^2 over F). Each
// interior face counts for both its tets. Boundary faces are left out: the Robin condition's residual
// there would need the incident light q, and the interior faces next to the boundary already see the
// steep fluence under a light.
//
// Per rgb channel the jumps are divided by that channel's largest |phi|, so a dim channel counts as much
// as a bright one (the image error is relative), and eta_T is the root of the sum over the channels.
#pragma once

#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <vector>

namespace waxwork {

// eta_T per tet (>= 0; 0 for a tet with no interior face or when phi is zero everywhere). phi: per
// vertex, per channel (solver/diffusion_solve.h); materials: one per tet; lengths are converted to
// millimetres with mm_per_unit, as the coefficients are per mm. Throws InvalidArgumentError for sizes
// that do not match the mesh, a non-finite phi (naming the vertex) or mm_per_unit not positive.
std::vector<double> gradient_jump_indicator(const TetMesh& mesh, const TetConnectivity& connectivity,
                                            const std::vector<std::array<double, 3>>& phi,
                                            const std::vector<TetMaterial>& materials, double mm_per_unit = 1.0);

}  // namespace waxwork
