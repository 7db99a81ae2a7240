// Finite volumes on Voronoi cells after Kang & Kim 2013 ("Real-time subsurface scattering for
// particle-based fluids using finite volume method", seed paper 000), on the volume's tet mesh.
//
// Cells and faces (Sec. 4.1). Each vertex owns its Voronoi cell clipped to the volume: the
// circumcentric dual of the tet mesh (voronoi_dual.h), with per cell the volume V_i, per mesh edge the
// neighbour-face area S_ij and per boundary vertex the surface-face area S_is. The paper samples
// cells of particles; on a tet mesh the dual is exact.
//
// Discretisation (Eqs. 7-15). Integrating div(kappa grad phi) - mu_a phi = 0 over cell i and applying
// the divergence theorem (Eq. 8), the flux through face ij is approximated by two-point differences
//     kappa_ij S_ij (phi_j - phi_i) / d_ij,   d_ij = |x_i - x_j|,
// the consistent form of Eq. 10 (the paper's S_ij (phi_j - phi_i) omits the distance, and Eq. 11
// puts kappa inside the difference; with one material per tet, kappa_ij S_ij is the sum over the
// tets around the edge of kappa_t times the face piece in t, which keeps fluxes conservative across
// material boundaries). The surface face carries the Robin condition (Eqs. 13-15):
//     S = (1 / (2A)) (-phi_i S_is + 4 / (1 - F_dr) q_i S_is),
// with A and F_dr of the tet that owns each boundary triangle. Per channel this is the symmetric system
//     (sum_j W_ij + mu_a V_i + S_is / (2A)) phi_i - sum_j W_ij phi_j = (4 / (1 - F_dr)) q_i S_is / (2A),
// W_ij = kappa_ij S_ij / d_ij the dual coefficient of edge ij (with mu_a V_i and S_is / (2A) summed over
// tets and boundary faces when materials differ).
//
// Solvers (Sec. 4.2, Eqs. 16-17). The paper iterates phi_{t+1} from phi_t on every cell at once,
// starting from zero: Jacobi relaxation (Eqs. 16-17 are Jacobi updates; their 1/S_ij weights and cube
// root of V_i are not dimensionally consistent and are replaced by the row of the system above).
// FvmSolver::Cg solves the same system with Jacobi-preconditioned CG (conjugate_gradient.h), for a fair
// comparison. Both stop on the same measure, the estimated relative error of phi in the norm weighted
// by the diagonal (see FvmOptions::relative_tolerance).
//
// Relation to TransCut (solver/diffusion_matrix.h). In 2D the circumcentric dual coefficient equals the
// cotangent weight. In 3D it does not, not even per well-centred tet: on the trirectangular tet the dual
// gives 1/4 and -1/24 where TransCut's (1/6) |kl| cot(theta_kl) gives 1/6 and 0 (voronoi_dual.h and
// tests/solver/fvm_method_test.cpp). Both reproduce the Laplacian of |x|^2 / 2 (per tet
// sum_e w_e |e|^2 = 3 V) and have zero row sums, and they coincide on structured meshes such as the six-tet cube grid (the 7-point
// stencil); on a TetGen ball they differ by about half the weights' size. So FVM differs from TransCut
// in its stiffness (Voronoi two-point fluxes instead of P1 gradients: positive on every interior edge
// of a Delaunay mesh, where TransCut's cotangent weights go negative at every obtuse dihedral angle),
// its absorption (the Voronoi cell volume instead of the barycentric quarter V_t / 4 per tet vertex),
// its boundary (the vertex's Voronoi share of each boundary triangle instead of a third), and its
// solver (relaxation instead of multigrid/CG).
//
// Failure case: a mesh that is not Delaunay. A Voronoi face of a Delaunay edge has positive area; where
// the mesh is not Delaunay (flipped pairs, slivers) the signed dual pieces of an edge can add up to a
// negative W_ij (and obtuse tets can make cell volumes negative). The matrix then is no M-matrix: the
// discrete maximum principle is lost (phi can go negative under positive light), Jacobi relaxation,
// which needs diagonal dominance, diverges, and the matrix can be indefinite (CG breaks down).
// NegativeDualCoefficients chooses what Waxwork does; every solve reports the count and fraction in
// MethodSolution::warnings.
//
// Resolution: the tet mesh itself (one unknown per vertex); the study sweeps ball meshes of several
// sizes. The options hold the solver, its stopping rule and the treatment of negative coefficients.
#pragma once

