// The problem the seeds' alternative methods solve, and the result each returns.
//
// Every method in solver/methods/ (finite differences after QuadGraph, finite volumes on Voronoi cells,
// lattice Boltzmann, the dipole surface method) approximates the same light as solve_diffusion
// (../shared/seeds README, "Shared physics"):
//   div(kappa grad phi) - mu_a phi = 0 inside, phi + 2 A kappa dphi/dn = 4 q / (1 - F_dr) on the boundary,
// with the same materials and the same incident light q. Each returns phi at the volume's vertices,
// sampled back from its own grid or surface samples where it has one, so that the exitant radiance
// (Eq. 3 of TransCut, solver/radiance.h), `render --fields` and the studies treat every method alike.
#pragma once

#include "base/progress.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace waxwork {

struct MethodProblem {
    const TetMesh& mesh;                  // positions in model units, in each piece's rest frame
    const TetConnectivity& connectivity;  // of `mesh`
    const std::vector<TetMaterial>& materials;  // one per tet
    // Per volume vertex and rgb channel, the diffuse incoming light (lighting.h); only boundary vertices
    // are read.
    const std::vector<std::array<double, 3>>& q;
    double mm_per_unit = 1.0;  // model units to millimetres (coefficients are per mm)
    // Stage and fraction of long work; cancellation is checked between iterations (CancelledError).
    Progress* progress = nullptr;
};

struct MethodSolution {
    // Per volume vertex and channel, the fluence phi (zero at vertices of no tet).
    std::vector<std::array<double, 3>> phi;
    size_t unknowns = 0;                // cells, graph nodes or surface samples solved for
    std::array<int, 3> iterations{};    // per channel; 0 for a method that does not iterate
    double setup_ms = 0;                // grid, graph or profile construction, precomputation
    double solve_ms = 0;                // the iterations (or the direct evaluation) for three channels
    // Where the scene is outside the method's valid range but it still ran (the caller prints them).
    std::vector<std::string> warnings;
};

}  // namespace waxwork
