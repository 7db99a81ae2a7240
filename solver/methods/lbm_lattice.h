// The lattice-Boltzmann core of the `lbm` method: photon densities on a D3Q6 lattice given as cells and
// neighbour lists, with a per-cell BGK collision, streaming, and partially reflecting boundary links
// that let light in (Bernabei et al., seed 004, Sec. III-C, Eqs. 4-5, after Geist et al.'s
// Lattice-Boltzmann Lighting).
//
// Each cell holds f_i, the photon density moving along the six axis directions c_i (0..5: +x, -x, +y,
// -y, +z, -z; the opposite of i is i ^ 1); rho = sum_i f_i is the fluence phi. One step is Eq. 4: a
// collision in every cell, f*_i = keep f_i + equilibrium rho / 6 (Eq. 5's matrix, written per cell as
// two coefficients per channel: BGK relaxation towards the isotropic equilibrium rho / 6 with the
// absorbed fraction removed), then streaming of f*_i to the neighbour along c_i. A population that
// would stream out of the medium through a boundary link comes back into its cell along the opposite
// direction as reflection * f*_i + source: the diffuse Fresnel reflection of the boundary and the light
// that enters there (the physical meaning of the two numbers is set by solver/methods/lbm.h).
//
// The core knows nothing of materials, time steps or meshes: it runs whatever coefficients it is given,
// including unstable or non-positive ones, so the failure cases of the method can be built on purpose.
#pragma once

#include "base/progress.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace waxwork {

inline constexpr int kLbmDirections = 6;  // D3Q6, the paper's "6 principal directions"

struct LbmLattice {
    size_t cell_count = 0;
    // next[i][c]: the cell a population leaving c along direction i streams into, or -(link + 1) when
    // it leaves the medium through boundary link `link`.
    std::array<std::vector<int32_t>, kLbmDirections> next;
    // Per cell and rgb channel, the collision f*_i = keep f_i + equilibrium rho / 6.
    std::vector<std::array<double, 3>> keep, equilibrium;
    // Per boundary link and channel: the population re-entering the link's cell is
    // reflection * (the post-collision population that left) + source.
    std::vector<std::array<double, 3>> reflection, source;
    // Optional (empty, or one per link): a correction of the source by the fluence gradient along the
    // boundary, source + tangent_gain[ch] * (tangent . grad rho), with grad rho from central (or, at
    // the boundary, one-sided) differences of the previous step's rho around the link's cell. It lets
    // an axis link impose a condition on the normal derivative of an oblique boundary (lbm_units.h).
    std::vector<std::array<double, 3>> tangent, tangent_gain;
    // Optional (empty, or one per link): a correction by the second difference of rho along the link,
    // source + curvature_gain[ch] * (rho_c - 2 rho_c' + rho_c''), with c' and c'' the next two cells
    // inward from the link's cell c (previous step's rho; none when the lattice is thinner than three
    // cells there). It moves the Robin condition from half a cell to the link's crossing (lbm_units.h).
    std::vector<std::array<double, 3>> curvature_gain;
};

// Checks sizes and that every next[] entry is a cell or a link; throws InvalidArgumentError
// ("lbm: ...") otherwise.
void validate_lattice(const LbmLattice& lattice);

struct LbmIterationOptions {
    // Stop when the estimated distance to the steady state, max |rho_k - rho_{k-1}| * lambda /
    // (1 - lambda) with lambda the observed contraction per step, is below tolerance * max |rho|.
    double tolerance = 1e-6;
    int max_iterations = 200000;
    int check_every = 16;  // steps between convergence checks (each costs one extra pass over rho)
    // max |rho| above this, or a non-finite rho, counts as divergence and stops the run.
    double divergence_limit = 1e30;
    Progress* progress = nullptr;  // cancellation checked and fraction set at every check
};

struct LbmRun {
    std::vector<std::array<double, 3>> rho;  // per cell and channel, the fluence at the last step
    int iterations = 0;
    bool converged = false;
    bool diverged = false;
    double relative_change = 0;  // max |rho_k - rho_{k-1}| / max |rho| at the last check
    double min_rho = 0;          // the most negative rho seen at any check (0 if none was negative)
    double min_population = 0;   // the most negative f_i seen at any check (0 if none was negative)
};

// Iterates Eq. 4 from f = 0 until the stopping rule holds, divergence, or max_iterations. Collision and
// streaming are one fused, race-free pass (each (cell, direction) slot receives from exactly one
// source), parallel over cells with TBB.
LbmRun run_lattice_boltzmann(const LbmLattice& lattice, const LbmIterationOptions& options);

}  // namespace waxwork
