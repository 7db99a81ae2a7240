// The diffusion system solved by several processes together with PETSc (the distributed render): each
// process holds the rows of its vertex range (solver/owned_rows.h) in a row-distributed AIJ matrix,
// preallocated exactly, and the three rgb channels are solved one after the other with CG and one of
// the PETSc peers' algebraic multigrids (solver/petsc_peers.h, with the same settings), then gathered
// to rank 0.
//
// Stopping rule: as in the serial solve (conjugate_gradient.h), CG stops when an estimated bound on the
// relative error of phi reaches the tolerance, with lambda_min the smallest Ritz value from CG's own
// Lanczos coefficients, and no Ritz value trusted before the third iteration. The serial Jacobi CG
// bounds the error in the diagonal's norm; with a multigrid B the natural norm is the energy norm:
// ||e||_M^2 = r.M^-1 r <= r.Br / lambda_min(BM), relative to ||x||_M^2 = x.b (exact for CG iterates from
// a zero start, whose residual is orthogonal to the Krylov space x lies in). All processes compute the
// same reductions, so they stop together.
//
// Exists only in builds with PETSc (WAXWORK_HAVE_PETSC).
#pragma once

#ifdef WAXWORK_HAVE_PETSC

#include "solver/owned_rows.h"
#include "solver/petsc_peers.h"

#include <array>
#include <string>
#include <vector>

namespace waxwork {

struct DistributedSolveOptions {
    PetscPeer preconditioner = PetscPeer::CgBoomerAmg;
    double relative_tolerance = 1e-2;  // on the estimated relative error above
    int max_iterations = 1000;         // per channel
};

struct DistributedSolveReport {
    std::array<int, 3> iterations{};
    std::array<double, 3> estimated_relative_error{};
    double conversion_ms = 0;      // the owned rows into the AIJ matrix, three channels
    double preconditioner_ms = 0;  // the multigrid setups, three channels
    double solve_ms = 0;           // the CG solves, three channels
    double gather_ms = 0;          // phi to rank 0
};

// Collective over PETSC_COMM_WORLD: every process passes its rows, the ranges in rank order covering
// [0, total_rows). Returns phi per vertex on rank 0 and nothing on the others. Throws
// InvalidArgumentError for options out of range or rows that do not match total_rows, and AlgorithmError
// when PETSc fails or CG does not reach the tolerance (on every process alike).
std::vector<std::array<double, 3>> solve_distributed(const OwnedRows& rows, size_t total_rows,
                                                     const DistributedSolveOptions& options,
                                                     DistributedSolveReport& report);

}  // namespace waxwork

#endif  // WAXWORK_HAVE_PETSC
