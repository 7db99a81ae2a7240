#include "solver/diffusion_solve.h"

#include "base/error.h"
#include "base/parallel_rows.h"
#include "base/timing.h"
#include "solver/cg_channel_state.h"
#include "solver/conjugate_gradient.h"
#include "solver/gpu/gpu_conjugate_gradient.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>

namespace waxwork {
namespace {

// --- Three channels in one CG loop --------------------------------------------------------------
// The three rgb systems share one pattern, so one pass over the pattern serves all three: the column
// indices are read once per iteration instead of three times, and the three row sums are independent
// dependency chains, which hides the latency of the double additions (the single-channel row
// product is bound by that latency, not by memory). Values and vectors are interleaved (3 per slot,
// 3 per vertex) so each gather fetches one cache line for all channels.
//
// Each channel runs exactly the algorithm of solve_jacobi_cg (same stopping rule, Ritz estimate,
// true-residual confirmation and restarts, same deterministic reduction tree and summation order per
// channel), so its iterates are those of a separate solve; a channel that has stopped is frozen while
// the others continue. Used for float (see solve_diffusion_system for why not double). Written here
// rather than in conjugate_gradient.h because it is specific to the shared-pattern rgb triple of
// DiffusionMatrix.
constexpr size_t kGrain = 4096;  // as conjugate_gradient.cpp: fixed chunks, deterministic reductions

[[noreturn]] void breakdown(int iteration, const std::string& what) {
    throw AlgorithmError("conjugate gradient: " + what + " at iteration " + std::to_string(iteration) +
                         " (matrix not positive definite, or values lost to rounding: degenerate tets?)");
}

template <typename Scalar>
struct Rgb {
    const DiffusionMatrix& m;
    size_t n;
    std::vector<Scalar> values;  // 3 per slot
    std::vector<Scalar> b, x, r, z, p, q, inv_diag;  // 3 per vertex
    std::vector<double> diag;                        // 3 per vertex

