#include "solver/methods/fvm.h"

#include "base/error.h"
#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "solver/material.h"
#include "solver/methods/voronoi_dual.h"
#include "tetops/delaunay_check.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

namespace waxwork {

namespace {

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

std::string percent_text(size_t part, size_t whole) {
    char text[32];
    std::snprintf(text, sizeof text, "%.2f%%", whole ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 0.0);
    return text;
}

void validate(const MethodProblem& problem) {
    const size_t n = problem.mesh.vertex_count();
    if (problem.q.size() != n)
        throw InvalidArgumentError("fvm: q has " + std::to_string(problem.q.size()) + " entries for " + std::to_string(n) +
                                   " vertices");
    if (problem.materials.size() != problem.mesh.tet_count())
        throw InvalidArgumentError("fvm: " + std::to_string(problem.materials.size()) + " materials for " +
                                   std::to_string(problem.mesh.tet_count()) + " tets");
    if (problem.connectivity.vertex_tets.row_count() != n || problem.connectivity.tet_neighbors.size() != problem.mesh.tet_count())
        throw InvalidArgumentError("fvm: the connectivity does not belong to the mesh");
    try {
        validate_mm_per_unit(problem.mm_per_unit, "mm_per_unit");
        validate_tet_materials(problem.materials);
    } catch (const InvalidArgumentError& error) {
        throw InvalidArgumentError(std::string("fvm: ") + error.what());
    }
    for (int32_t v : problem.connectivity.boundary_vertices)
        for (double value : problem.q[v])
            if (!std::isfinite(value))
                throw InvalidArgumentError("fvm: q of vertex " + std::to_string(v) + " is not finite");
}

int32_t slot_of(const FvmSystem& s, int32_t row, int32_t column) {
    const auto begin = s.columns.begin() + s.offsets[row], end = s.columns.begin() + s.offsets[row + 1];
    return static_cast<int32_t>(std::lower_bound(begin, end, column) - s.columns.begin());
}

// Jacobi relaxation (Eqs. 16-17): phi_{t+1} = D^-1 (b + W phi_t), from phi_0 = 0.
int relax(const FvmSystem& s, int channel, std::span<const double> b, std::span<double> phi, const FvmOptions& options,
          const MethodProblem& problem, double* final_estimate) {
    const size_t n = s.diagonal.size();
    const std::vector<double>& m = s.values[channel];
    std::vector<double> current(n, 0.0), next(n, 0.0);
    std::fill(phi.begin(), phi.end(), 0.0);
    double previous_step = 0, start_step = 0;
    for (int iteration = 1; iteration <= options.max_iterations; ++iteration) {
        check_cancelled(problem.progress);
        struct Norms {
            double step2 = 0, phi2 = 0;
        };
        const Norms norms = tbb::parallel_reduce(
            tbb::blocked_range<size_t>(0, n, 1024), Norms{},
            [&](const tbb::blocked_range<size_t>& range, Norms acc) {
                for (size_t i = range.begin(); i != range.end(); ++i) {
                    double sum = b[i];
                    const int32_t d = s.diagonal[i];
                    for (int32_t k = s.offsets[i]; k < s.offsets[i + 1]; ++k)
                        if (k != d) sum -= m[k] * current[s.columns[k]];
                    next[i] = sum / m[d];
                    const double step = next[i] - current[i];
                    acc.step2 += m[d] * step * step;
                    acc.phi2 += m[d] * next[i] * next[i];
                }
                return acc;
            },
            [](Norms a, Norms c) { return Norms{a.step2 + c.step2, a.phi2 + c.phi2}; });
        current.swap(next);
        const double step = std::sqrt(norms.step2);
        if (!std::isfinite(step) || (iteration > 1 && step > 1e6 * start_step))
            throw AlgorithmError("fvm: relaxation diverged after " + std::to_string(iteration) +
                                 " iterations (the dual has negative coefficients: the matrix is not diagonally "
                                 "dominant; clamp them or use CG)");
        if (iteration == 1) start_step = step;
        if (norms.phi2 == 0) {  // no light reaches this channel
            *final_estimate = 0;
            std::copy(current.begin(), current.end(), phi.begin());
            return iteration;
        }
        // A contraction with ratio rho leaves an error of at most step rho / (1 - rho).
        const double rho = previous_step > 0 ? step / previous_step : 1.0;
        previous_step = step;
        const double estimate = rho < 1 ? step * rho / (1 - rho) / std::sqrt(norms.phi2) : INFINITY;
        *final_estimate = estimate;
        if (problem.progress && iteration % 64 == 0 && std::isfinite(estimate))
            problem.progress->set_fraction(static_cast<float>(
                (channel + std::clamp(std::log(estimate) / std::log(options.relative_tolerance), 0.0, 1.0)) / 3.0));
        if (iteration >= 3 && estimate <= options.relative_tolerance) {
            std::copy(current.begin(), current.end(), phi.begin());
            return iteration;
        }
    }
    std::copy(current.begin(), current.end(), phi.begin());
    return options.max_iterations;
}

}  // namespace

FvmSystem assemble_fvm_system(const MethodProblem& problem, NegativeDualCoefficients negative) {
    validate(problem);
    const TetMesh& mesh = problem.mesh;
    const TetConnectivity& conn = problem.connectivity;
    const size_t n = mesh.vertex_count();
    VoronoiDual dual;
    try {
        dual = build_voronoi_dual(mesh, conn, problem.mm_per_unit);
    } catch (const InvalidArgumentError& error) {
        throw InvalidArgumentError(std::string("fvm: ") + error.what());
    }

    FvmSystem s;
    // Pattern: i and its one-ring, ascending.
    s.offsets.assign(n + 1, 0);
    for (size_t i = 0; i < n; ++i)
        s.offsets[i + 1] = s.offsets[i] + static_cast<int32_t>(conn.vertex_vertices.row(i).size()) + 1;
    s.columns.resize(s.offsets[n]);
    s.diagonal.resize(n);
    for (auto& v : s.values) v.assign(s.columns.size(), 0.0);
    s.source.assign(n, 0.0);
    s.cell_volume.assign(n, 0.0);
    std::vector<std::array<double, 3>> absorption(n, {0, 0, 0});

    std::vector<DiffusionMatrix::TetCoefficients> coefficients(mesh.tet_count());
    tbb::parallel_for(size_t{0}, mesh.tet_count(), [&](size_t t) { coefficients[t] = tet_diffusion_coefficients(problem.materials[t]); });
    // TransCut's cotangent weights, for the edges where the fallback replaces a negative coefficient.
    const bool fallback = negative == NegativeDualCoefficients::CotangentFallback;
    std::vector<std::array<double, 6>> cotangent(fallback ? mesh.tet_count() : 0);
    std::array<std::vector<double>, 3> cotangent_values;
    if (fallback) {
        for (auto& v : cotangent_values) v.assign(s.columns.size(), 0.0);
        tbb::parallel_for(size_t{0}, mesh.tet_count(), [&](size_t t) {
            const Tet& tet = mesh.tets[t];
            const Eigen::Vector3d& origin = mesh.positions[tet[0]];
            const double mm = problem.mm_per_unit;
            cotangent[t] = tet_edge_stiffness<double>(Eigen::Vector3d::Zero(), (mesh.positions[tet[1]] - origin) * mm,
                                                      (mesh.positions[tet[2]] - origin) * mm,
                                                      (mesh.positions[tet[3]] - origin) * mm, StiffnessForm::Gradient);
        });
    }

    // Row by row (no races): off-diagonal entries hold -W_ij, summed over the tets around edge ij in
    // ascending tet order in both rows, so the matrix is symmetric bit for bit.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
            int32_t k = s.offsets[i];
            bool placed = false;
            for (int32_t j : conn.vertex_vertices.row(i)) {
                if (!placed && j > static_cast<int32_t>(i)) {
                    s.diagonal[i] = k;
                    s.columns[k++] = static_cast<int32_t>(i);
                    placed = true;
                }
                s.columns[k++] = j;
            }
            if (!placed) {
                s.diagonal[i] = k;
                s.columns[k++] = static_cast<int32_t>(i);
            }
            for (int32_t t : conn.vertex_tets.row(i)) {
                const Tet& tet = mesh.tets[t];
                const int li = static_cast<int>(std::find(tet.begin(), tet.end(), static_cast<int32_t>(i)) - tet.begin());
                s.cell_volume[i] += dual.cell_volume[t][li];
                for (int c = 0; c < 3; ++c) absorption[i][c] += coefficients[t].mua[c] * dual.cell_volume[t][li];
                for (int lj = 0; lj < 4; ++lj) {
                    if (lj == li) continue;
                    const double g = dual.edge_coefficient[t][tet_edge_index(li, lj)];
                    const int32_t slot = slot_of(s, static_cast<int32_t>(i), tet[lj]);
                    for (int c = 0; c < 3; ++c) s.values[c][slot] -= coefficients[t].kappa[c] * g;
                    if (fallback)  // K_ab / kappa = -(cotangent weight): stored like -W_ij
                        for (int c = 0; c < 3; ++c)
                            cotangent_values[c][slot] += coefficients[t].kappa[c] * cotangent[t][tet_edge_index(li, lj)];
                }
            }
        }
    });

    // Robin term and source on the surface faces (Eq. 15): S_is / (2A) on the diagonal, and
    // b_i = S_is (4 / (1 - F_dr)) q_i / (2A) = 2 S_is q_i / (A (1 - F_dr)).
    std::vector<double> robin(n, 0.0);
    FvmDualStatistics& stats = s.statistics;
    std::vector<uint8_t> boundary_slot(s.columns.size(), 0);
    for (size_t f = 0; f < conn.boundary_faces.size(); ++f) {
        const BoundaryFace& face = conn.boundary_faces[f];
        const DiffusionMatrix::TetCoefficients& tc = coefficients[face.tet];
        for (int corner = 0; corner < 3; ++corner) {
            const int32_t v = face.vertices[corner];
            const double share = dual.boundary_area[f][corner];
            robin[v] += 0.5 * tc.inv_a * share;
            s.source[v] += 2.0 * tc.inv_a_one_minus_fdr * share;
            const int32_t w = face.vertices[(corner + 1) % 3];
            boundary_slot[slot_of(s, std::min(v, w), std::max(v, w))] = 1;
        }
    }

    // Statistics on channel 0, before clamping.
    for (size_t i = 0; i < n; ++i) {
        double row_sum = 0;
        for (int32_t k = s.offsets[i]; k < s.offsets[i + 1]; ++k)
            if (k != s.diagonal[i]) row_sum += std::abs(s.values[0][k]);
        for (int32_t k = s.offsets[i]; k < s.offsets[i + 1]; ++k) {
            if (k == s.diagonal[i]) continue;
            const double w = -s.values[0][k];
            if (w < 0 && row_sum > 0) stats.most_negative_ratio = std::min(stats.most_negative_ratio, w / row_sum);
            if (s.columns[k] <= static_cast<int32_t>(i)) continue;  // each edge once
            ++stats.edges;
            stats.boundary_edges += boundary_slot[k];
            if (w < 0) {
                ++stats.negative_edges;
                stats.negative_boundary_edges += boundary_slot[k];
            }
        }
        if (s.cell_volume[i] < 0) ++stats.negative_cells;
    }
    if (stats.negative_edges > 0 || stats.negative_cells > 0) {
        const DelaunayCheck check = check_local_delaunay(mesh, conn);
        stats.interior_faces = check.interior_faces;
        stats.non_delaunay_faces = check.non_delaunay_faces;
    }

    // Clamp, then the diagonal: sum_j W_ij + mu_a V_i + S_is / (2A).
    const bool clamp = negative != NegativeDualCoefficients::Keep;
    tbb::parallel_for(size_t{0}, n, [&](size_t i) {
        const int32_t d = s.diagonal[i];
        if (conn.vertex_tets.row(i).empty()) {  // a vertex of no tet: phi = 0
            for (int c = 0; c < 3; ++c) s.values[c][d] = 1.0;
            s.source[i] = 0;
            return;
        }
        for (int c = 0; c < 3; ++c) {
            double diagonal = robin[i] + (clamp ? std::max(absorption[i][c], 0.0) : absorption[i][c]);
            for (int32_t k = s.offsets[i]; k < s.offsets[i + 1]; ++k) {
                if (k == d) continue;
                if (clamp && s.values[c][k] > 0) s.values[c][k] = fallback ? std::min(cotangent_values[c][k], 0.0) : 0.0;
                diagonal -= s.values[c][k];
            }
            s.values[c][d] = diagonal;
        }
    });
    return s;
}

