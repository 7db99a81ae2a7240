#include "bench/studies/solver_comparison.h"

#include "base/error.h"
#include "base/timing.h"
#include "bench/studies/cpu_usage.h"
#include "bench/studies/provenance.h"
#include "bench/studies/repeated_timing.h"
#include "bench/studies/svg_chart.h"
#include "io/atomic_file.h"
#include "multires/cascadic_solver.h"
#include "multires/gpu_multigrid_frame_solver.h"
#include "multires/gpu_multires_solver.h"
#include "multires/multigrid_cg.h"
#include "multires/multigrid_frame_solver.h"
#include "multires/multires_solver.h"
#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "solver/gpu/gpu_conjugate_gradient.h"
#include "solver/petsc_peers.h"
#include "solver/reference/reference_solvers.h"

#include <Eigen/IterativeLinearSolvers>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <functional>
#include <iostream>
#include <limits>
#include <span>

namespace waxwork {
namespace {

using Fields = std::array<std::vector<double>, 3>;
// Runs one solver with an iteration cap on all three channels, writing x (zeroed before the call).
using CappedSolve = std::function<void(int cap, Fields& x)>;

double relative_error(const Fields& x, const Fields& reference) {
    double e = 0, r = 0;
    for (size_t c = 0; c < 3; ++c)
        for (size_t i = 0; i < x[c].size(); ++i) {
            const double d = x[c][i] - reference[c][i];
            e += d * d;
            r += reference[c][i] * reference[c][i];
        }
    return r > 0 ? std::sqrt(e / r) : std::sqrt(e);
}

// The JSON's peers.petsc: the PETSc version the peers ran with, or why they did not run.
std::string petsc_status(const SolverComparison& comparison) {
    if (!comparison.peers_missing_reason.empty()) return "not run: " + comparison.peers_missing_reason;
#ifdef WAXWORK_HAVE_PETSC
    return petsc_version();
#else
    return "not run: " + petsc_unavailable_reason();
#endif
}

struct Run {
    RunTimes times;
    double error = 1;
};

// A setup rebuilt after its first run (which the caller timed): the median of three more runs, each
// freeing what it built before the next, as an edit does.
double median_rebuild_ms(const std::function<double()>& run_ms) { return median_run_ms(3, run_ms); }

// Calls `run_ms` (which times itself) as the statistic asks and returns its times: `repeats` runs and
// their median, or by default up to three runs while the fastest is under 100 ms, and the fastest.
RunTimes repeated_times(int repeats, const std::function<double()>& run_ms) {
    std::vector<double> samples;
    if (repeats > 0) {
        for (int i = 0; i < repeats; ++i) samples.push_back(run_ms());
        return median_min_max(std::move(samples));
    }
    for (int i = 0; i < 3; ++i) {
        samples.push_back(run_ms());
        if (*std::min_element(samples.begin(), samples.end()) >= 100) break;
    }
    RunTimes times = median_min_max(std::move(samples));
    times.ms = times.min_ms;
    return times;
}

class Measurer {
public:
    Measurer(const Fields& reference, const SolverComparisonOptions& options)
        : reference_(reference), options_(options) {}

    Run run(const CappedSolve& solve, int cap) {
        Run result;
        result.times = repeated_times(options_.repeats, [&] {
            for (size_t c = 0; c < 3; ++c) x_[c].assign(reference_[c].size(), 0.0);
            const auto start = std::chrono::steady_clock::now();
            solve(cap, x_);
            return milliseconds_since(start);
        });
        result.error = relative_error(x_, reference_);
        return result;
    }

    // A setup step (which times itself) measured with the same statistic as the solves.
    double setup(const std::function<double()>& run_ms) const { return repeated_times(options_.repeats, run_ms).ms; }