#include "solver/methods/method_problem.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace waxwork {

enum class FvmSolver {
    Relaxation,  // Jacobi relaxation, Eqs. 16-17 of Kang & Kim (the paper's solver)
    Cg,          // Jacobi-preconditioned conjugate gradients on the same system
};

enum class NegativeDualCoefficients {
    // The default: negative edge coefficients W_ij and negative cell volumes are set to zero, which
    // restores the M-matrix property (positive phi, convergent relaxation) at the cost of changing the
    // operator on those edges (a local consistency error, measured in docs/method_fvm.md).
    Clamp,
    // Negative W_ij are replaced by TransCut's cotangent weight of the edge (Eq. 10 of Li et al.),
    // itself clamped to zero where negative; negative cell volumes are clamped to zero.
    CotangentFallback,
    // Solve the signed system as is (to study the failure): relaxation can diverge (AlgorithmError) and
    // phi can go negative.
    Keep,
};

struct FvmOptions {
    FvmSolver solver = FvmSolver::Relaxation;
    NegativeDualCoefficients negative_coefficients = NegativeDualCoefficients::Clamp;
    // Stop when the estimated relative error of phi, ||phi - phi*||_D / ||phi||_D with D the diagonal,
    // falls below this, in [1e-15, 1). Relaxation estimates it from the contraction of its updates,
    // ||delta_t||_D rho / (1 - rho) with rho = ||delta_t||_D / ||delta_t-1||_D; CG from its Lanczos
    // bound (conjugate_gradient.h).
    double relative_tolerance = 1e-6;
    int max_iterations = 200000;  // per channel, >= 1
};

// What the dual looked like, before any clamping (coefficients of channel 0).
struct FvmDualStatistics {
    size_t edges = 0;
    size_t negative_edges = 0;           // W_ij < 0
    size_t boundary_edges = 0;           // edges of boundary triangles
    size_t negative_boundary_edges = 0;  // of negative_edges, those on the boundary
    size_t negative_cells = 0;           // cells whose circumcentric volume is negative
    double most_negative_ratio = 0;      // min over edges of W_ij / (sum of |W_ik| of row i), <= 0
    // Interior faces tested and failing the empty-circumsphere test (tetops/delaunay_check.h); computed
    // only when some coefficient is negative (0 / 0 otherwise).
    size_t interior_faces = 0;
    size_t non_delaunay_faces = 0;
};

// The assembled system on the mesh's edges: row i holds i and its one-ring, columns ascending.
struct FvmSystem {
    std::vector<int32_t> offsets{0};
    std::vector<int32_t> columns;
    std::vector<int32_t> diagonal;               // slot of (i, i)
    std::array<std::vector<double>, 3> values;   // per channel, aligned with columns
    std::vector<double> source;                  // b_i = source_i q_i (channel independent)
    std::vector<double> cell_volume;             // V_i, mm^3 (signed, before clamping)
    FvmDualStatistics statistics;
};

// Builds the dual and the system (in parallel) and applies `negative` to it. Throws
// InvalidArgumentError (message "fvm: ...") for mismatched sizes, bad materials or scale, or a tet of
// non-positive volume.
FvmSystem assemble_fvm_system(const MethodProblem& problem, NegativeDualCoefficients negative);

// Solves the problem with finite volumes on Voronoi cells. Throws InvalidArgumentError for bad options
// or input, AlgorithmError when relaxation diverges (a non-Delaunay mesh solved with Keep), and
// CancelledError between iterations.
MethodSolution solve_fvm(const MethodProblem& problem, const FvmOptions& options = {});

}  // namespace waxwork
