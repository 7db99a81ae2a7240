// The seeds' alternative methods for the same light, by name: what `render --method`, the solved
// scene and `waxwork bench --only methods` choose from. Each method is in its own pair
// (fd.h, fvm.h, lbm.h, dipole.h); this file only names
// them, holds the one setting the command line gives them and dispatches.
#pragma once

#include "solver/methods/method_problem.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace waxwork {

enum class AlternativeMethod {
    FdJacobi,   // finite differences on a voxel grid, Jacobi relaxation (QuadGraph, seed 002)
    FdCg,       // the same system solved with CG (the fair comparison)
    FvmRelax,   // finite volumes on the vertices' Voronoi cells, the paper's relaxation (seed 000)
    FvmCg,      // the same system solved with CG
    Lbm,        // lattice-Boltzmann diffusion on voxels (seed 004)
    Dipole,     // surface-only, the dipole profile between surface vertices (seed 003)
};

// "fd", "fd-cg", "fvm", "fvm-cg", "lbm", "dipole".
const char* alternative_method_name(AlternativeMethod method);
// Every method, in the order above.
std::vector<AlternativeMethod> all_alternative_methods();
// The method of a name above; nullopt for any other word (transcut, fem, mc are not alternatives).
std::optional<AlternativeMethod> parse_alternative_method(std::string_view name);

// Whether the method lives on a voxel grid (fd, lbm): then cell_mm sets its resolution; the others
// take the volume's own vertices.
bool uses_voxel_grid(AlternativeMethod method);

struct AlternativeMethodSettings {
    AlternativeMethod method = AlternativeMethod::FdCg;
    // Grid methods: the cell size in mm; 0 chooses it from the volume (default_cell_mm).
    double cell_mm = 0;
    // The iterative methods' stopping rule (each option struct's tolerance): the estimated relative
    // error of phi, from CG's Lanczos bound, the relaxations' contraction of their updates, or LBM's
    // distance to its steady state.
    double relative_tolerance = 1e-4;
};

// The cell size a grid method gets when none is given: (volume / vertices)^(1/3) in mm, so that the
// grid has about as many cells as the tet mesh has vertices and both compare at the same unknowns.
double default_cell_mm(const MethodProblem& problem);

// Throws InvalidArgumentError "<name>: why" for scenes or settings the method cannot handle, and what
// the method itself throws.
MethodSolution solve_alternative(const MethodProblem& problem, const AlternativeMethodSettings& settings);

}  // namespace waxwork