    SolverCurve curve(const std::string& name, const CappedSolve& solve) {
        const CpuSample cpu_start = sample_cpu_usage();
        SolverCurve out = measure_curve(name, solve);
        const CpuUsage usage = cpu_usage_between(cpu_start, sample_cpu_usage());
        out.parallelism = usage.parallelism;
        out.other_load_cores = usage.other_load_cores;
        return out;
    }

private:
    SolverCurve measure_curve(const std::string& name, const CappedSolve& solve) {
        SolverCurve out;
        out.name = name;
        const auto start = std::chrono::steady_clock::now();
        std::vector<std::pair<int, Run>> runs;  // every cap measured, for the bisection
        // Warm-up, untimed: first-touch page faults and lazy initialisation are not the solver's time.
        for (size_t c = 0; c < 3; ++c) x_[c].assign(reference_[c].size(), 0.0);
        solve(0, x_);
        std::vector<std::pair<double, double>> points;
        std::vector<std::pair<double, double>> ranges;
        int cap = 0;
        double best_error = std::numeric_limits<double>::infinity();
        int stalled = 0;
        for (;;) {
            const Run r = run(solve, cap);
            runs.emplace_back(cap, r);
            points.emplace_back(r.times.ms, r.error);
            ranges.emplace_back(r.times.min_ms, r.times.max_ms);
            // CG minimises the energy norm, not the L2 error this curve measures: from a good start
            // (multires' coarse pass) the first few iterations can leave the L2 error flat or higher,
            // so a stall only counts once the run is past the first 16 iterations.
            stalled = r.error < 0.95 * best_error || cap < 16 ? 0 : stalled + 1;
            best_error = std::min(best_error, r.error);
            if (r.error <= options_.floor_error || stalled >= 4 || cap >= 200000 ||
                milliseconds_since(start) > 1000 * options_.max_seconds)
                break;
            cap = std::max(cap + 1, static_cast<int>(std::ceil(cap * 1.25)));
        }
        // Monotone in time: from the last point backwards, keep a point only if it ran faster than every
        // point kept after it (noise that made a small cap slow drops that point, not the later ones).
        for (size_t i = points.size(); i-- > 0;)
            if (out.curve.empty() || points[i].first < out.curve.back().first) {
                out.curve.push_back(points[i]);
                out.ms_range.push_back(ranges[i]);
            }
        std::reverse(out.curve.begin(), out.curve.end());
        std::reverse(out.ms_range.begin(), out.ms_range.end());
        // Smallest cap reaching the target: bisection between the last cap above it and the first below.
        for (size_t i = 0; i < runs.size(); ++i) {
            if (runs[i].second.error > options_.target_error) continue;
            if (i == 0) {
                out.time_to_target_ms = runs[i].second.times.ms;
                out.time_to_target_range = {runs[i].second.times.min_ms, runs[i].second.times.max_ms};
                out.cap_to_target = runs[i].first;
                break;
            }
            int lo = runs[i - 1].first, hi = runs[i].first;
            Run at_hi = runs[i].second;
            while (hi - lo > 1) {
                const int mid = (lo + hi) / 2;
                const Run r = run(solve, mid);
                if (r.error <= options_.target_error) {
                    hi = mid;
                    at_hi = r;
                } else {
                    lo = mid;
                }
            }
            out.time_to_target_ms = at_hi.times.ms;
            out.time_to_target_range = {at_hi.times.min_ms, at_hi.times.max_ms};
            out.cap_to_target = hi;
            break;
        }
        return out;
    }