    // r = b - M x for channel c (double accumulation); fills z = D^-1 r, returns r . z.
    double true_residual(int c) {
        return sum_rows(n, kGrain, [&](size_t i) {
            double sum = 0;
            for (int32_t k = m.offsets[i]; k < m.offsets[i + 1]; ++k)
                sum += static_cast<double>(values[3 * k + c]) *
                       static_cast<double>(x[3 * static_cast<size_t>(m.columns[k]) + c]);
            const size_t j = 3 * i + c;
            const double ri = static_cast<double>(b[j]) - sum;
            r[j] = static_cast<Scalar>(ri);
            z[j] = static_cast<Scalar>(ri * static_cast<double>(inv_diag[j]));
            return static_cast<double>(r[j]) * static_cast<double>(z[j]);
        });
    }
};

template <typename Scalar>
std::array<ConjugateGradientResult, 3> solve_rgb(const DiffusionMatrix& m, const std::array<std::vector<double>, 3>& b,
                                                 const DiffusionOptions& options,
                                                 std::vector<std::array<double, 3>>& phi) {
    const size_t n = m.size(), nnz = m.nonzeros();
    if (!(options.relative_tolerance > 0) || options.max_iterations < 0)
        throw InvalidArgumentError("conjugate gradient: tolerance must be positive and max_iterations non-negative");
    std::array<CgChannelState, 3> ch;
    std::array<ConjugateGradientResult, 3> results;
    if (n == 0) {
        for (auto& r : results) r.converged = true;
        return results;
    }
    Rgb<Scalar> s{m, n, std::vector<Scalar>(3 * nnz), {}, {}, {}, {}, {}, {}, {}, std::vector<double>(3 * n)};
    for (auto* v : {&s.b, &s.x, &s.r, &s.z, &s.p, &s.q, &s.inv_diag}) v->resize(3 * n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nnz, 16 * kGrain), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k)
            for (int c = 0; c < 3; ++c) s.values[3 * k + c] = static_cast<Scalar>(m.values[c][k]);
    });
    for (int c = 0; c < 3; ++c) {
        bool bad_input = false;
        for (size_t i = 0; i < n; ++i) {
            const size_t j = 3 * i + c;
            s.b[j] = static_cast<Scalar>(b[c][i]);
            s.x[j] = static_cast<Scalar>(phi[i][c]);
            // As solve_jacobi_cg: the diagonal is the stored (Scalar) value.
            const double d = s.values[3 * static_cast<size_t>(m.diagonal[i]) + c];
            if (!(d > 0) || !std::isfinite(d))
                throw AlgorithmError("conjugate gradient: diagonal entry " + std::to_string(i) + " is " +
                                     std::to_string(d) + " (must be positive and finite)");
            s.diag[j] = d;
            s.inv_diag[j] = static_cast<Scalar>(1.0 / d);
            if (!std::isfinite(static_cast<double>(s.b[j])) || !std::isfinite(static_cast<double>(s.x[j])))
                bad_input = true;
        }
        if (bad_input) throw AlgorithmError("conjugate gradient: right-hand side or start vector is not finite");
    }

    const double tol = options.relative_tolerance;
    for (int c = 0; c < 3; ++c) {
        ch[c].rz = s.true_residual(c);
        // b . D^-1 b and x . D x.
        const auto norms = reduce_rows<2>(n, kGrain, [&](size_t i, std::array<double, 2>& sums) {
            const size_t j = 3 * i + c;
            sums[0] += static_cast<double>(s.b[j]) * s.b[j] / s.diag[j];
            sums[1] += s.diag[j] * static_cast<double>(s.x[j]) * s.x[j];
        });
        if (norms[0] == 0) {  // the solution is exactly zero
            for (size_t i = 0; i < n; ++i) s.x[3 * i + c] = Scalar(0);
            ch[c].active = false;
            ch[c].result.converged = true;
        }
        ch[c].xnorm2 = norms[1];
    }
    s.p = s.z;

    const Scalar* values = s.values.data();
    const int32_t* offsets = m.offsets.data();
    const int32_t* columns = m.columns.data();
    int k = 0;
    for (; k < options.max_iterations && (ch[0].active || ch[1].active || ch[2].active); ++k) {
        const std::array<bool, 3> act = {ch[0].active, ch[1].active, ch[2].active};
        // q = M p and p . q for the three channels in one pass (frozen channels are computed and ignored:
        // cheaper than branching in the inner loop, and their p stays finite).
        const Scalar* p = s.p.data();
        Scalar* q = s.q.data();
        const auto pq = reduce_rows<3>(n, kGrain, [&](size_t i, std::array<double, 3>& sums) {
            double s0 = 0, s1 = 0, s2 = 0;
            for (int32_t kk = offsets[i]; kk < offsets[i + 1]; ++kk) {
                const Scalar* v = values + 3 * static_cast<size_t>(kk);
                const Scalar* pj = p + 3 * static_cast<size_t>(columns[kk]);
                s0 += static_cast<double>(v[0]) * static_cast<double>(pj[0]);
                s1 += static_cast<double>(v[1]) * static_cast<double>(pj[1]);
                s2 += static_cast<double>(v[2]) * static_cast<double>(pj[2]);
            }
            q[3 * i] = static_cast<Scalar>(s0);
            q[3 * i + 1] = static_cast<Scalar>(s1);
            q[3 * i + 2] = static_cast<Scalar>(s2);
            sums[0] += static_cast<double>(p[3 * i]) * s0;
            sums[1] += static_cast<double>(p[3 * i + 1]) * s1;
            sums[2] += static_cast<double>(p[3 * i + 2]) * s2;
        });
        std::array<Scalar, 3> a{};
        std::array<double, 3> alpha{};
        for (int c = 0; c < 3; ++c) {
            if (!act[c]) continue;
            if (!std::isfinite(pq[c])) breakdown(k, "p.Mp is not finite");
            if (!(pq[c] > 0)) breakdown(k, "p.Mp = " + std::to_string(pq[c]) + " is not positive");
            alpha[c] = ch[c].rz / pq[c];
            a[c] = static_cast<Scalar>(alpha[c]);
        }
        // x += alpha p, r -= alpha q, z = D^-1 r, and the two norms per channel, in one pass.
        // While all three channels run (nearly always: they converge within a few iterations of each
        // other), the branch-free instance of the loop is taken.
        const bool all_active = act[0] && act[1] && act[2];
        const auto update = [&](auto every_channel) {
            return reduce_rows<6>(n, kGrain, [&](size_t i, std::array<double, 6>& sums) {
                for (int c = 0; c < 3; ++c) {
                    if (!every_channel && !act[c]) continue;
                    const size_t j = 3 * i + c;
                    s.x[j] += a[c] * s.p[j];
                    s.r[j] -= a[c] * s.q[j];
                    s.z[j] = s.inv_diag[j] * s.r[j];
                    sums[2 * c] += static_cast<double>(s.r[j]) * static_cast<double>(s.z[j]);
                    sums[2 * c + 1] += s.diag[j] * static_cast<double>(s.x[j]) * static_cast<double>(s.x[j]);
                }
            });
        };
        const std::array<double, 6> upd = all_active ? update(std::true_type{}) : update(std::false_type{});
        std::array<double, 3> beta{};
        std::array<bool, 3> update_p{};
        for (int c = 0; c < 3; ++c) {
            if (!act[c]) continue;
            CgChannelState& st = ch[c];
            if (!std::isfinite(upd[2 * c]) || !std::isfinite(upd[2 * c + 1]))
                breakdown(k, "the iterate became non-finite");
            beta[c] = st.record_step(alpha[c], upd[2 * c], upd[2 * c + 1]);
            double lam = 0;
            const double est = st.current_estimate(k, tol, false, lam);
            if (est <= tol && st.may_stop(k, n)) {
                // Confirm with the true residual: the recursive one drifts (far, in float).
                const double rz_true = s.true_residual(c);
                if (!std::isfinite(rz_true)) breakdown(k, "the true residual is not finite");
                if (st.confirm(k, rz_true, st.estimate(rz_true, lam), lam, tol)) continue;
                for (size_t i = 0; i < n; ++i) s.p[3 * i + c] = s.z[3 * i + c];
                continue;
            }
            st.result.estimated_relative_error = est;
            update_p[c] = true;
        }
        if (update_p[0] || update_p[1] || update_p[2]) {
            std::array<Scalar, 3> bt{};
            for (int c = 0; c < 3; ++c) bt[c] = static_cast<Scalar>(beta[c]);
            tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& range) {
                for (size_t i = range.begin(); i != range.end(); ++i)
                    for (int c = 0; c < 3; ++c)
                        if (update_p[c]) s.p[3 * i + c] = s.z[3 * i + c] + bt[c] * s.p[3 * i + c];
            });
        }
    }
    for (int c = 0; c < 3; ++c) results[c] = ch[c].finish(k);
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) phi[i][c] = s.x[3 * i + c];
    return results;
}

}  // namespace