MethodSolution solve_fvm(const MethodProblem& problem, const FvmOptions& options) {
    if (!(options.relative_tolerance >= kMinRelativeTolerance && options.relative_tolerance < 1))
        throw InvalidArgumentError("fvm: relative_tolerance must be in [1e-15, 1) (got " +
                                   number_text(options.relative_tolerance) + ")");
    if (options.max_iterations < 1)
        throw InvalidArgumentError("fvm: max_iterations must be at least 1 (got " + std::to_string(options.max_iterations) + ")");
    if (options.solver != FvmSolver::Relaxation && options.solver != FvmSolver::Cg)
        throw InvalidArgumentError("fvm: unknown solver");

    const auto setup_start = std::chrono::steady_clock::now();
    report_stage(problem.progress, "fvm: Voronoi dual");
    const FvmSystem system = assemble_fvm_system(problem, options.negative_coefficients);
    const size_t n = problem.mesh.vertex_count();
    MethodSolution solution;
    solution.setup_ms = milliseconds_since(setup_start);
    for (int32_t v = 0; v < static_cast<int32_t>(n); ++v)
        if (!problem.connectivity.vertex_tets.row(v).empty()) ++solution.unknowns;

    const FvmDualStatistics& stats = system.statistics;
    const bool clamp = options.negative_coefficients != NegativeDualCoefficients::Keep;
    if (stats.negative_edges > 0) {
        std::string warning = "fvm: " + std::to_string(stats.negative_edges) + " of " + std::to_string(stats.edges) +
                              " dual coefficients (" + percent_text(stats.negative_edges, stats.edges) + ") are negative (" +
                              std::to_string(stats.negative_boundary_edges) + " on the boundary; " +
                              std::to_string(stats.non_delaunay_faces) + " of " + std::to_string(stats.interior_faces) +
                              " interior faces are not Delaunay); ";
        switch (options.negative_coefficients) {
        case NegativeDualCoefficients::Clamp: warning += "clamped to zero (the operator changes on those edges)"; break;
        case NegativeDualCoefficients::CotangentFallback:
            warning += "replaced by TransCut's cotangent weights (clamped to zero where those are negative too)";
            break;
        case NegativeDualCoefficients::Keep:
            warning += "kept: the matrix is not an M-matrix, phi can go negative and relaxation can diverge";
            break;
        }
        solution.warnings.push_back(warning);
    }
    if (stats.negative_cells > 0)
        solution.warnings.push_back("fvm: " + std::to_string(stats.negative_cells) +
                                    " Voronoi cells have negative circumcentric volume (obtuse tets); " +
                                    (clamp ? "their absorption is clamped to zero" : "kept"));

    const auto solve_start = std::chrono::steady_clock::now();
    report_stage(problem.progress, options.solver == FvmSolver::Relaxation ? "fvm: relaxation" : "fvm: CG");
    solution.phi.assign(n, {0, 0, 0});
    std::vector<double> b(n), phi(n);
    for (int c = 0; c < 3; ++c) {
        check_cancelled(problem.progress);
        for (size_t i = 0; i < n; ++i) b[i] = system.source[i] * problem.q[i][c];
        double estimate = 0;
        bool converged = true;
        if (options.solver == FvmSolver::Relaxation) {
            solution.iterations[c] = relax(system, c, b, phi, options, problem, &estimate);
            converged = estimate <= options.relative_tolerance;
        } else {
            std::fill(phi.begin(), phi.end(), 0.0);
            const CsrMatrixView<double> view{n, system.offsets.data(), system.columns.data(), system.values[c].data()};
            ConjugateGradientOptions cg;
            cg.relative_tolerance = options.relative_tolerance;
            cg.max_iterations = options.max_iterations;
            if (problem.progress)
                cg.on_iteration = [&](int, double) { check_cancelled(problem.progress); };
            try {
                const ConjugateGradientResult result = solve_jacobi_cg<double>(view, b, phi, cg);
                solution.iterations[c] = result.iterations;
                estimate = result.estimated_relative_error;
                converged = result.converged;
            } catch (const AlgorithmError& error) {
                throw AlgorithmError(std::string("fvm: CG failed (") + error.what() + ")");
            }
        }
        if (!converged)
            solution.warnings.push_back("fvm: channel " + std::to_string(c) + " stopped after " +
                                        std::to_string(solution.iterations[c]) + " iterations at estimated error " +
                                        number_text(estimate));
        for (size_t i = 0; i < n; ++i) solution.phi[i][c] = phi[i];
        if (problem.progress) problem.progress->set_fraction(static_cast<float>(c + 1) / 3.0f);
    }
    solution.solve_ms = milliseconds_since(solve_start);
    return solution;
}

}  // namespace waxwork