    const Fields& reference_;
    const SolverComparisonOptions& options_;
    Fields x_;
};

}  // namespace

SolverComparison compare_solvers(const TetMesh& mesh, const TetConnectivity& connectivity,
                                 const std::vector<TetMaterial>& materials, const Lighting& lighting,
                                 const SolverComparisonOptions& options) {
    if (!(options.target_error > 0) || !(options.floor_error > 0) || !(options.max_seconds > 0))
        throw InvalidArgumentError("solver comparison: target, floor and time limit must be positive");
    AssemblyOptions assembly;
    assembly.mm_per_unit = options.mm_per_unit;
    const DiffusionMatrix matrix = assemble_diffusion_matrix(mesh, connectivity, materials, assembly);
    const std::vector<Rgb> q = incident_light(mesh, connectivity, materials, lighting);
    const size_t n = matrix.size();
    Fields b;
    for (int c = 0; c < 3; ++c) {
        b[static_cast<size_t>(c)].resize(n);
        diffusion_right_hand_side(matrix, q, c, b[static_cast<size_t>(c)]);
    }
    std::array<Eigen::SparseMatrix<double>, 3> sparse;
    for (int c = 0; c < 3; ++c) sparse[static_cast<size_t>(c)] = to_eigen_sparse(matrix, c);
    auto as_eigen = [](const std::vector<double>& v) {
        return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
    };

    // Reference: direct solution plus one refinement step.
    Fields reference;
    for (size_t c = 0; c < 3; ++c) {
        const Eigen::VectorXd x = refined_direct_solution(sparse[c], as_eigen(b[c]));
        reference[c].assign(x.data(), x.data() + x.size());
    }

    SolverComparison result;
    result.tets = mesh.tet_count();
    result.vertices = mesh.vertex_count();
    result.repeats = options.repeats;
    Measurer measurer(reference, options);

    // Jacobi CG in float and double (solver/conjugate_gradient.h).
    std::array<std::vector<float>, 3> values_f;
    Fields b_copy = b;
    std::array<std::vector<float>, 3> b_f;
    for (size_t c = 0; c < 3; ++c) {
        values_f[c].assign(matrix.values[c].begin(), matrix.values[c].end());
        b_f[c].assign(b[c].begin(), b[c].end());
    }
    std::vector<float> x_f(n);
    result.solvers.push_back(measurer.curve("jacobi_cg", [&](int cap, Fields& x) {
        for (size_t c = 0; c < 3; ++c) {
            const CsrMatrixView<float> view{n, matrix.offsets.data(), matrix.columns.data(), values_f[c].data()};
            std::fill(x_f.begin(), x_f.end(), 0.0f);
            solve_jacobi_cg<float>(view, b_f[c], x_f, exact_iteration_count(cap));
            std::copy(x_f.begin(), x_f.end(), x[c].begin());
        }
    }));
    result.solvers.push_back(measurer.curve("jacobi_cg_double", [&](int cap, Fields& x) {
        for (size_t c = 0; c < 3; ++c) {
            const CsrMatrixView<double> view{n, matrix.offsets.data(), matrix.columns.data(), matrix.values[c].data()};
            solve_jacobi_cg<double>(view, b_copy[c], x[c], exact_iteration_count(cap));
        }
    }));

    // The paper's coarse-to-fine scheme (multires_solver.h); cap = level-0 CG iterations.
    MultiresSolver multires(matrix, mesh.positions);
    result.levels = multires.hierarchy().level_count();
    result.hierarchy_ms = multires.hierarchy().build_ms;
    result.hierarchy_rebuild_ms =
        median_rebuild_ms([&] { return build_multires_hierarchy(matrix, mesh.positions).build_ms; });
    result.solvers.push_back(measurer.curve("multires", [&](int cap, Fields& x) {
        MultiresSolveOptions solve;
        solve.relative_tolerance = 1e-15;
        solve.max_iterations = cap;
        for (int c = 0; c < 3; ++c) multires.solve(b_copy[static_cast<size_t>(c)], c, x[static_cast<size_t>(c)], solve);
    }));
    result.solvers.back().setup_ms = result.hierarchy_ms;

    // Multigrid-preconditioned CG on the same hierarchy (multigrid_cg.h).
    MultigridPreconditioner multigrid(multires.hierarchy());
    result.multigrid_setup_ms = multigrid.setup_ms();
    result.multigrid_setup_rebuild_ms =
        median_rebuild_ms([&] { return MultigridPreconditioner(multires.hierarchy()).setup_ms(); });
    result.solvers.push_back(measurer.curve("multigrid_cg", [&](int cap, Fields& x) {
        for (int c = 0; c < 3; ++c)
            solve_multigrid_cg(multigrid, c, b_copy[static_cast<size_t>(c)], x[static_cast<size_t>(c)], exact_iteration_count(cap));
    }));
    result.solvers.back().setup_ms = result.hierarchy_ms + result.multigrid_setup_ms;

    // The paper's coarse-to-fine pass on the multigrid's Galerkin operators (cascadic_solver.h), with
    // its default schedule; cap = level-0 CG iterations. No setup of its own: it borrows `multigrid`'s.
    CascadicSolver cascadic(multigrid);
    result.solvers.push_back(measurer.curve("cascadic_cg", [&](int cap, Fields& x) {
        CascadicOptions solve;
        solve.relative_tolerance = 1e-15;
        solve.max_iterations = cap;
        for (int c = 0; c < 3; ++c) cascadic.solve(b_copy[static_cast<size_t>(c)], c, x[static_cast<size_t>(c)], solve);
    }));
    result.solvers.back().setup_ms = result.hierarchy_ms + result.multigrid_setup_ms;

    // The live editor's frame solver (multigrid_frame_solver.h): the same multigrid CG with the three
    // channels in one pass over interleaved vectors; cap = V-cycles, each followed by one CG update, so
    // cap k gives the iterate of multigrid_cg's cap k. It builds its own hierarchy and Galerkin
    // operators (setup, excluded: multigrid_rgb_setup_ms) and is freed after its curve. Cold start:
    // reset() zeroes phi and forgets the eigenvalue estimates of the previous run.
    {
        FrameSolverOptions frame_options;
        frame_options.relative_tolerance = 1e-15;  // never stop on the estimate: run the cap
        const auto setup_start = std::chrono::steady_clock::now();
        MultigridFrameSolver frame(matrix, mesh.positions, frame_options);
        result.multigrid_rgb_setup_ms = milliseconds_since(setup_start);
        result.multigrid_rgb_setup_rebuild_ms = median_rebuild_ms([&] {
            const auto start = std::chrono::steady_clock::now();
            const MultigridFrameSolver rebuilt(matrix, mesh.positions, frame_options);
            return milliseconds_since(start);
        });
        const std::array<std::span<const double>, 3> rhs{b_copy[0], b_copy[1], b_copy[2]};
        result.solvers.push_back(measurer.curve("multigrid_cg_rgb", [&](int cap, Fields& x) {
            // Cap 0 is the cold start alone (phi = 0; step() needs a budget >= 1), timed like the other
            // solvers' cap 0, which also set up their vectors without updating phi.
            frame.reset();
            frame.set_right_hand_side(rhs);
            if (cap > 0) frame.step(cap);
            for (size_t c = 0; c < 3; ++c) {
                const std::span<const double> phi = frame.phi(static_cast<int>(c));
                std::copy(phi.begin(), phi.end(), x[c].begin());
            }
        }));
        result.solvers.back().setup_ms = result.multigrid_rgb_setup_ms;
    }

    // Eigen's CG with incomplete Cholesky, as solve_eigen_cg_ic (reference_solvers.h) runs it, with the
    // factorisation of each channel done once as setup and the solves reusing it.
    {
        using IcCg = Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                                              Eigen::IncompleteCholesky<double>>;
        std::array<IcCg, 3> ic_cg;
        const double ic_setup_ms = measurer.setup([&] {
            const auto start = std::chrono::steady_clock::now();
            for (size_t c = 0; c < 3; ++c) {
                ic_cg[c].compute(sparse[c]);
                if (ic_cg[c].info() != Eigen::Success)
                    throw AlgorithmError("Eigen CG: incomplete Cholesky factorisation failed");
            }
            return milliseconds_since(start);
        });
        result.solvers.push_back(measurer.curve("eigen_ic_cg", [&](int cap, Fields& x) {
            for (size_t c = 0; c < 3; ++c) {
                ic_cg[c].setTolerance(1e-16);
                ic_cg[c].setMaxIterations(cap);
                const Eigen::VectorXd xc =
                    ic_cg[c].solveWithGuess(as_eigen(b_copy[c]), Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n)));
                if (!xc.allFinite()) throw AlgorithmError("Eigen CG: non-finite solution");
                std::copy(xc.data(), xc.data() + xc.size(), x[c].begin());
            }
        }));
        result.solvers.back().setup_ms = ic_setup_ms;
    }

    // The PETSc peers (solver/petsc_peers.h): CG with GAMG or BoomerAMG on the same matrices; cap = CG
    // iterations per channel, tolerance 0 so that only the cap stops a run.
    // PETSc failing to start (MPI unable to run as a singleton) leaves the peers out with the reason,
    // as the GPU curves are left out without a GPU.
