// PETSc's algebraic multigrids as peers of Waxwork's own solvers: conjugate gradients preconditioned by
// PETSc's smoothed-aggregation GAMG, or by hypre's BoomerAMG (classical AMG) through PCHYPRE, on the
// same DiffusionMatrix, converted channel by channel to a sequential AIJ (compressed row) matrix.
//
// Settings (petsc_peer_settings lists them as PETSc options, for the record):
//   CG + GAMG: smoothed aggregation (one prolongator smoothing step), graph threshold 0.01 (couplings
//     weaker than that are dropped before aggregating, which slows coarsening where the default keeps
//     every entry; not tuned on these systems), Chebyshev/Jacobi smoothing (PETSc's default), a full
//     setup on every rebuild (no reuse of the interpolation).
//   CG + BoomerAMG: HMIS coarsening with one level of aggressive coarsening, extended+i interpolation,
//     strong threshold 0.25, l1 Gauss-Seidel smoothing, forward down and backward up so the V-cycle is
//     symmetric and CG stays valid, Gaussian elimination on the coarsest level. HMIS with a distance-two
//     interpolation, plus aggressive coarsening for lower complexity, is what hypre's manual recommends
//     for 3D diffusion; the threshold 0.25 (hypre's default) is the one the earlier measurement on the spot
//     system found best among the settings it tried (the manual suggests trying 0.5 in 3D).
// Both use CG with the unpreconditioned residual norm, so a relative tolerance means
// ||b - A x||_2 <= tol ||b||_2, from a zero start.
//
// Everything here but kPetscBuilt and petsc_unavailable_reason() exists only in builds with PETSc
// (CMake's WAXWORK_WITH_PETSC, which defines WAXWORK_HAVE_PETSC).
#pragma once

#include <string>

#ifdef WAXWORK_HAVE_PETSC
#include <memory>
#include <span>
#include <utility>
#include <vector>
#endif

namespace waxwork {

#ifdef WAXWORK_HAVE_PETSC
inline constexpr bool kPetscBuilt = true;
#else
inline constexpr bool kPetscBuilt = false;
#endif

// Why the PETSc peers cannot run in this build, or "" when they can.
inline std::string petsc_unavailable_reason() {
    if (kPetscBuilt) return "";
    return "this build has no PETSc (install petsc-dev and configure with -DWAXWORK_WITH_PETSC=AUTO or ON)";
}

#ifdef WAXWORK_HAVE_PETSC

struct DiffusionMatrix;

enum class PetscPeer {
    CgGamg,       // CG + PETSc GAMG
    CgBoomerAmg,  // CG + hypre BoomerAMG
};

// The peer's name in the solver comparison: "petsc_cg_gamg", "petsc_cg_boomeramg".
const char* petsc_peer_name(PetscPeer peer);

// The PETSc options the peer sets (without its prefix), in the order set, e.g.
// {"pc_hypre_boomeramg_coarsen_type", "HMIS"}; the KSP and PC types come first.
std::vector<std::pair<std::string, std::string>> petsc_peer_settings(PetscPeer peer);

// "PETSc 3.18.5": the version this program was built with.
std::string petsc_version();

struct PetscSolveOptions {
    double relative_tolerance = 1e-8;  // on ||b - A x||_2 / ||b||_2; 0: run max_iterations
    int max_iterations = 1000;         // CG iterations (one preconditioner application each)
};

struct PetscSolveReport {
    int iterations = 0;
    double residual_norm = 0;   // ||b - A x||_2 as CG tracked it
    bool converged = false;     // the tolerance was reached (not the iteration cap)
    std::string reason;         // PETSc's converged reason, e.g. "CONVERGED_RTOL" or "DIVERGED_ITS"
};

// Milliseconds of the last build or rebuild, all three channels.
struct PetscSetupTimes {
    double conversion_ms = 0;      // DiffusionMatrix values (and, on the first build, pattern) into AIJ
    double preconditioner_ms = 0;  // KSPSetUp: the AMG hierarchy (hypre: also its own matrix copy)
};

// One peer on the three channels of one matrix: three AIJ matrices and three CG solvers, each with its
// preconditioner set up. Not copyable; movable.
class PetscPeerSolver {
public:
    // Starts PETSc if needed (petsc_runtime.h; not timed), converts the three channels and sets up the
    // preconditioners. Throws InvalidArgumentError for an empty, malformed or non-finite matrix and
    // AlgorithmError when PETSc fails.
    PetscPeerSolver(const DiffusionMatrix& matrix, PetscPeer peer);
    ~PetscPeerSolver();
    PetscPeerSolver(PetscPeerSolver&&) noexcept;
    PetscPeerSolver& operator=(PetscPeerSolver&&) noexcept;

    // Copies `matrix`'s values in again (its pattern must be the one built on) and sets the
    // preconditioners up from scratch: the rebuild after an edit that changed coefficients only.
    // Throws InvalidArgumentError for a different pattern or non-finite values.
    void rebuild(const DiffusionMatrix& matrix);

    // The last build's or rebuild's times.
    const PetscSetupTimes& setup_times() const;

    size_t size() const;
    PetscPeer peer() const;

    // Solves channel `channel` (0..2) for b from x = 0, writing x. Throws InvalidArgumentError for a
    // bad channel, sizes that differ from the matrix, a non-finite b or options out of range, and
    // AlgorithmError when CG breaks down (reaching max_iterations is not a failure: converged is false).
    PetscSolveReport solve(int channel, std::span<const double> b, std::span<double> x,
                           const PetscSolveOptions& options) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

#endif  // WAXWORK_HAVE_PETSC

}  // namespace waxwork
