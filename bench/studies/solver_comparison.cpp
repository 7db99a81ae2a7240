#include "bench/studies/solver_comparison.h"

#include "base/error.h"
#include "base/timing.h"
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
#include "solver/reference/reference_solvers.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
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

struct Run {
    double ms = 0, error = 1;
};

// A setup rebuilt after its first run (which the caller timed): the median of three more runs, each
// freeing what it built before the next, as an edit does.
double median_rebuild_ms(const std::function<double()>& run_ms) { return median_run_ms(3, run_ms); }

class Measurer {
public:
    Measurer(const Fields& reference, const SolverComparisonOptions& options)
        : reference_(reference), options_(options) {}

    Run run(const CappedSolve& solve, int cap) {
        Run best;
        best.ms = std::numeric_limits<double>::infinity();
        for (int repeat = 0; repeat < 3; ++repeat) {
            for (size_t c = 0; c < 3; ++c) x_[c].assign(reference_[c].size(), 0.0);
            const auto start = std::chrono::steady_clock::now();
            solve(cap, x_);
            best.ms = std::min(best.ms, milliseconds_since(start));
            if (best.ms >= 100) break;
        }
        best.error = relative_error(x_, reference_);
        return best;
    }

    SolverCurve curve(const std::string& name, const CappedSolve& solve) {
        SolverCurve out;
        out.name = name;
        const auto start = std::chrono::steady_clock::now();
        std::vector<std::pair<int, Run>> runs;  // every cap measured, for the bisection
        run(solve, 0);  // warm-up: first-touch page faults and lazy initialisation are not the solver's time
        std::vector<std::pair<double, double>> points;
        int cap = 0;
        double best_error = std::numeric_limits<double>::infinity();
        int stalled = 0;
        for (;;) {
            const Run r = run(solve, cap);
            runs.emplace_back(cap, r);
            points.emplace_back(r.ms, r.error);
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
            if (out.curve.empty() || points[i].first < out.curve.back().first) out.curve.push_back(points[i]);
        std::reverse(out.curve.begin(), out.curve.end());
        // Smallest cap reaching the target: bisection between the last cap above it and the first below.
        for (size_t i = 0; i < runs.size(); ++i) {
            if (runs[i].second.error > options_.target_error) continue;
            if (i == 0) {
                out.time_to_target_ms = runs[i].second.ms;
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
            out.time_to_target_ms = at_hi.ms;
            out.cap_to_target = hi;
            break;
        }
        return out;
    }

private:
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

    // Multigrid-preconditioned CG on the same hierarchy (multigrid_cg.h).
    MultigridPreconditioner multigrid(multires.hierarchy());
    result.multigrid_setup_ms = multigrid.setup_ms();
    result.multigrid_setup_rebuild_ms =
        median_rebuild_ms([&] { return MultigridPreconditioner(multires.hierarchy()).setup_ms(); });
    result.solvers.push_back(measurer.curve("multigrid_cg", [&](int cap, Fields& x) {
        for (int c = 0; c < 3; ++c)
            solve_multigrid_cg(multigrid, c, b_copy[static_cast<size_t>(c)], x[static_cast<size_t>(c)], exact_iteration_count(cap));
    }));

    // The paper's coarse-to-fine pass on the multigrid's Galerkin operators (cascadic_solver.h), with
    // its default schedule; cap = level-0 CG iterations. No setup of its own: it borrows `multigrid`'s.
    CascadicSolver cascadic(multigrid);
    result.solvers.push_back(measurer.curve("cascadic_cg", [&](int cap, Fields& x) {
        CascadicOptions solve;
        solve.relative_tolerance = 1e-15;
        solve.max_iterations = cap;
        for (int c = 0; c < 3; ++c) cascadic.solve(b_copy[static_cast<size_t>(c)], c, x[static_cast<size_t>(c)], solve);
    }));

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
    }

    // Eigen's CG with incomplete Cholesky (reference_solvers.h); factorised in every run.
    result.solvers.push_back(measurer.curve("eigen_ic_cg", [&](int cap, Fields& x) {
        for (size_t c = 0; c < 3; ++c) {
            Eigen::VectorXd xc = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
            solve_eigen_cg_ic(sparse[c], as_eigen(b_copy[c]), xc, 1e-16, cap);
            std::copy(xc.data(), xc.data() + xc.size(), x[c].begin());
        }
    }));

    // The GPU path: CG, the multires scheme and the multigrid CG in float on compute shaders, matrices
    // resident (the upload is per-mesh setup, excluded); cap = level-0 CG iterations (V-cycles for the
    // multigrid CG).
    if (options.gl) {
        try {
            auto read_back = [](const std::vector<std::array<double, 3>>& phi, Fields& x) {
                for (size_t i = 0; i < phi.size(); ++i)
                    for (size_t c = 0; c < 3; ++c) x[c][i] = phi[i][c];
            };
            GpuDiffusionSolver gpu(*options.gl, matrix);
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
            GpuMultiresSolver gpu_multires(*options.gl, matrix, multires.hierarchy());
            gpu_multires.set_right_hand_side(b);
            result.solvers.push_back(measurer.curve("gpu_multires", [&](int cap, Fields& x) {
                MultiresSolveOptions solve;
                solve.relative_tolerance = 1e-15;
                solve.max_iterations = cap;
                gpu_multires.solve(solve);
                read_back(gpu_multires.solution(), x);
            }));
            // The multigrid CG on the device (gpu_multigrid_frame_solver.h), as multigrid_cg_rgb: cap =
            // V-cycles from phi = 0; its own hierarchy and levels are setup (excluded).
            FrameSolverOptions frame_options;
            frame_options.relative_tolerance = 1e-15;  // never stop on the estimate: run the cap
            GpuMultigridFrameSolver gpu_multigrid(*options.gl, matrix, mesh.positions, frame_options);
            const std::array<std::span<const double>, 3> rhs{b[0], b[1], b[2]};
            result.solvers.push_back(measurer.curve("gpu_multigrid_cg", [&](int cap, Fields& x) {
                gpu_multigrid.reset();
                gpu_multigrid.set_right_hand_side(rhs);
                if (cap > 0) gpu_multigrid.step(cap);
                x = gpu_multigrid.phi();
            }));
        } catch (const GpuError& e) {
            result.gpu_fallback_reason = e.what();
        }
    }

    // Direct: one point, factorisation and solve.
    SolverCurve direct;
    direct.name = "direct";
    const Run r = measurer.run(
        [&](int, Fields& x) {
            for (size_t c = 0; c < 3; ++c) {
                const DirectSolver solver(sparse[c]);
                const Eigen::VectorXd xc = solver.solve(as_eigen(b_copy[c]));
                std::copy(xc.data(), xc.data() + xc.size(), x[c].begin());
            }
        },
        0);
    direct.curve.emplace_back(r.ms, r.error);
    if (r.error <= options.target_error) direct.time_to_target_ms = r.ms;
    result.solvers.push_back(std::move(direct));
    return result;
}

std::vector<std::pair<std::string, double>> setup_times(const SolverComparison& comparison) {
    return {{"hierarchy_ms", comparison.hierarchy_ms},
            {"hierarchy_rebuild_ms", comparison.hierarchy_rebuild_ms},
            {"multigrid_setup_ms", comparison.multigrid_setup_ms},
            {"multigrid_setup_rebuild_ms", comparison.multigrid_setup_rebuild_ms},
            {"multigrid_rgb_setup_ms", comparison.multigrid_rgb_setup_ms},
            {"multigrid_rgb_setup_rebuild_ms", comparison.multigrid_rgb_setup_rebuild_ms}};
}

void write_solver_comparison(const std::filesystem::path& dir, const std::string& stem, const ComparedScene& scene,
                             const SolverComparison& comparison) {
    nlohmann::ordered_json solvers = nlohmann::ordered_json::object();
    std::vector<ChartSeries> series;
    for (const SolverCurve& s : comparison.solvers) {
        nlohmann::ordered_json curve = nlohmann::ordered_json::array();
        for (const auto& [ms, error] : s.curve) curve.push_back({ms, error});
        const nlohmann::ordered_json time = s.time_to_target_ms ? nlohmann::ordered_json(*s.time_to_target_ms) : nullptr;
        const nlohmann::ordered_json cap = s.cap_to_target ? nlohmann::ordered_json(*s.cap_to_target) : nullptr;
        solvers[s.name] = {{"time_to_1pct_ms", time}, {"cap_to_1pct", cap}, {"curve", curve}};
        ChartSeries line{s.name, {}, true};
        // A direct solution can be exact to the last bit; draw it at 1e-16 rather than not at all.
        for (const auto& [ms, error] : s.curve) line.points.emplace_back(ms, std::max(error, 1e-16));
        series.push_back(std::move(line));
    }
    nlohmann::ordered_json json = {
        {"mesh", scene.mesh},
        {"material", scene.material},
        {"mm_per_unit", scene.mm_per_unit},
        {"tets", comparison.tets},
        {"vertices", comparison.vertices},
        {"levels", comparison.levels},
    };
    for (const auto& [key, ms] : setup_times(comparison)) json[key] = ms;
    json["solvers"] = solvers;
    write_file_atomically(dir / (stem + ".json"), [&](std::ostream& out) { out << json.dump(2) << "\n"; });

    ChartOptions chart;
    chart.title = "Diffusion solvers on " + std::filesystem::path(scene.mesh).filename().string() + " (" +
                  scene.material + "), " + std::to_string(comparison.tets) + " tets (3 channels)";
    chart.x = {"solve time (ms, log scale)", AxisScale::Log, 0, 0};  // direct is orders of magnitude slower
    chart.y = {"relative L2 error of phi vs direct reference", AxisScale::Log, 0, 0};
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