void solve_diffusion_system(const DiffusionMatrix& matrix, const std::vector<std::array<double, 3>>& q,
                            const DiffusionOptions& options, DiffusionSolution& solution,
                            std::span<const CornerLight> corners) {
    const auto start = std::chrono::steady_clock::now();
    const size_t n = matrix.size();
    if (solution.phi.size() != n) solution.phi.assign(n, {0.0, 0.0, 0.0});
    for (const auto& v : q)
        for (double c : v)
            if (!std::isfinite(c)) throw InvalidArgumentError("solve_diffusion: the incident light q is not finite");
    std::array<std::vector<double>, 3> b;
    for (int c = 0; c < 3; ++c) {
        b[c].resize(n);
        diffusion_right_hand_side(matrix, q, c, b[c]);
        add_corner_light(matrix, corners, c, b[c]);
    }
    // Float: the three channels in one loop (solve_rgb); the interleaved float values and the pattern
    // (~16 bytes per nonzero) stay in the last-level cache across iterations at 500K tets. Double:
    // one channel after the other on the assembled values (no copy); interleaved, the three double
    // channels (28 bytes per nonzero) no longer fit in that cache and the fused loop was measured
    // slower (bench/solver_bench.cpp, BM_JacobiCg<Double> vs 3x BM_JacobiCgDoubleOneChannel).
    std::array<ConjugateGradientResult, 3> results;
    bool solved = false, gpu_stopped_short = false;
    solution.backend = SolverBackend::Cpu;
    solution.gpu_fallback_reason.clear();
    if (options.backend == SolverBackend::Gpu) {
        try {
            if (!options.gl) throw GpuError("GPU solver: no OpenGL context was given");
            GpuCgOptions gpu;
            gpu.relative_tolerance = options.relative_tolerance;
            gpu.max_iterations = options.max_iterations;
            GpuDiffusionSolver gpu_solver(*options.gl, matrix);
            gpu_solver.set_right_hand_side(b);
            gpu_solver.set_solution(solution.phi);  // the warm start
            results = gpu_solver.solve(gpu);
            solution.phi = gpu_solver.solution();  // also the CPU's warm start if it has to take over
            solved = std::all_of(results.begin(), results.end(), [](const auto& r) { return r.converged; });
            if (solved) {
                solution.backend = SolverBackend::Gpu;
            } else {
                // Float CG cannot reach every tolerance on every volume (a tight one, or coefficients
                // scaled to the edge of float's range); double CG on the CPU can, from where it stopped.
                const auto worst = std::max_element(results.begin(), results.end(), [](const auto& a, const auto& b) {
                    return a.estimated_relative_error < b.estimated_relative_error;
                });
                gpu_stopped_short = true;
                std::ostringstream reason;
                reason << "float CG on the GPU stopped at an estimated error of " << worst->estimated_relative_error
                       << " (tolerance " << options.relative_tolerance << "): finished in double on the CPU";
                solution.gpu_fallback_reason = reason.str();
            }
        } catch (const GpuError& e) {
            solution.gpu_fallback_reason = e.what();
        }
    }
    const bool float_path = options.precision == SolverPrecision::Float || solution.backend == SolverBackend::Gpu;
    if (solved) {
        // phi came from the GPU
    } else if (options.precision == SolverPrecision::Float && !gpu_stopped_short) {
        results = solve_rgb<float>(matrix, b, options, solution.phi);
    } else {
        ConjugateGradientOptions cg;
        cg.relative_tolerance = options.relative_tolerance;
        cg.max_iterations = options.max_iterations;
        std::vector<double> x(n);
        for (int c = 0; c < 3; ++c) {
            for (size_t i = 0; i < n; ++i) x[i] = solution.phi[i][c];
            const CsrMatrixView<double> view{n, matrix.offsets.data(), matrix.columns.data(), matrix.values[c].data()};
            results[c] = solve_jacobi_cg<double>(view, b[c], x, cg);
            for (size_t i = 0; i < n; ++i) solution.phi[i][c] = x[i];
            if (!results[c].converged) break;  // reported below, as before, without solving the rest
        }
    }
    for (int c = 0; c < 3; ++c) {
        const ConjugateGradientResult& r = results[c];
        solution.iterations[c] = r.iterations;
        solution.estimated_relative_error[c] = r.estimated_relative_error;
        if (!r.converged) {
            std::ostringstream msg;
            msg << "solve_diffusion: channel " << "rgb"[c] << " did not converge to relative error "
                << options.relative_tolerance << " (" << r.iterations << " iterations, estimated error "
                << r.estimated_relative_error << ", "
                << (float_path ? "float: try double precision or " : "")
                << "check the mesh for slivers)";
            throw AlgorithmError(msg.str());
        }
    }
    solution.solve_ms = milliseconds_since(start);
}

DiffusionSolution solve_diffusion(const TetMesh& mesh, const TetConnectivity& connectivity,
                                  const std::vector<TetMaterial>& materials,
                                  const std::vector<std::array<double, 3>>& q, const DiffusionOptions& options,
                                  std::span<const CornerLight> corners) {
    if (q.size() != mesh.vertex_count())
        throw InvalidArgumentError("solve_diffusion: " + std::to_string(q.size()) + " light values for " +
                                   std::to_string(mesh.vertex_count()) + " vertices");
    DiffusionSolution solution;
    const auto start = std::chrono::steady_clock::now();
    AssemblyOptions assembly;
    assembly.discretization = options.discretization;
    assembly.stiffness_form = options.stiffness_form;
    assembly.mm_per_unit = options.mm_per_unit;
    const DiffusionMatrix matrix = assemble_diffusion_matrix(mesh, connectivity, materials, assembly);
    solution.assembly_ms = milliseconds_since(start);
    solve_diffusion_system(matrix, q, options, solution, corners);
    return solution;
}

}  // namespace waxwork
