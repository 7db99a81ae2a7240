// Finite differences on a regular grid, after Wang et al., "Real-time Rendering of Heterogeneous
// Translucent Objects with Arbitrary Shapes" (QuadGraph, CGF 2010; ../shared/seeds/002).
//
// What the paper does (Sec. 4): it builds a graph from a tetrahedralization (one inner node per tet
// centroid, 4-connected through faces; tets with one boundary face get a surface node where the ray
// from the inner node meets the surface), writes the diffusion equation on it by finite differences
// with inverse-squared-distance Laplacian weights (Eq. 5), the Robin boundary as a one-sided difference
// between each surface node and its inner node (Eq. 6), and relaxes both with Jacobi (Eqs. 8-9),
// coarse-to-fine over independently meshed levels (Eq. 10).
//
// What is built here, and why it differs:
//  - The graph is a regular grid over the volume (voxel_grid.h) instead of the tets' dual graph. On
//    a grid the 7-point stencil is a consistent second-order Laplacian; the paper's 1/d^2 weights on
//    4 neighbours are not (4 equal links in the regular tetrahedral directions give 2/3 of the
//    Laplacian, and the factor varies over an irregular graph). The grid also decouples the
//    resolution from the mesh (one knob, the cell size) and is rebuilt from the current tets on every
//    solve, so cuts and fractures are followed, which the paper's precomputed graph cannot do
//    (Sec. 6.4, 7: "we cannot change the topology").
//  - Conservative form with the harmonic mean of kappa on links between cells of different
//    materials, instead of Eq. 5's kappa(n_j) phi(n_j) - kappa(n_i) phi(n_i) (which discretises
//    laplace(kappa phi), not div(kappa grad phi), and is not symmetric).
//  - The surface nodes of Eq. 6 sit where each boundary link crosses the surface (VoxelLink::fraction)
//    and are eliminated: solving Eq. 6 for phi_s gives a flux kappa (phi_s - phi_k) / d =
//    (g - phi_k) / (d / kappa + 2A), g = 4 q / (1 - F_dr), through the cell's face (a conductance in
//    series: the half-link d / kappa and the Robin 2A). Jacobi on the cells with this substituted is
//    Eqs. 8-9 with the surface node updated in the same sweep; the fixed point is the same.
//    Eq. 6's one-sided difference runs along the link, so it is read as (n . axis) dphi/dn with n the
//    crossed face's normal: the Robin resistance 2A becomes 2A / (n . axis). Without this (the
//    cubes' own boundary, FdBoundary::Cubes) the surface's exchange is counted over the staircase's
//    area and the error stays at about 4% on the ball at every cell size.
//    FdBoundary::Staircase puts every surface node on the cell face (d = h/2); FdBoundary::Fraction
//    (default) puts it at the crossing and gives the cell the absorbing volume it really has along
//    each axis (h/2 + d per boundary side instead of h), which makes the boundary cell a consistent
//    1D finite volume along its boundary links. Observed orders (docs/method_fd.md): second under
//    uniform light on the ball, first under directional light (each link drops the tangential part of
//    the gradient) and on a box whose faces keep one fraction (the links along a boundary cell's face
//    keep full h x h faces).
//  - The system is symmetric positive definite, so besides the paper's Jacobi relaxation the same
//    system is solved with Jacobi-preconditioned CG (conjugate_gradient.h) for a fair comparison. The
//    paper's multi-resolution start (Eq. 10) is not built.
//
// Failure cases (docs/method_fd.md measures them): a cut or crack narrower than a cell still separates
// cells (links are segment-tested against the boundary faces), so light does not leak across it. A part thinner than a cell has no
// cell of its own: its vertices cannot be sampled, keep phi = 0 and the solution carries a warning
// naming the cell size to go below; a volume with no cell at all is an InvalidArgumentError.
#pragma once

#include "solver/methods/method_problem.h"

namespace waxwork {

enum class FdSolver {
    Jacobi,  // the paper's relaxation (Eqs. 8-9)
    Cg,      // Jacobi-preconditioned conjugate gradients on the same system
};

enum class FdBoundary {
    Fraction,   // surface nodes where the links cross the boundary (the cells' true extent)
    Staircase,  // surface nodes on the cell faces, with the crossed face's normal
    // The boundary of the cubes themselves (surface nodes on the cell faces, every boundary face
    // taken as normal to its link), as a voxel method without the surface would do. For comparison
    // only: it counts the surface |n_x| + |n_y| + |n_z| times (1.5 times on a sphere), so its error
    // does not fall with the cell size (docs/method_fd.md).
    Cubes,
};

// The most cells a solve takes: 2^22, about 1 GB for the system, the CG vectors and the grid.
inline constexpr size_t kMaxFdCells = size_t{1} << 22;

struct FdOptions {
    // The resolution knob: the cell size in millimetres (problem.mm_per_unit converts the mesh).
    // Cells cover the volume's bounding box; at most kMaxVoxelGridVoxels voxels (voxel_grid.h).
    double cell_size_mm = 0.5;
    FdSolver solver = FdSolver::Cg;
    FdBoundary boundary = FdBoundary::Fraction;
    // Both solvers stop on an estimate of the relative error of the cell values in the norm of the
    // matrix diagonal: CG's Lanczos bound (conjugate_gradient.h), Jacobi's |x_k+1 - x_k| rho / (1 -
    // rho) with rho the observed contraction per sweep.
    double relative_tolerance = 1e-5;
    int max_iterations = 200000;  // per channel; a solve that reaches it carries a warning
};

// phi at the volume's vertices (voxel_grid.h sample_at_vertices), unknowns = inside cells. Throws
// InvalidArgumentError ("fd: ...") for options out of range, inputs of the wrong size, a volume in
// which no cell centre lies, or more than kMaxFdCells cells (naming a cell size that fits);
// CancelledError when problem.progress asks.
MethodSolution solve_fd(const MethodProblem& problem, const FdOptions& options);

}  // namespace waxwork
