#include "solver/methods/fd.h"

#include "base/error.h"
#include "solver/conjugate_gradient.h"
#include "solver/material.h"
#include "solver/methods/voxel_grid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <tuple>

namespace waxwork {
namespace {

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The cells' system for the three channels: one compressed-row pattern (diagonal first in each row),
// values and right-hand side per channel.
struct FdSystem {
    std::vector<int32_t> offsets, columns;
    std::array<std::vector<double>, 3> values, rhs;

    CsrMatrixView<double> view(int channel) const {
        return {offsets.size() - 1, offsets.data(), columns.data(), values[channel].data()};
    }
};

// Assembles the finite-volume form of Eqs. 5-6 multiplied by the cell volume (all lengths in mm):
//   sum_links kappa_ij h (phi_i - phi_j) + sum_boundary links h^2 (phi_i - g) / (d / kappa + 2 A / (n . axis))
//     + mu_a V_i phi_i = 0,   g = 4 q / (1 - F_dr),
// where kappa_ij is the harmonic mean of the two cells' kappa, d the distance from the centre to the
// surface node, and V_i = h^3 (staircase, cubes) or the product over the axes of the cell's extent
// along it (fraction).
FdSystem assemble(const VoxelGrid& grid, const MethodProblem& problem, FdBoundary boundary) {
    const size_t cells = grid.cell_count();
    const double h = grid.cell_size * problem.mm_per_unit;
    FdSystem system;
    system.offsets.assign(cells + 1, 0);
    for (size_t c = 0; c < cells; ++c) {
        int32_t row = 1;
        for (int d = 0; d < 6; ++d) row += grid.neighbor[d][c] >= 0;
        system.offsets[c + 1] = system.offsets[c] + row;
    }
    const size_t entries = static_cast<size_t>(system.offsets[cells]);
    system.columns.resize(entries);
    for (int ch = 0; ch < 3; ++ch) {
        system.values[ch].assign(entries, 0.0);
        system.rhs[ch].assign(cells, 0.0);
    }
    // Boundary links are ordered by cell: each cell's are a contiguous run.
    std::vector<int32_t> first_link(cells + 1, 0);
    for (const VoxelLink& link : grid.boundary_links) ++first_link[link.cell + 1];
    for (size_t c = 0; c < cells; ++c) first_link[c + 1] += first_link[c];

    const auto kappa_of = [&](int32_t tet, int ch) {
        const TetMaterial& m = problem.materials[tet];
        return diffusion_coefficient(m.mua[ch], m.musp[ch]);
    };
    tbb::parallel_for(size_t{0}, cells, [&](size_t c) {
        const int32_t tet = grid.cell_tet[c];
        std::array<double, 3> half_extent_sum = {0, 0, 0};  // per axis: the cell's extent, h/2 or d per side
        int32_t slot = system.offsets[c];
        const int32_t diagonal = slot++;
        system.columns[diagonal] = static_cast<int32_t>(c);
        for (int d = 0; d < 6; ++d) {
            const int32_t other = grid.neighbor[d][c];
            if (other < 0) continue;
            half_extent_sum[d / 2] += 0.5 * h;
            system.columns[slot] = other;
            for (int ch = 0; ch < 3; ++ch) {
                const double ki = kappa_of(tet, ch), kj = kappa_of(grid.cell_tet[other], ch);
                const double link = 2 * ki * kj / (ki + kj) * h;  // harmonic mean across materials
                system.values[ch][slot] = -link;
                system.values[ch][diagonal] += link;
            }
            ++slot;
        }
        for (int32_t l = first_link[c]; l < first_link[c + 1]; ++l) {
            const VoxelLink& link = grid.boundary_links[l];
            const double distance = (boundary == FdBoundary::Fraction ? link.fraction : 0.5) * h;
            half_extent_sum[link.direction / 2] += boundary == FdBoundary::Fraction ? distance : 0.5 * h;
            const TetMaterial& m = problem.materials[link.tet];
            const double fdr = diffuse_fresnel_reflectance(m.eta);
            const double a = boundary_reflection_parameter(m.eta);
            // Eq. 6 along the link: its one-sided difference is the derivative along the axis, which
            // is n . axis times dphi/dn, so the Robin resistance 2A grows by 1 / (n . axis).
            const auto& axis = kVoxelDirections[link.direction];
            const double cosine =
                boundary == FdBoundary::Cubes
                    ? 1.0
                    : std::max(1e-6, std::abs(link.normal[0] * axis[0] + link.normal[1] * axis[1] +
                                              link.normal[2] * axis[2]));
            for (int ch = 0; ch < 3; ++ch) {
                const double conductance = h * h / (distance / kappa_of(link.tet, ch) + 2 * a / cosine);
                system.values[ch][diagonal] += conductance;
                system.rhs[ch][c] += conductance * 4 * link.q[ch] / (1 - fdr);
            }
        }
        const double volume = half_extent_sum[0] * half_extent_sum[1] * half_extent_sum[2];
        for (int ch = 0; ch < 3; ++ch) system.values[ch][diagonal] += problem.materials[tet].mua[ch] * volume;
    });
    return system;
}

// The paper's relaxation (Eq. 8 with Eq. 9 substituted) on one channel; returns the sweeps done and
// whether the error estimate reached the tolerance.
std::pair<int, bool> solve_jacobi(const CsrMatrixView<double>& m, const std::vector<double>& b, std::vector<double>& x,
                                  const FdOptions& options, Progress* progress, int channel) {
    const size_t n = m.rows;
    std::vector<double> next(n, 0.0);
    double previous_step = 0;
    const double log_tolerance = std::log(options.relative_tolerance);
    for (int sweep = 1; sweep <= options.max_iterations; ++sweep) {
        struct Sums {
            double step = 0, norm = 0;
        };
        const Sums sums = tbb::parallel_reduce(
            tbb::blocked_range<size_t>(0, n), Sums{},
            [&](const tbb::blocked_range<size_t>& range, Sums s) {
                for (size_t i = range.begin(); i != range.end(); ++i) {
                    double sum = b[i];
                    const int32_t start = m.offsets[i];
                    for (int32_t k = start + 1; k < m.offsets[i + 1]; ++k) sum -= m.values[k] * x[m.columns[k]];
                    const double diagonal = m.values[start];
                    next[i] = sum / diagonal;
                    const double change = next[i] - x[i];
                    s.step += diagonal * change * change;
                    s.norm += diagonal * next[i] * next[i];
                }
                return s;
            },
            [](Sums a, const Sums& c) {
                a.step += c.step;
                a.norm += c.norm;
                return a;
            });
        x.swap(next);
        const double step = std::sqrt(sums.step), norm = std::sqrt(sums.norm);
        if (norm == 0) return {sweep, true};  // no light: phi = 0 exactly
        // The contraction per sweep; the remaining error is about step * rho / (1 - rho).
        const double rho = previous_step > 0 ? std::min(step / previous_step, 1.0 - 1e-12) : 1.0 - 1e-12;
        previous_step = step;
        const double estimate = step * rho / (1 - rho) / norm;
        if (sweep > 2 && estimate <= options.relative_tolerance) return {sweep, true};
        if (sweep % 32 == 0) {
            check_cancelled(progress);
            if (progress) {
                const double done = std::clamp(std::log(std::max(estimate, 1e-300)) / log_tolerance, 0.0, 1.0);
                progress->set_fraction(static_cast<float>((channel + done) / 3.0));
            }
        }
    }
    return {options.max_iterations, false};
}

}  // namespace

MethodSolution solve_fd(const MethodProblem& problem, const FdOptions& options) {
    if (!(options.cell_size_mm > 0) || !std::isfinite(options.cell_size_mm))
        throw InvalidArgumentError("fd: cell size " + number_text(options.cell_size_mm) +
                                   " mm must be a positive finite number");
    if (!(options.relative_tolerance >= kMinRelativeTolerance && options.relative_tolerance < 1))
        throw InvalidArgumentError("fd: relative tolerance " + number_text(options.relative_tolerance) +
                                   " must lie in [1e-15, 1)");
    if (options.max_iterations < 1)
        throw InvalidArgumentError("fd: max iterations " + std::to_string(options.max_iterations) + " must be at least 1");
    if (problem.materials.size() != problem.mesh.tet_count() || problem.q.size() != problem.mesh.vertex_count())
        throw InvalidArgumentError("fd: " + std::to_string(problem.materials.size()) + " materials and " +
                                   std::to_string(problem.q.size()) + " q values for " +
                                   std::to_string(problem.mesh.tet_count()) + " tets and " +
                                   std::to_string(problem.mesh.vertex_count()) + " vertices");

    MethodSolution solution;
    const auto setup_start = std::chrono::steady_clock::now();
    report_stage(problem.progress, "fd: grid");
    VoxelGrid grid = naming_context("fd", [&] { return voxelize(problem, options.cell_size_mm, kMaxFdCells); });
    if (grid.cell_count() == 0)
        throw InvalidArgumentError("fd: no cell centre lies inside the volume at cell size " +
                                   number_text(options.cell_size_mm) +
                                   " mm (the volume is thinner than a cell); use a smaller cell size");
    const FdSystem system = assemble(grid, problem, options.boundary);
    const VertexSampling sampling = build_vertex_sampling(grid, problem);
    solution.unknowns = grid.cell_count();
    solution.setup_ms = milliseconds_since(setup_start);

    const auto solve_start = std::chrono::steady_clock::now();
    report_stage(problem.progress, options.solver == FdSolver::Jacobi ? "fd: Jacobi" : "fd: CG");
    std::vector<std::array<double, 3>> cell_phi(grid.cell_count());
    for (int ch = 0; ch < 3; ++ch) {
        check_cancelled(problem.progress);
        std::vector<double> x(grid.cell_count(), 0.0);
        bool converged = false;
        if (options.solver == FdSolver::Jacobi) {
            std::tie(solution.iterations[ch], converged) =
                solve_jacobi(system.view(ch), system.rhs[ch], x, options, problem.progress, ch);
        } else {
            ConjugateGradientOptions cg;
            cg.relative_tolerance = options.relative_tolerance;
            cg.max_iterations = options.max_iterations;
            if (problem.progress)
                cg.on_iteration = [&](int, double estimate) {
                    check_cancelled(problem.progress);
                    const double done = std::clamp(std::log(std::max(estimate, 1e-300)) /
                                                       std::log(options.relative_tolerance), 0.0, 1.0);
                    problem.progress->set_fraction(static_cast<float>((ch + done) / 3.0));
                };
            const ConjugateGradientResult result =
                solve_jacobi_cg<double>(system.view(ch), system.rhs[ch], x, cg);
            solution.iterations[ch] = result.iterations;
            converged = result.converged;
        }
        if (!converged)
            solution.warnings.push_back("fd: channel " + std::to_string(ch) + " stopped after " +
                                        std::to_string(solution.iterations[ch]) +
                                        " iterations before reaching the tolerance");
        for (size_t c = 0; c < x.size(); ++c) cell_phi[c][ch] = x[c];
        if (problem.progress) problem.progress->set_fraction(static_cast<float>((ch + 1) / 3.0));
    }
    solution.phi = apply_vertex_sampling(sampling, cell_phi);
    solution.solve_ms = milliseconds_since(solve_start);
    if (sampling.stats.unsampled > 0)
        solution.warnings.push_back("fd: " + std::to_string(sampling.stats.unsampled) +
                                    " vertices lie in parts thinner than a cell (" +
                                    number_text(options.cell_size_mm) +
                                    " mm) with no cell of their own; they are left dark (phi = 0): use a smaller cell size");
    return solution;
}

}  // namespace waxwork