#ifdef WAXWORK_HAVE_PETSC
    for (const PetscPeer peer : {PetscPeer::CgGamg, PetscPeer::CgBoomerAmg}) {
        try {
            PetscPeerSolver solver(matrix, peer);
            PeerSetup setup;
            setup.name = petsc_peer_name(peer);
            setup.conversion_ms = solver.setup_times().conversion_ms;
            setup.preconditioner_ms = solver.setup_times().preconditioner_ms;
            setup.rebuild_ms = median_rebuild_ms([&] {
                solver.rebuild(matrix);
                return solver.setup_times().conversion_ms + solver.setup_times().preconditioner_ms;
            });
            setup.settings = petsc_peer_settings(peer);
            result.solvers.push_back(measurer.curve(setup.name, [&](int cap, Fields& x) {
                PetscSolveOptions solve;
                solve.relative_tolerance = 0;
                solve.max_iterations = cap;
                for (size_t c = 0; c < 3; ++c) solver.solve(static_cast<int>(c), b_copy[c], x[c], solve);
            }));
            result.solvers.back().setup_ms = setup.conversion_ms + setup.preconditioner_ms;
            result.peers.push_back(std::move(setup));
        } catch (const AlgorithmError& e) {
            result.peers_missing_reason = e.what();
            break;
        }
    }
