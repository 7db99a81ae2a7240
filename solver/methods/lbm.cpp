#include "solver/methods/lbm.h"

#include "base/error.h"
#include "base/parallel_rows.h"
#include "base/timing.h"
#include "solver/material.h"
#include "solver/methods/voxel_grid.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

namespace waxwork {
namespace {

// Links more grazing than this carry their boundary flux as if at this cosine: the Robin length
// K / cos_n would otherwise grow without bound on links that barely cross a face (or cross one whose
// normal points back, on thin or noisy features).
constexpr double kMinLinkCosine = 0.1;

std::string number(double x) {
    std::ostringstream s;
    s << x;
    return s.str();
}

// The outward unit normal of the boundary face of `tet` nearest to `point` (the link's crossing), or
// the zero vector when the tet has no boundary face.
Eigen::Vector3d crossing_normal(const MethodProblem& problem, int32_t tet, const Eigen::Vector3d& point) {
    Eigen::Vector3d best = Eigen::Vector3d::Zero();
    if (tet < 0) return best;
    double best_distance = std::numeric_limits<double>::infinity();
    const auto& t = problem.mesh.tets[tet];
    for (int f = 0; f < 4; ++f) {
        if (problem.connectivity.tet_neighbors[tet][f] >= 0) continue;
        const Eigen::Vector3d& a = problem.mesh.positions[t[kTetFaces[f][0]]];
        const Eigen::Vector3d& b = problem.mesh.positions[t[kTetFaces[f][1]]];
        const Eigen::Vector3d& c = problem.mesh.positions[t[kTetFaces[f][2]]];
        Eigen::Vector3d n = (b - a).cross(c - a);
        if (n.norm() == 0) continue;
        n.normalize();
        if (n.dot(problem.mesh.positions[t[f]] - a) > 0) n = -n;  // away from the opposite vertex
        const double distance = std::abs(n.dot(point - a));
        if (distance < best_distance) {
            best_distance = distance;
            best = n;
        }
    }
    return best;
}

}  // namespace

void validate_lbm_options(const LbmOptions& options) {
    if (!std::isfinite(options.cell_size_mm) || options.cell_size_mm <= 0)
        throw InvalidArgumentError("lbm: cell_size_mm must be a positive length in mm (got " + number(options.cell_size_mm) + ")");
    if (!std::isfinite(options.tau) || options.tau <= 0.5)
        throw InvalidArgumentError("lbm: tau must be above 1/2 (got " + number(options.tau) +
                                   "): at tau <= 1/2 the collision amplifies the non-equilibrium populations every step and the iteration diverges");
    if (!(options.tolerance > 0 && options.tolerance < 1))
        throw InvalidArgumentError("lbm: tolerance must be in (0, 1) (got " + number(options.tolerance) + ")");
    if (options.max_iterations < 1)
        throw InvalidArgumentError("lbm: max_iterations must be at least 1 (got " + std::to_string(options.max_iterations) + ")");
}

LbmSetup build_lbm_setup(const VoxelGrid& grid, const MethodProblem& problem, const LbmOptions& options) {
    validate_lbm_options(options);
    const size_t n = grid.cell_count();
    if (n == 0)
        throw InvalidArgumentError("lbm: no cell centre lies inside the volume at cell_size_mm " + number(options.cell_size_mm) +
                                   "; use smaller cells");
    const double dx = options.cell_size_mm;

    // dt from the most diffusive material channel present in the cells (lbm_units.h).
    double kappa_max = 0;
    for (size_t c = 0; c < n; ++c) {
        const TetMaterial& m = problem.materials[grid.cell_tet[c]];
        for (int ch = 0; ch < 3; ++ch) kappa_max = std::max(kappa_max, diffusion_coefficient(m.mua[ch], m.musp[ch]));
    }
    LbmSetup setup;
    setup.time_step = lbm_time_step(kappa_max, dx, options.tau);
    LbmLattice& l = setup.lattice;
    l.cell_count = n;
    l.keep.resize(n);
    l.equilibrium.resize(n);
    std::vector<std::array<double, 3>> tau(n);
    setup.min_tau = std::numeric_limits<double>::infinity();
    double max_sigma_dx = 0, min_explicit_margin = std::numeric_limits<double>::infinity();
    bool negative_explicit = false;
    for (size_t c = 0; c < n; ++c) {
        const TetMaterial& m = problem.materials[grid.cell_tet[c]];
        for (int ch = 0; ch < 3; ++ch) {
            const double kappa = diffusion_coefficient(m.mua[ch], m.musp[ch]);
            const LbmRelaxation r = lbm_relaxation(kappa, m.mua[ch], setup.time_step, dx);
            const auto coll = lbm_collision(r, options.explicit_absorption);
            l.keep[c][ch] = coll[0];
            l.equilibrium[c][ch] = coll[1];
            tau[c][ch] = r.tau;
            setup.min_tau = std::min(setup.min_tau, r.tau);
            setup.max_tau = std::max(setup.max_tau, r.tau);
            setup.max_absorption = std::max(setup.max_absorption, r.absorption);
            max_sigma_dx = std::max(max_sigma_dx, effective_transport_coefficient(m.mua[ch], m.musp[ch]) * dx);
            if (options.explicit_absorption) {
                // Stable while |keep| < 1 (the equilibrium mode's 1 - a is then inside too); positive while keep >= 0.
                min_explicit_margin = std::min(min_explicit_margin, 1.0 + coll[0]);
                if (coll[0] < 0) negative_explicit = true;
            }
        }
    }
    if (options.explicit_absorption && min_explicit_margin <= 0)
        throw InvalidArgumentError("lbm: explicit absorption of " + number(setup.max_absorption) +
                                   " per step is unstable at this cell size and tau (it needs mu_a dt < 2 - 1/tau); use implicit absorption or smaller cells");

    for (int i = 0; i < kLbmDirections; ++i) l.next[i] = grid.neighbor[i];
    l.reflection.resize(grid.boundary_links.size());
    l.source.resize(grid.boundary_links.size());
    l.curvature_gain.resize(grid.boundary_links.size());
    if (options.tangential_correction) {
        l.tangent.assign(grid.boundary_links.size(), {0, 0, 0});
        l.tangent_gain.assign(grid.boundary_links.size(), {0, 0, 0});
    }
    const double cell_size_units = grid.cell_size;
    std::vector<size_t> clamped(grid.boundary_links.size(), 0);
    for_rows(grid.boundary_links.size(), 256, [&](size_t k) {
        const VoxelLink& link = grid.boundary_links[k];
        const auto& e = kVoxelDirections[link.direction];
        const Eigen::Vector3d dir(e[0], e[1], e[2]);
        const Eigen::Vector3d crossing = grid.cell_centre(link.cell) + link.fraction * cell_size_units * dir;
        const Eigen::Vector3d normal = crossing_normal(problem, link.tet, crossing);
        // A link whose tet has no boundary face of its own (should not happen) counts as head-on.
        const double cosine = normal.squaredNorm() > 0 ? std::max(normal.dot(dir), kMinLinkCosine) : 1.0;
        const TetMaterial& m = problem.materials[link.tet >= 0 ? link.tet : grid.cell_tet[link.cell]];
        const double a_param = boundary_reflection_parameter(m.eta), fdr = diffuse_fresnel_reflectance(m.eta);
        for (int ch = 0; ch < 3; ++ch) {
            const double robin_cells = 2 * a_param * diffusion_coefficient(m.mua[ch], m.musp[ch]) / (cosine * dx);
            double r = lbm_boundary_reflection(robin_cells, link.fraction, tau[link.cell][ch]);
            if (r < 0) {
                // Cells coarser than the Robin length: a negative reflection would make populations
                // negative on dark boundaries; r = 0 lets all light out (an absorbing link).
                r = 0;
                clamped[k] = 1;
            }
            l.reflection[k][ch] = r;
            l.source[k][ch] = lbm_boundary_source(r, link.q[ch], fdr);
            l.curvature_gain[k][ch] = lbm_boundary_curvature_gain(r, robin_cells, link.fraction);
            // The link imposes phi + K_d d phi/ds = S; K d phi/dn = K_d (ds - t . grad) phi with t the part
            // of the link direction along the boundary, so S gains K_d t . grad phi.
            // The gain is at most 1/6 (a population may move by at most a difference of rho): at tau <= 1
            // it always is, while at larger tau the full correction amplifies checkerboard modes of the
            // lagged gradient and the iteration diverges (measured on the ball at tau = 3).
            if (options.tangential_correction) l.tangent_gain[k][ch] = std::min((1 - r) * robin_cells, 1.0) / 6;
        }
        if (options.tangential_correction && normal.squaredNorm() > 0) {
            const Eigen::Vector3d t = dir - normal.dot(dir) * normal;
            l.tangent[k] = {t.x(), t.y(), t.z()};
        }
    });
    for (size_t k = 0; k < grid.boundary_links.size(); ++k) {
        const VoxelLink& link = grid.boundary_links[k];
        l.next[link.direction][link.cell] = -static_cast<int32_t>(k) - 1;
        setup.clamped_links += clamped[k];
    }

    // What the user should know (lbm_units.h has the measurements behind each threshold).
    if (options.tau < 1)
        setup.warnings.push_back("lbm: tau " + number(options.tau) +
                                 " < 1 over-relaxes the collision: populations go negative while iterating and convergence slows as 1/(tau - 1/2)");
    if (options.tau > kLbmLargeTau)
        setup.warnings.push_back("lbm: tau " + number(options.tau) + " > " + number(kLbmLargeTau) +
                                 " converges in fewer steps but its discretisation error grows with tau; use tau near 1");
    if (setup.min_tau < kLbmSmallTau)
        setup.warnings.push_back("lbm: the least diffusive material gets tau " + number(setup.min_tau) +
                                 " (its kappa is far below the most diffusive one's): it converges slowly and oscillates");
    if (max_sigma_dx > 1)
        setup.warnings.push_back("lbm: cells of " + number(dx) + " mm are coarser than the diffusion length (sigma_tr dx = " +
                                 number(max_sigma_dx) + " > 1): phi near lit surfaces is not resolved; use smaller cells");
    if (negative_explicit)
        setup.warnings.push_back("lbm: explicit absorption of " + number(setup.max_absorption) +
                                 " per step exceeds 1 - 1/tau: populations and phi can go negative");
    if (setup.clamped_links > 0)
        setup.warnings.push_back("lbm: " + std::to_string(setup.clamped_links) + " boundary links are coarser than the Robin length 2 A kappa and were made fully transmitting; use smaller cells");
    return setup;
}

MethodSolution solve_lbm(const MethodProblem& problem, const LbmOptions& options) {
    validate_lbm_options(options);
    const auto start = std::chrono::steady_clock::now();
    report_stage(problem.progress, "lbm: voxelising");
    const VoxelGrid grid = voxelize(problem, options.cell_size_mm);
    check_cancelled(problem.progress);
    LbmSetup setup = build_lbm_setup(grid, problem, options);
    // The weights that carry cell values back to the vertices depend on geometry only: built here so
    // that the solve time is the iteration's alone, as for fd.
    const VertexSampling sampling = build_vertex_sampling(grid, problem);

    MethodSolution solution;
    solution.unknowns = grid.cell_count();
    solution.warnings = std::move(setup.warnings);
    solution.setup_ms = milliseconds_since(start);

    const auto solve_start = std::chrono::steady_clock::now();
    report_stage(problem.progress, "lbm: iterating to the steady state");
    LbmIterationOptions iteration;
    iteration.tolerance = options.tolerance;
    iteration.max_iterations = options.max_iterations;
    iteration.progress = problem.progress;
    const LbmRun run = run_lattice_boltzmann(setup.lattice, iteration);
    if (run.diverged)
        throw AlgorithmError("lbm: the iteration diverged after " + std::to_string(run.iterations) + " steps");
    if (!run.converged)
        solution.warnings.push_back("lbm: stopped after " + std::to_string(run.iterations) +
                                    " steps before the steady state (relative change per step " + number(run.relative_change) + ")");
    solution.iterations = {run.iterations, run.iterations, run.iterations};

    solution.phi = apply_vertex_sampling(sampling, run.rho);
    if (sampling.stats.unsampled > 0)
        solution.warnings.push_back("lbm: " + std::to_string(sampling.stats.unsampled) +
                                    " vertices lie in parts thinner than a cell and got phi = 0; use smaller cells");
    solution.solve_ms = milliseconds_since(solve_start);
    return solution;
}

}  // namespace waxwork
