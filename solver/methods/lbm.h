// The `lbm` method: lattice-Boltzmann diffusion on a voxelisation of the volume (Bernabei et al., seed
// 004, Sec. III-C, Eqs. 4-5: Lattice-Boltzmann Lighting on the 6 principal directions), iterated to its
// steady state, which solves div(kappa grad phi) - mu_a phi = 0 with the Robin boundary of TransCut.
//
// The lattice units, tau, and the stable and positive ranges are in lbm_units.h.
#pragma once

#include "solver/methods/lbm_lattice.h"
#include "solver/methods/lbm_units.h"
#include "solver/methods/method_problem.h"

#include <array>
#include <string>
#include <vector>

namespace waxwork {

struct VoxelGrid;

struct LbmOptions {
    // The resolution knob: the voxel size in mm. Unknowns grow as cell_size_mm^-3 and steps to the
    // steady state as cell_size_mm^-2.
    double cell_size_mm = 1.0;
    // Relaxation time of the most diffusive material, in (1/2, inf). 1 relaxes fully to equilibrium
    // every step (the positivity-safe choice); larger converges in fewer steps but less accurately.
    double tau = 1.0;
    // Steady-state stopping rule on the change of phi (lbm_lattice.h).
    double tolerance = 1e-6;
    int max_iterations = 500000;
    // The paper's explicit absorption (Eq. 5) instead of the implicit one (lbm_units.h).
    bool explicit_absorption = false;
    // Correct each boundary link's source by the lagged tangential gradient so that oblique links
    // impose the Robin condition on the normal derivative (lbm_units.h); off: each link imposes it on
    // the derivative along itself, first order where phi varies along the boundary.
    bool tangential_correction = true;
};

// Solves `problem` on a voxelisation with cells of options.cell_size_mm: phi at the volume's vertices.
// Throws InvalidArgumentError ("lbm: ...") for bad options (tau <= 1/2, non-positive cell size or
// tolerance, too many cells, unstable explicit absorption), CancelledError when cancelled, and
// AlgorithmError if the iteration diverges or does not converge within max_iterations.
MethodSolution solve_lbm(const MethodProblem& problem, const LbmOptions& options);

// The lattice of solve_lbm on a given voxel grid, with what it warns about (exposed for tests and
// studies that need the lattice itself).
struct LbmSetup {
    LbmLattice lattice;
    double time_step = 0;
    double min_tau = 0, max_tau = 0, max_absorption = 0;  // over cells and channels
    size_t clamped_links = 0;                              // links whose reflection was clamped to 0
    std::vector<std::string> warnings;
};
LbmSetup build_lbm_setup(const VoxelGrid& grid, const MethodProblem& problem, const LbmOptions& options);

// Throws InvalidArgumentError for options solve_lbm cannot run.
void validate_lbm_options(const LbmOptions& options);

}  // namespace waxwork