#else
    result.peers_missing_reason = petsc_unavailable_reason();
#endif

    // The GPU path: CG, the multires scheme and the multigrid CG in float on compute shaders, matrices
    // resident (the upload is per-mesh setup, excluded); cap = level-0 CG iterations (V-cycles for the
    // multigrid CG).
    if (options.gl) {
        try {
            auto read_back = [](const std::vector<std::array<double, 3>>& phi, Fields& x) {
                for (size_t i = 0; i < phi.size(); ++i)
                    for (size_t c = 0; c < 3; ++c) x[c][i] = phi[i][c];
            };
            auto setup_start = std::chrono::steady_clock::now();
            GpuDiffusionSolver gpu(*options.gl, matrix);
            const double gpu_cg_setup_ms = milliseconds_since(setup_start);
            gpu.set_right_hand_side(b);
            const std::vector<std::array<double, 3>> zero(n, {0.0, 0.0, 0.0});
            result.solvers.push_back(measurer.curve("gpu_cg", [&](int cap, Fields& x) {
                gpu.set_solution(zero);
                GpuCgOptions cg;
                cg.relative_tolerance = 1e-15;
                cg.max_iterations = cap;
                gpu.solve(cg);
                read_back(gpu.solution(), x);
            }));
            result.solvers.back().setup_ms = gpu_cg_setup_ms;
            setup_start = std::chrono::steady_clock::now();
            GpuMultiresSolver gpu_multires(*options.gl, matrix, multires.hierarchy());
            const double gpu_multires_setup_ms = result.hierarchy_ms + milliseconds_since(setup_start);
            gpu_multires.set_right_hand_side(b);
            result.solvers.push_back(measurer.curve("gpu_multires", [&](int cap, Fields& x) {
                MultiresSolveOptions solve;
                solve.relative_tolerance = 1e-15;
                solve.max_iterations = cap;
                gpu_multires.solve(solve);
                read_back(gpu_multires.solution(), x);
            }));
            result.solvers.back().setup_ms = gpu_multires_setup_ms;
            // The multigrid CG on the device (gpu_multigrid_frame_solver.h), as multigrid_cg_rgb: cap =
            // V-cycles from phi = 0; its own hierarchy and levels are setup (excluded).
            FrameSolverOptions frame_options;
            frame_options.relative_tolerance = 1e-15;  // never stop on the estimate: run the cap
            setup_start = std::chrono::steady_clock::now();
            GpuMultigridFrameSolver gpu_multigrid(*options.gl, matrix, mesh.positions, frame_options);
            const double gpu_multigrid_setup_ms = milliseconds_since(setup_start);
            const std::array<std::span<const double>, 3> rhs{b[0], b[1], b[2]};
            result.solvers.push_back(measurer.curve("gpu_multigrid_cg", [&](int cap, Fields& x) {
                gpu_multigrid.reset();
                gpu_multigrid.set_right_hand_side(rhs);
                if (cap > 0) gpu_multigrid.step(cap);
                x = gpu_multigrid.phi();
            }));
            result.solvers.back().setup_ms = gpu_multigrid_setup_ms;
        } catch (const GpuError& e) {
            result.gpu_fallback_reason = e.what();
        }
    }

    // Direct: one point, the solves; the factorisation is its setup. One channel at a time, each
    // factorisation freed before the next (three large factors need not fit at once); a run's setup and
    // solve times are each summed over the channels.
    SolverCurve direct;
    direct.name = "direct";
    Fields x_direct;
    std::vector<double> factor_samples;
    const CpuSample direct_cpu_start = sample_cpu_usage();
    const RunTimes solve_times = repeated_times(options.repeats, [&] {
        double factor_ms = 0, solve_ms = 0;
        for (size_t c = 0; c < 3; ++c) {
            const auto factor_start = std::chrono::steady_clock::now();
            const DirectSolver solver(sparse[c]);
            factor_ms += milliseconds_since(factor_start);
            const auto solve_start = std::chrono::steady_clock::now();
            const Eigen::VectorXd xc = solver.solve(as_eigen(b_copy[c]));
            solve_ms += milliseconds_since(solve_start);
            x_direct[c].assign(xc.data(), xc.data() + xc.size());
        }
        factor_samples.push_back(factor_ms);
        return solve_ms;
    });
    const CpuUsage direct_usage = cpu_usage_between(direct_cpu_start, sample_cpu_usage());
    direct.parallelism = direct_usage.parallelism;
    direct.other_load_cores = direct_usage.other_load_cores;
    const RunTimes factor_times = median_min_max(factor_samples);
    direct.setup_ms = options.repeats > 0 ? factor_times.ms : factor_times.min_ms;
    const double direct_error = relative_error(x_direct, reference);
    direct.curve.emplace_back(solve_times.ms, direct_error);
    direct.ms_range.emplace_back(solve_times.min_ms, solve_times.max_ms);
    if (direct_error <= options.target_error) {
        direct.time_to_target_ms = solve_times.ms;
        direct.time_to_target_range = {solve_times.min_ms, solve_times.max_ms};
    }
    result.solvers.push_back(std::move(direct));
    return result;
}

std::string busy_machine_warning(const SolverComparison& comparison) {
    std::string busy;
    char entry[96];
    for (const SolverCurve& s : comparison.solvers)
        if (s.other_load_cores > kBusyMachineCores) {
            std::snprintf(entry, sizeof entry, "%s%s (%.2f)", busy.empty() ? "" : ", ", s.name.c_str(), s.other_load_cores);
            busy += entry;
        }
    if (busy.empty()) return "";
    return "the machine was busy during these solvers' measurements, so their times may be slow and noisy (cores "
           "other processes kept busy on average): " + busy;
}

std::string missing_peers_warning(const SolverComparison& comparison) {
    return comparison.peers_missing_reason.empty() ? "" : "PETSc peer rows missing: " + comparison.peers_missing_reason;
}

std::vector<std::pair<std::string, double>> setup_times(const SolverComparison& comparison) {
    return {{"hierarchy_ms", comparison.hierarchy_ms},
            {"hierarchy_rebuild_ms", comparison.hierarchy_rebuild_ms},
            {"multigrid_setup_ms", comparison.multigrid_setup_ms},
            {"multigrid_setup_rebuild_ms", comparison.multigrid_setup_rebuild_ms},
            {"multigrid_rgb_setup_ms", comparison.multigrid_rgb_setup_ms},
            {"multigrid_rgb_setup_rebuild_ms", comparison.multigrid_rgb_setup_rebuild_ms}};
}

std::string timing_statistic(int repeats) {
    if (repeats <= 0) return "fastest of 3 runs (runs over 100 ms: one run) after one warm-up";
    if (repeats == 1) return "one run after one warm-up";
    return "median of " + std::to_string(repeats) + " runs after one warm-up";
}

std::string solver_chart_caption(const SolverComparison& comparison, const nlohmann::ordered_json& provenance) {
    std::string caption = provenance_caption(provenance) + " | times: " + timing_statistic(comparison.repeats);
    const std::string gpu_renderer = provenance.at("machine").at("opengl_renderer").get<std::string>();
    const bool gpu_ran = std::any_of(comparison.solvers.begin(), comparison.solvers.end(),
                                     [](const SolverCurve& s) { return s.name.rfind("gpu_", 0) == 0; });
    if (gpu_ran && gpu_renderer.find("llvmpipe") != std::string::npos)
        caption += " | GPU curves: software GPU (llvmpipe)";
    else if (gpu_ran && !gpu_renderer.empty())
        caption += " | GPU curves: " + gpu_renderer;
    return caption;
}

nlohmann::ordered_json solver_comparison_definitions(const SolverComparisonOptions& options) {
    return {
        {"error", "relative L2 error of phi over every vertex and the three channels: ||phi - phi_ref||_2 / "
                  "||phi_ref||_2 (unweighted sums)"},
        {"reference", std::string("direct solve of each channel in double (") +
                          (DirectSolver::backend() == "cholmod-supernodal" ? "CHOLMOD supernodal Cholesky"
                                                                           : "Eigen SimplicialLDLT") +
                          ") plus one step of iterative refinement"},
        {"curve", "each iterative solver runs from a cold start (phi = 0; multires: its coarse-to-fine pass) with "
                  "an increasing cap (0, 1, 2, then growing by a quarter), all three channels per run; a point is "
                  "(time of that run, its error); a point slower than a later one is dropped"},
        {"cap", "jacobi_cg, jacobi_cg_double, eigen_ic_cg, petsc_cg_gamg, petsc_cg_boomeramg, gpu_cg: CG iterations "
                "per channel; multires, cascadic_cg, "
                "gpu_multires: level-0 CG iterations after the coarse levels; multigrid_cg: V-cycle-preconditioned CG "
                "iterations; multigrid_cg_rgb, gpu_multigrid_cg: V-cycles (three channels at once)"},
        {"stopping_rule", "a curve ends when its error falls below floor_error, when four caps in a row past cap 16 "
                          "cut the error by less than 5%, at cap 200000, or after max_seconds of measuring"},
        {"target_error", options.target_error},
        {"floor_error", options.floor_error},
        {"max_seconds", options.max_seconds},
        {"time_to_1pct_ms", "the smallest cap reaching target_error (bisection between the measured caps), timed "
                            "again; null when not reached"},
        {"cap_to_1pct", "that cap, in the solver's cap unit"},
        {"times", "milliseconds of wall clock for all three channels, solve only; statistic: " +
                      timing_statistic(options.repeats)},
        {"setup_ms", "per solver, milliseconds of per-mesh setup not in its curve (hierarchy, Galerkin operators, "
                     "incomplete or direct factorisation, GPU uploads, PETSc's matrix conversion and AMG setup); "
                     "setup + solve = setup_ms + a point's time"},
        {"peers", "petsc_cg_gamg, petsc_cg_boomeramg: CG (unpreconditioned residual norm) with PETSc's GAMG or hypre's "
                  "BoomerAMG through PETSc, one process and one thread; setup_ms: first build (the three channels "
                  "converted to AIJ, then the three preconditioners set up; PETSc and MPI start-up excluded); "
                  "setup_rebuild_ms: median of three rebuilds (the same values copied in again, the preconditioners "
                  "set up from scratch); settings: the PETSc options"},
        {"parallelism", "per solver, this process's CPU seconds per wall second over all of its measurements"},
        {"other_load_cores", "per solver, the cores other processes kept busy on average during its measurements"},
    };
}

void write_solver_comparison(const std::filesystem::path& dir, const std::string& stem, const ComparedScene& scene,
                             const SolverComparison& comparison, const nlohmann::ordered_json& provenance,
                             const SolverChartOptions& chart_options) {
    using Json = nlohmann::ordered_json;
    Json solvers = Json::object();
    std::vector<ChartSeries> series;
    for (const SolverCurve& s : comparison.solvers) {
        Json curve = Json::array(), curve_min = Json::array(), curve_max = Json::array();
        for (const auto& [ms, error] : s.curve) curve.push_back({ms, error});
        for (const auto& [lo, hi] : s.ms_range) {
            curve_min.push_back(lo);
            curve_max.push_back(hi);
        }
        const Json time = s.time_to_target_ms ? Json(*s.time_to_target_ms) : nullptr;
        const Json time_min = s.time_to_target_ms ? Json(s.time_to_target_range.first) : nullptr;
        const Json time_max = s.time_to_target_ms ? Json(s.time_to_target_range.second) : nullptr;
        const Json cap = s.cap_to_target ? Json(*s.cap_to_target) : nullptr;
        solvers[s.name] = {{"time_to_1pct_ms", time},
                           {"time_to_1pct_ms_min", time_min},
                           {"time_to_1pct_ms_max", time_max},
                           {"cap_to_1pct", cap},
                           {"setup_ms", s.setup_ms},
                           {"setup_plus_time_to_1pct_ms", s.time_to_target_ms ? Json(s.setup_ms + *s.time_to_target_ms) : Json(nullptr)},
                           {"parallelism", s.parallelism},
                           {"other_load_cores", s.other_load_cores},
                           {"curve", curve},
                           {"curve_ms_min", curve_min},
                           {"curve_ms_max", curve_max}};

        // The chart: solve time, or setup + solve when asked.
        const double shift = chart_options.include_setup ? s.setup_ms : 0;
        ChartSeries line;
        line.method = s.name;
        for (const auto& [ms, error] : s.curve) line.points.emplace_back(ms + shift, error);
        if (comparison.repeats > 1)
            for (const auto& [lo, hi] : s.ms_range) line.x_spread.emplace_back(lo + shift, hi + shift);
        if (s.name == "direct") {
            // Exact to rounding: a marker on the bottom edge with its true error, not an axis down to 1e-16.
            if (DirectSolver::backend() != "cholmod-supernodal") line.name = "Eigen LDLT direct";
            line.pinned_to_bottom = true;
            if (!s.curve.empty()) {
                char label[160];
                std::snprintf(label, sizeof label, "%s: %.3g ms%s, error %.1e",
                              line.name.empty() ? "CHOLMOD direct" : line.name.c_str(), s.curve[0].first + shift,
                              chart_options.include_setup ? " with factorisation" : " solve", s.curve[0].second);
                line.pin_label = label;
            }
        }
        series.push_back(std::move(line));
    }
    Json json = {
        {"provenance", provenance},
        {"mesh", scene.mesh},
        {"material", scene.material},
        {"mm_per_unit", scene.mm_per_unit},
        {"tets", comparison.tets},
        {"vertices", comparison.vertices},
        {"levels", comparison.levels},
    };
    for (const auto& [key, ms] : setup_times(comparison)) json[key] = ms;
    json["statistic"] = timing_statistic(comparison.repeats);
    json["repeats"] = comparison.repeats;
    json["solvers"] = solvers;
    Json peers = {{"petsc", petsc_status(comparison)}};
    for (const PeerSetup& peer : comparison.peers) {
        Json settings = Json::object();
        for (const auto& [key, value] : peer.settings) settings[key] = value;
        peers[peer.name] = {{"setup_ms", peer.conversion_ms + peer.preconditioner_ms},
                            {"setup_rebuild_ms", peer.rebuild_ms},
                            {"conversion_ms", peer.conversion_ms},
                            {"preconditioner_setup_ms", peer.preconditioner_ms},
                            {"settings", settings}};
    }
    json["peers"] = peers;
    write_file_atomically(dir / (stem + ".json"), [&](std::ostream& out) { out << json.dump(2) << "\n"; });

    ChartOptions chart;
    chart.title = "Diffusion solvers on " + std::filesystem::path(scene.mesh).filename().string() + " (" +
                  scene.material + "), " + std::to_string(comparison.tets) + " tets (3 channels)" +
                  (chart_options.quick ? " (quick run)" : "");
    // Log time: direct is orders of magnitude slower.
    chart.x = {chart_options.include_setup ? "setup + solve time (ms, log scale)" : "solve time (ms, log scale; setup excluded)",
               AxisScale::Log, 0, 0};
    chart.y = {"relative L2 error of phi vs direct reference", AxisScale::Log, 0, 0};
    chart.target_line = 1e-2;
    chart.target_label = "1% error";
    chart.caption = solver_chart_caption(comparison, provenance);
    write_svg_chart(dir / (stem + ".svg"), series, chart);
}

std::unique_ptr<HeadlessGlContext> open_gpu_for_comparison(SolverComparisonOptions& options) {
    try {
        auto context = std::make_unique<HeadlessGlContext>();
        options.gl = &context->gl();
        return context;
    } catch (const Error& e) {
        std::cerr << "warning: no GPU curves: " << e.what() << "\n";
        return nullptr;
    }
}

}  // namespace waxwork
