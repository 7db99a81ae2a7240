// The independent-set multi-resolution solver (multires/, Li et al. 2013 Sec. 4) against plain Jacobi
// CG on spot (bench::spot_volume) at ~50K and ~500K tets: hierarchy build time, and the time for one
// channel (green) to reach a true relative error of 1% against the direct solution (Fig. 7's measure).
//
// "To 1%": for each solver (and intermediate-level budget) the smallest level-0 CG iteration count whose result is within 1% of the
// direct solution is found once (doubling, then bisection) and then timed; the multires time includes
// the coarse-to-fine pass but not the hierarchy build (reported separately, and together in
// BM_MultiresBuildAndSolve: what a frame after a cut pays). Marble (the longest diffusion length of the
// presets), lit from +z as in solver_bench.cpp. Wall and process CPU time are both reported: the
// machine may be shared.
//
// Also: MG-CG (multigrid_cg.h) to 1% and its setup, the three-channel frame solver to 1% from cold
// (BM_MultigridCgFrameTo1Percent), a 10-degree light turn per frame (BM_LightTurn10Degrees) and the
// updates after painting (BM_PaintUpdate); see each benchmark.
//
// Run: build-bench/bench/multires_bench (configure with -DWAXWORK_BUILD_BENCH=ON).
#include "multires/cascadic_solver.h"
#include "multires/multigrid_cg.h"
#include "multires/multigrid_frame_solver.h"
#include "multires/multires_solver.h"
#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "solver/reference/reference_solvers.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/fracture.h"
#include "bench_main.h"
#include "bench_meshes.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <numeric>
#include <tuple>

namespace waxwork {
namespace {

struct Scene {
    const TetMesh* mesh = nullptr;
    TetConnectivity conn;
    DiffusionMatrix matrix;
    std::vector<double> b;      // green channel
    Eigen::VectorXd exact;      // direct solution, green channel
    int cg_iterations = 0;      // Jacobi CG iterations to 1%
};

double relative_error(std::span<const double> x, const Eigen::VectorXd& ref) {
    return (Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size())) - ref).norm() / ref.norm();
}

// Smallest k in [0, limit] with error(k) <= 1e-2 (error assumed non-increasing in k).
int smallest_budget(const std::function<double(int)>& error, int limit) {
    if (error(0) <= 1e-2) return 0;
    int hi = 1;
    while (hi < limit && error(hi) > 1e-2) hi *= 2;
    int lo = hi / 2;  // error(lo) > 1e-2
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        (error(mid) <= 1e-2 ? hi : lo) = mid;
    }
    return hi;
}

ConjugateGradientOptions fixed_budget(int iterations) {
    ConjugateGradientOptions options;
    options.relative_tolerance = 1e-14;  // never stop on the estimate: run exactly the budget
    options.max_iterations = iterations;
    return options;
}

// A benchmark argument naming Eq. 16's weights: 0 the paper's inverse edge lengths, 1 linear-exact
// (hierarchy.h).
InterpolationWeights weights_argument(int64_t argument) {
    return argument != 0 ? InterpolationWeights::LinearExact : InterpolationWeights::InverseEdgeLength;
}

// The scene's hierarchy with the weights a benchmark argument names.
MultiresHierarchy scene_hierarchy(const Scene& s, int64_t weights) {
    HierarchyOptions options;
    options.weights = weights_argument(weights);
    return build_multires_hierarchy(s.matrix, s.mesh->positions, options);
}

std::unique_ptr<MultiresSolver> make_solver(const Scene& s, int64_t weights = 0) {
    HierarchyOptions options;
    options.weights = weights_argument(weights);
    return std::make_unique<MultiresSolver>(s.matrix, s.mesh->positions, options);
}

MultiresSolveOptions multires_budget(int iterations, int level_iterations) {
    MultiresSolveOptions options;
    options.relative_tolerance = 1e-14;
    options.max_iterations = iterations;
    options.level_max_iterations = level_iterations;
    return options;
}

const Scene& scene(size_t target_tets);

// Level-0 iterations after the coarse-to-fine pass to reach 1%, per (size, intermediate-level budget,
// weights).
int multires_iterations(size_t target_tets, int level_iterations, int64_t weights = 0) {
    static std::map<std::tuple<size_t, int, int64_t>, int> cache;
    auto [it, inserted] = cache.try_emplace({target_tets, level_iterations, weights}, 0);
    if (!inserted) return it->second;
    const Scene& s = scene(target_tets);
    auto solver = make_solver(s, weights);
    std::vector<double> x(s.b.size());
    it->second = smallest_budget(
        [&](int k) {
            solver->solve(s.b, 1, x, multires_budget(k, level_iterations));
            return relative_error(x, s.exact);
        },
        100000);
    std::fprintf(stderr, "spot %zu: levels", s.mesh->tet_count());
    for (const auto& level : solver->hierarchy().levels) std::fprintf(stderr, " %zu", level.size());
    std::fprintf(stderr, "; %d iterations per intermediate level: %d level-0 iterations to 1%%\n", level_iterations,
                 it->second);
    return it->second;
}

const Scene& scene(size_t target_tets) {
    static std::map<size_t, std::unique_ptr<Scene>> cache;
    auto& slot = cache[target_tets];
    if (slot) return *slot;
    slot = std::make_unique<Scene>();
    Scene& s = *slot;
    const bench::LitSpot& lit = bench::lit_spot(target_tets);
    s.mesh = &lit.mesh;
    s.conn = lit.conn;
    s.matrix = lit.matrix;
    const std::vector<std::array<double, 3>>& q = lit.q;
    s.b.resize(s.matrix.size());
    diffusion_right_hand_side(s.matrix, q, 1, s.b);
    const Eigen::Map<const Eigen::VectorXd> bm(s.b.data(), static_cast<Eigen::Index>(s.b.size()));
    s.exact = DirectSolver(to_eigen_sparse(s.matrix, 1)).solve(bm);

    const CsrMatrixView<double> view{s.matrix.size(), s.matrix.offsets.data(), s.matrix.columns.data(),
                                     s.matrix.values[1].data()};
    std::vector<double> x(s.b.size());
    s.cg_iterations = smallest_budget(
        [&](int k) {
            std::fill(x.begin(), x.end(), 0.0);
            solve_jacobi_cg<double>(view, s.b, x, fixed_budget(k));
            return relative_error(x, s.exact);
        },
        100000);
    std::fprintf(stderr, "spot: %zu tets, %zu vertices; to 1%%: Jacobi CG %d iterations\n", s.mesh->tet_count(),
                 s.mesh->vertex_count(), s.cg_iterations);
    return s;
}

void BM_MultiresBuild(benchmark::State& state) {
    const Scene& s = scene(static_cast<size_t>(state.range(0)));
    size_t levels = 0, coarse = 0;
    HierarchyBuildTimes times;
    for (auto _ : state) {
        const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh->positions);
        levels = h.level_count();
        coarse = h.levels.back().size();
        times = h.build_times;
    }
    state.counters["tets"] = static_cast<double>(s.mesh->tet_count());
    state.counters["levels"] = static_cast<double>(levels);
    state.counters["coarsest"] = static_cast<double>(coarse);
    // The last build's phases (HierarchyBuildTimes), in ms.
    state.counters["fine_ms"] = times.fine_level;
    state.counters["select_ms"] = times.selection;
    state.counters["interp_ms"] = times.interpolation;
    state.counters["graph_ms"] = times.coarse_graph;
    state.counters["eq17_ms"] = times.coarse_matrix;
}

// spot after an edit, with the scene's hierarchy before it and the edited system's direct solution.
// Edit 0: the editor benches' middle plane cut (bench::middle_cut's; removal only: its relaxation moves
// vertices but changes no edge). Edit 1: an exact Voronoi fracture into 5 cells (scatter_fracture_seeds,
// seed 1), whose crack walls cross the whole volume.
struct EditScene {
    TetMesh mesh;
    std::unique_ptr<bench::LitSpot> lit;
    std::vector<int32_t> new_of_old;  // the edit's vertex map
    std::vector<double> b;            // green channel
    Eigen::VectorXd exact;
    MultiresHierarchy before;         // the unedited scene's hierarchy
};

const EditScene& edit_scene(size_t target_tets, int64_t edit) {
    static std::map<std::pair<size_t, int64_t>, std::unique_ptr<EditScene>> cache;
    auto& slot = cache[{target_tets, edit}];
    if (slot) return *slot;
    slot = std::make_unique<EditScene>();
    EditScene& c = *slot;
    const Scene& s = scene(target_tets);
    c.before = build_multires_hierarchy(s.matrix, s.mesh->positions);
    c.mesh = *s.mesh;
    if (edit == 0) {
        const auto box = bounding_box(c.mesh);
        const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 0.3, 0.2).normalized();
        c.new_of_old = remove_cut_away_tets(c.mesh, PlaneCut(normal, normal.dot(0.5 * (box[0] + box[1])))).old_to_new_vertex;
    } else {
        const size_t vertices_before = c.mesh.vertex_count();
        fracture_voronoi(c.mesh, scatter_fracture_seeds(c.mesh, 5, 1));
        c.new_of_old.resize(vertices_before);  // a fracture keeps every vertex's index (fracture.h)
        std::iota(c.new_of_old.begin(), c.new_of_old.end(), 0);
    }
    c.lit = bench::light_spot_volume(c.mesh, bench::lit_spot(target_tets).mm_per_unit);
    c.b.resize(c.lit->matrix.size());
    diffusion_right_hand_side(c.lit->matrix, c.lit->q, 1, c.b);
    const Eigen::Map<const Eigen::VectorXd> bm(c.b.data(), static_cast<Eigen::Index>(c.b.size()));
    c.exact = DirectSolver(to_eigen_sparse(c.lit->matrix, 1)).solve(bm);
    return c;
}

// The hierarchy after an edit (third argument: 0 the cut, 1 the fracture): built from scratch (second
// argument 0) or rebuilt from the hierarchy before it (1, rebuild_multires_hierarchy: the selection
// is made again only around the changed rows). Times the build; then reports the level sizes and the
// level-0 CG iterations the coarse-to-fine solve needs to 1% with that hierarchy (the rebuilt
// selection is not the fresh one, so its quality is measured, not assumed).
void BM_HierarchyAfterEdit(benchmark::State& state) {
    const EditScene& c = edit_scene(static_cast<size_t>(state.range(0)), state.range(2));
    const bool rebuild = state.range(1) != 0;
    MultiresHierarchy h;
    for (auto _ : state) {
        h = rebuild ? rebuild_multires_hierarchy(c.before, c.new_of_old, c.lit->matrix, c.mesh.positions)
                    : build_multires_hierarchy(c.lit->matrix, c.mesh.positions);
    }
    state.counters["tets"] = static_cast<double>(c.mesh.tet_count());
    state.counters["levels"] = static_cast<double>(h.level_count());
    state.counters["level1"] = static_cast<double>(h.levels.size() > 1 ? h.levels[1].size() : 0);
    state.counters["changed0"] = static_cast<double>(h.levels[0].changed_vertices);
    state.counters["select_ms"] = h.build_times.selection;
    std::fprintf(stderr, "spot %zu after the %s, %s: levels (vertices/changed)", c.mesh.tet_count(),
                 state.range(2) == 0 ? "cut" : "fracture", rebuild ? "rebuilt" : "fresh");
    for (const HierarchyLevel& level : h.levels)
        std::fprintf(stderr, " %zu/%lld", level.size(), static_cast<long long>(level.changed_vertices));
    const HierarchyBuildTimes& t = h.build_times;
    std::fprintf(stderr, "; ms: fine %.1f, selection %.1f, Eq. 16 %.1f, graphs %.1f, Eq. 17 %.1f\n", t.fine_level,
                 t.selection, t.interpolation, t.coarse_graph, t.coarse_matrix);
    MultiresSolver solver(std::move(h));
    std::vector<double> x(c.b.size());
    state.counters["iters0"] = smallest_budget(
        [&](int k) {
            solver.solve(c.b, 1, x, multires_budget(k, 2));
            return relative_error(x, c.exact);
        },
        100000);
}

void BM_JacobiCgTo1Percent(benchmark::State& state) {
    const Scene& s = scene(static_cast<size_t>(state.range(0)));
    const CsrMatrixView<double> view{s.matrix.size(), s.matrix.offsets.data(), s.matrix.columns.data(),
                                     s.matrix.values[1].data()};
    std::vector<double> x(s.b.size());
    for (auto _ : state) {
        std::fill(x.begin(), x.end(), 0.0);
        solve_jacobi_cg<double>(view, s.b, x, fixed_budget(s.cg_iterations));
    }
    state.counters["iters"] = s.cg_iterations;
    state.counters["true_err"] = relative_error(x, s.exact);
}

void BM_MultiresTo1Percent(benchmark::State& state) {
    const Scene& s = scene(static_cast<size_t>(state.range(0)));
    const int level_iterations = static_cast<int>(state.range(1));
    const int iterations = multires_iterations(static_cast<size_t>(state.range(0)), level_iterations, state.range(2));
    auto solver = make_solver(s, state.range(2));
    std::vector<double> x(s.b.size());
    MultiresSolveReport report;
    for (auto _ : state) report = solver->solve(s.b, 1, x, multires_budget(iterations, level_iterations));
    state.counters["iters0"] = iterations;
    state.counters["coarse_ms"] = report.coarse_ms;
    state.counters["fallbacks"] = report.fallbacks();
    state.counters["true_err"] = relative_error(x, s.exact);
}

void BM_MultiresBuildAndSolve(benchmark::State& state) {
    const Scene& s = scene(static_cast<size_t>(state.range(0)));
    const int iterations = multires_iterations(static_cast<size_t>(state.range(0)), 10);
    std::vector<double> x(s.b.size());
    for (auto _ : state) {
        MultiresSolver solver(s.matrix, s.mesh->positions);
        solver.solve(s.b, 1, x, multires_budget(iterations, 10));
    }
    state.counters["true_err"] = relative_error(x, s.exact);
}

// The multires solve as `waxwork bench --only table1` times it (T_s): default options, stopped by the
// level-0 CG's estimate at 1%, from a fresh solver (no eigenvalue hint). Reports the true error it
// stops at and the level-0 iterations, so the estimate's honesty is measured where T_s relies on it.
void BM_MultiresSolveToEstimated1Percent(benchmark::State& state) {
    const Scene& s = scene(static_cast<size_t>(state.range(0)));
    std::vector<double> x(s.b.size());
    MultiresSolveOptions options;
    options.relative_tolerance = 0.01;
    MultiresSolveReport report;
    for (auto _ : state) {
        state.PauseTiming();
        MultiresSolver solver(s.matrix, s.mesh->positions);
        state.ResumeTiming();
        report = solver.solve(s.b, 1, x, options);
    }
    state.counters["true_err"] = relative_error(x, s.exact);
    state.counters["level0_iterations"] = report.fine.iterations;
}

// All levels' stored entries over level 0's (the multigrid's operator complexity).
double operator_complexity(const MultigridPreconditioner& mg) {
    size_t nnz = 0;
    for (size_t l = 0; l < mg.level_count(); ++l) nnz += mg.nonzeros(l);
    return static_cast<double>(nnz) / static_cast<double>(mg.nonzeros(0));
}

// Cascadic CG (cascadic_solver.h: the paper's coarse-to-fine pass on Galerkin coarse systems) to 1%:
// the smallest level-0 iteration count after the pass, found once and then timed, pass included (the
// operators are built beforehand, as MG-CG's: setup_ms). Second argument: CG iterations on level 1;
// third: the growth per coarser level in tenths (CascadicOptions); fourth: Eq. 16's weights, 0 the
// paper's, 1 linear-exact; fifth: the Galerkin drop tolerance in thousandths (MultigridOptions; 20 the
// default, 0 the exact products). Counter start_err: the error of the pass's start alone.
void BM_CascadicTo1Percent(benchmark::State& state) {
    const Scene& s = scene(static_cast<size_t>(state.range(0)));
    const MultiresHierarchy h = scene_hierarchy(s, state.range(3));
    MultigridOptions mg_options;
    mg_options.drop_tolerance = static_cast<double>(state.range(4)) / 1000.0;
    MultigridPreconditioner mg(h, mg_options);
    CascadicSolver solver(mg);
    CascadicOptions options;
    options.level_iterations = static_cast<int>(state.range(1));
    options.growth = static_cast<double>(state.range(2)) / 10.0;
    options.relative_tolerance = 1e-14;  // never stop on the estimate: run exactly the budget
    std::vector<double> x(s.b.size());
    solver.coarse_pass(s.b, 1, x, options);
    const double start_error = relative_error(x, s.exact);
    const int iterations = smallest_budget(
        [&](int k) {
            options.max_iterations = k;
            solver.solve(s.b, 1, x, options);
            return relative_error(x, s.exact);
        },
        10000);
    options.max_iterations = iterations;
    CascadicReport report;
    for (auto _ : state) report = solver.solve(s.b, 1, x, options);
    state.counters["iters0"] = iterations;
    state.counters["jacobi_iters"] = s.cg_iterations;
    state.counters["coarse_ms"] = report.coarse_ms;
    state.counters["start_err"] = start_error;
    state.counters["nnz_ratio"] = operator_complexity(mg);
    state.counters["setup_ms"] = mg.setup_ms();
    state.counters["true_err"] = relative_error(x, s.exact);
}

// MG-CG (multigrid_cg.h) to 1%: the smallest iteration count found as for Jacobi CG, then timed with
// the preconditioner built (its setup, the Galerkin products and the coarsest factorisation, is
// reported as setup_ms and in BM_MultigridSetup). Second argument: 1 = float V-cycle, 0 = double.
void BM_MultigridCgTo1Percent(benchmark::State& state) {
    const Scene& s = scene(static_cast<size_t>(state.range(0)));
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh->positions);
    MultigridOptions options;
    options.single_precision = state.range(1) != 0;
    options.drop_tolerance = static_cast<double>(state.range(2)) / 1000.0;
    MultigridPreconditioner mg(h, options);
    std::vector<double> x(s.b.size());
    const int iterations = smallest_budget(
        [&](int k) {
            std::fill(x.begin(), x.end(), 0.0);
            solve_multigrid_cg(mg, 1, s.b, x, fixed_budget(k));
            return relative_error(x, s.exact);
        },
        10000);
    for (auto _ : state) {
        std::fill(x.begin(), x.end(), 0.0);
        solve_multigrid_cg(mg, 1, s.b, x, fixed_budget(iterations));
    }
    state.counters["iters"] = iterations;
    state.counters["setup_ms"] = mg.setup_ms();
    state.counters["true_err"] = relative_error(x, s.exact);
    state.counters["nnz_ratio"] = operator_complexity(mg);
}

// Second argument: the drop tolerance in thousandths; third: Eq. 16's weights (0 the paper's, 1
// linear-exact).
void BM_MultigridSetup(benchmark::State& state) {
    const Scene& s = scene(static_cast<size_t>(state.range(0)));
    const MultiresHierarchy h = scene_hierarchy(s, state.range(2));
    MultigridOptions options;
    options.drop_tolerance = static_cast<double>(state.range(1)) / 1000.0;
    for (auto _ : state) {
        MultigridPreconditioner mg(h, options);
        benchmark::DoNotOptimize(mg.level_count());
    }
    const MultigridPreconditioner mg(h, options);
    std::fprintf(stderr, "spot %zu: multigrid levels (rows, entries per row):", s.mesh->tet_count());
    for (size_t l = 0; l < mg.level_count(); ++l)
        std::fprintf(stderr, " (%zu, %.1f)", mg.rows(l), static_cast<double>(mg.nonzeros(l)) / static_cast<double>(mg.rows(l)));
    std::fprintf(stderr, "\n");
}

// The multigrid's Galerkin operators after an edit (third argument: 0 the cut, 1 the fracture, as
// BM_HierarchyAfterEdit), on the hierarchy rebuilt around it: built from scratch (second argument 0)
// or rebuilt from the preconditioner before the edit (1: rows the edit left unchanged are copied; the
// operators are the same). Default options (drop 0.02, row-sum lumping).
void BM_MultigridSetupAfterEdit(benchmark::State& state) {
    const EditScene& c = edit_scene(static_cast<size_t>(state.range(0)), state.range(2));
    const bool rebuild = state.range(1) != 0;
    const MultiresHierarchy after = rebuild_multires_hierarchy(c.before, c.new_of_old, c.lit->matrix, c.mesh.positions);
    const MultigridPreconditioner previous(c.before);
    std::unique_ptr<MultigridPreconditioner> mg;
    for (auto _ : state) {
        mg.reset();
        mg = rebuild ? std::make_unique<MultigridPreconditioner>(after, previous, c.new_of_old)
                     : std::make_unique<MultigridPreconditioner>(after);
    }
    state.counters["tets"] = static_cast<double>(c.mesh.tet_count());
    size_t product = 0, operators = 0, fine = 0, coarse = 0;
    for (size_t l = 0; l < mg->level_count(); ++l) {
        product += mg->copied_product_rows(l);
        operators += mg->copied_operator_rows(l);
        if (l + 1 < mg->level_count()) fine += mg->rows(l);
        if (l > 0) coarse += mg->rows(l);
    }
    state.counters["ap_copied"] = static_cast<double>(product) / static_cast<double>(fine);
    state.counters["rows_copied"] = static_cast<double>(operators) / static_cast<double>(coarse);
}

// Per-frame relighting: the key light (direction (1, -1, -1), as `waxwork render`) turns by 10 degrees
// about the vertical axis. The solver warm-starts from the converged solution of the previous light
// and stops on its own estimate (relative_tolerance 1e-2, the frame's accuracy), all three channels.
// Reported: the time, level-0 iterations and the true error of the result against a tight MG-CG
// solution (1e-9) for the new light. Second argument: 0 = warm MG-CG, 1 = MultiresSolver::solve_frame
// (warm Jacobi CG), 2 = warm Jacobi CG in double; 3, 4 = MultigridFrameSolver (the three channels in
// one pass) with a budget of 1 and 2 V-cycles, 5 = the same stopping on its estimate (budget 10),
// 6, 7 = budgets 1 and 2 with a Chebyshev smoother of degree 1 (half the smoothing sweeps); 8 = as
// 1, with the last frame's phi first corrected by the coarse-to-fine pass (set_warm_start, what the
// live multires does after a cut): whether that correction also pays after a light change.
// For 3-5 the frame solver's state is that of the previous frame (converged on the old light, its
// eigenvalue estimates kept); the timed part is what a frame pays: set_right_hand_side and step.
struct LightTurn {
    std::array<std::vector<double>, 3> before, after;  // right-hand sides
    std::array<std::vector<double>, 3> start, exact;   // converged solutions for before / after
};

const LightTurn& light_turn(size_t target_tets, MultigridPreconditioner& mg) {
    static std::map<size_t, std::unique_ptr<LightTurn>> cache;
    auto& slot = cache[target_tets];
    if (slot) return *slot;
    slot = std::make_unique<LightTurn>();
    const Scene& s = scene(target_tets);
    const std::vector<TetMaterial> materials(s.mesh->tet_count(), material_preset("marble"));
    auto rhs = [&](double degrees) {
        Lighting lighting;
        Light light;
        const double a = degrees * M_PI / 180.0;
        light.vector = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()) * Eigen::Vector3d(1, -1, -1).normalized();
        lighting.lights.push_back(light);
        const std::vector<Rgb> q = incident_light(*s.mesh, s.conn, materials, lighting);
        std::array<std::vector<double>, 3> b;
        for (int c = 0; c < 3; ++c) {
            b[static_cast<size_t>(c)].resize(s.matrix.size());
            diffusion_right_hand_side(s.matrix, q, c, b[static_cast<size_t>(c)]);
        }
        return b;
    };
    slot->before = rhs(0);
    slot->after = rhs(10);
    ConjugateGradientOptions tight;
    tight.relative_tolerance = 1e-9;
    for (size_t c = 0; c < 3; ++c) {
        slot->start[c].assign(s.matrix.size(), 0.0);
        slot->exact[c].assign(s.matrix.size(), 0.0);
        solve_multigrid_cg(mg, static_cast<int>(c), slot->before[c], slot->start[c], tight);
        solve_multigrid_cg(mg, static_cast<int>(c), slot->after[c], slot->exact[c], tight);
    }
    return *slot;
}

double relative_error3(const std::array<std::vector<double>, 3>& x, const std::array<std::vector<double>, 3>& ref) {
    double e = 0, r = 0;
    for (size_t c = 0; c < 3; ++c)
        for (size_t i = 0; i < x[c].size(); ++i) {
            e += (x[c][i] - ref[c][i]) * (x[c][i] - ref[c][i]);
            r += ref[c][i] * ref[c][i];
        }
    return std::sqrt(e / r);
}

void light_turn_per_channel(benchmark::State& state) {
    const Scene& s = scene(static_cast<size_t>(state.range(0)));
    const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh->positions);
    MultigridPreconditioner mg(h);
    const LightTurn& turn = light_turn(static_cast<size_t>(state.range(0)), mg);
    const int mode = static_cast<int>(state.range(1));
    MultiresSolver multires(s.matrix, s.mesh->positions);
    std::array<double, 3> hints{};
    if (mode == 1 || mode == 8)  // the previous frame: a full multires solve for the old light
        for (int c = 0; c < 3; ++c) multires.solve_frame(turn.before[static_cast<size_t>(c)], c, 10000);
    std::array<std::vector<double>, 3> x;
    int iterations = 0;
    for (auto _ : state) {
        state.PauseTiming();
        x = turn.start;
        iterations = 0;
        MultiresSolver frame = multires;  // solve_frame keeps its warm start inside; copy per repetition
        state.ResumeTiming();
        for (size_t c = 0; c < 3; ++c) {
            ConjugateGradientOptions options;
            options.relative_tolerance = 1e-2;
            options.smallest_eigenvalue_hint = hints[c];
            if (mode == 0) {
                const auto r = solve_multigrid_cg(mg, static_cast<int>(c), turn.after[c], x[c], options);
                iterations += r.iterations;
                hints[c] = r.smallest_eigenvalue_estimate;
            } else if (mode == 1 || mode == 8) {
                // 8: the last frame's phi corrected by the coarse-to-fine pass first (set_warm_start)
                if (mode == 8) frame.set_warm_start(static_cast<int>(c), turn.start[c]);
                MultiresSolveReport report;
                MultiresSolveOptions frame_options;
                frame_options.relative_tolerance = 1e-2;
                const auto phi = frame.solve_frame(turn.after[c], static_cast<int>(c), 10000, &report, frame_options);
                iterations += report.fine.iterations;
                x[c].assign(phi.begin(), phi.end());
            } else {
                const CsrMatrixView<double> view{s.matrix.size(), s.matrix.offsets.data(), s.matrix.columns.data(),
                                                 s.matrix.values[c].data()};
                const auto r = solve_jacobi_cg<double>(view, turn.after[c], x[c], options);
                iterations += r.iterations;
                hints[c] = r.smallest_eigenvalue_estimate;
            }
        }
    }
    state.counters["iters"] = iterations;
    state.counters["true_err"] = relative_error3(x, turn.exact);
    state.counters["start_err"] = relative_error3(turn.start, turn.exact);
}

std::array<std::span<const double>, 3> spans3(const std::array<std::vector<double>, 3>& v) {
    return {v[0], v[1], v[2]};
}

void light_turn_frame_solver(benchmark::State& state, int budget, int smoothing_steps = 2) {
    const Scene& s = scene(static_cast<size_t>(state.range(0)));
    const LightTurn* turn = nullptr;
    {
        const MultiresHierarchy h = build_multires_hierarchy(s.matrix, s.mesh->positions);
        MultigridPreconditioner mg(h);
        turn = &light_turn(static_cast<size_t>(state.range(0)), mg);
    }
    FrameSolverOptions options;
    options.multigrid.smoothing_steps = smoothing_steps;
    MultigridFrameSolver solver(s.matrix, s.mesh->positions, options);
    // The previous frames: converged on the old light (this also sets the eigenvalue estimates).
    solver.set_right_hand_side(spans3(turn->before));
    for (int frame = 0; frame < 100 && !solver.step(4).converged; ++frame) {
    }
    FrameStep step;
    for (auto _ : state) {
        state.PauseTiming();
        solver.set_right_hand_side(spans3(turn->before));
        solver.set_phi(spans3(turn->start));
        state.ResumeTiming();
        solver.set_right_hand_side(spans3(turn->after));
        step = solver.step(budget);
    }
    std::array<std::vector<double>, 3> x;
    for (int c = 0; c < 3; ++c) x[static_cast<size_t>(c)].assign(solver.phi(c).begin(), solver.phi(c).end());
    state.counters["iters"] = step.vcycles;
    state.counters["true_err"] = relative_error3(x, turn->exact);
    state.counters["start_err"] = relative_error3(turn->start, turn->exact);
    state.counters["est_err"] = std::max({step.estimated_relative_error[0], step.estimated_relative_error[1],
                                          step.estimated_relative_error[2]});
}

void BM_LightTurn10Degrees(benchmark::State& state) {
    const int mode = static_cast<int>(state.range(1));
    if (mode == 3) return light_turn_frame_solver(state, 1);
    if (mode == 4) return light_turn_frame_solver(state, 2);
    if (mode == 5) return light_turn_frame_solver(state, 10);
    if (mode == 6) return light_turn_frame_solver(state, 1, 1);
    if (mode == 7) return light_turn_frame_solver(state, 2, 1);
    light_turn_per_channel(state);
}

// The three channels from phi = 0 to 1% with MultigridFrameSolver (what a frame after a cut pays on
// top of the setup): the smallest V-cycle budget whose result is within 1% of a tight MG-CG solution
// in every channel, found once and then timed (hierarchy and preconditioner built beforehand).
// Second and third arguments: the Chebyshev degree and ratio (MultigridOptions; defaults 2 and 8);
// fourth: Eq. 16's weights, 0 the paper's inverse edge lengths, 1 linear-exact (hierarchy.h). Counter
// vcycles_to_1e-6: the same search for a 1e-6 error (the rate of convergence beyond the first 1%).
void BM_MultigridCgFrameTo1Percent(benchmark::State& state) {
    const Scene& s = scene(static_cast<size_t>(state.range(0)));
    const bench::LitSpot& lit = bench::lit_spot(static_cast<size_t>(state.range(0)));
    std::array<std::vector<double>, 3> b, exact;
    FrameSolverOptions options;
    options.relative_tolerance = 1e-14;  // never stop on the estimate: run exactly the budget
    options.multigrid.smoothing_steps = static_cast<int>(state.range(1));
    options.multigrid.chebyshev_ratio = static_cast<double>(state.range(2));
    options.hierarchy.weights = weights_argument(state.range(3));
    MultigridFrameSolver solver(s.matrix, s.mesh->positions, options);
    {
        MultigridPreconditioner mg(solver.hierarchy());
        ConjugateGradientOptions tight;
        tight.relative_tolerance = 1e-9;
        for (size_t c = 0; c < 3; ++c) {
            b[c].resize(s.matrix.size());
            diffusion_right_hand_side(s.matrix, lit.q, static_cast<int>(c), b[c]);
            exact[c].assign(s.matrix.size(), 0.0);
            solve_multigrid_cg(mg, static_cast<int>(c), b[c], exact[c], tight);
        }
    }
    solver.set_right_hand_side(spans3(b));
    auto worst_error = [&] {
        double worst = 0;
        for (int c = 0; c < 3; ++c) {
            const Eigen::Map<const Eigen::VectorXd> ref(exact[static_cast<size_t>(c)].data(),
                                                        static_cast<Eigen::Index>(s.matrix.size()));
            worst = std::max(worst, relative_error(solver.phi(c), ref));
        }
        return worst;
    };
    const auto error_after = [&](int k) {
        solver.reset();
        if (k > 0) solver.step(k);
        return worst_error();
    };
    const int tight_budget = smallest_budget([&](int k) { return error_after(k) * 1e4; }, 1000);  // 1e-6
    const int budget = smallest_budget(error_after, 1000);
    for (auto _ : state) {
        solver.reset();
        solver.step(budget);
    }
    state.counters["vcycles"] = budget;
    state.counters["vcycles_to_1e-6"] = tight_budget;
    state.counters["true_err"] = worst_error();
}

// After painting: the tets within 5% of the model's size of a surface point get a new material
// (update_diffusion_matrix rewrites their vertices' rows). Second argument: 0 = MultiresSolver
// update_values of all coarse rows, 1 = of the rows depending on the changed ones, 2 = multigrid
// preconditioner rebuilt, 3 = multigrid update_values of the affected rows.
void BM_PaintUpdate(benchmark::State& state) {
    const Scene& s = scene(static_cast<size_t>(state.range(0)));
    const int mode = static_cast<int>(state.range(1));
    DiffusionMatrix matrix = s.matrix;
    std::vector<TetMaterial> materials(s.mesh->tet_count(), material_preset("marble"));
    const auto box = bounding_box(*s.mesh);
    const Eigen::Vector3d centre = s.mesh->positions[static_cast<size_t>(s.conn.boundary_vertices.front())];
    const double radius = 0.05 * (box[1] - box[0]).maxCoeff();
    std::vector<int32_t> painted;
    for (size_t t = 0; t < s.mesh->tet_count(); ++t)
        if ((s.mesh->positions[static_cast<size_t>(s.mesh->tets[t][0])] - centre).norm() < radius) {
            painted.push_back(static_cast<int32_t>(t));
            materials[t] = material_preset("skin1");
        }
    const std::vector<int32_t> rows = update_diffusion_matrix(matrix, *s.mesh, s.conn, materials, painted);
    MultiresSolver solver(s.matrix, s.mesh->positions);
    MultiresHierarchy h = solver.hierarchy();
    h.levels[0].values = matrix.values;
    MultigridPreconditioner mg(h);
    for (auto _ : state) {
        if (mode == 0) solver.update_values(matrix);
        if (mode == 1) solver.update_values(matrix, rows);
        if (mode == 2) {
            MultigridPreconditioner rebuilt(h);
            benchmark::DoNotOptimize(rebuilt.level_count());
        }
        if (mode == 3) mg.update_values(rows);
    }
    state.counters["painted_tets"] = static_cast<double>(painted.size());
    state.counters["changed_rows"] = static_cast<double>(rows.size());
}

#define WAXWORK_SIZES \
    Arg(50000)->Arg(500000)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()
BENCHMARK(BM_MultiresBuild)->WAXWORK_SIZES;
BENCHMARK(BM_JacobiCgTo1Percent)->WAXWORK_SIZES;
BENCHMARK(BM_HierarchyAfterEdit)
    ->ArgsProduct({{50000, 500000}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
// Second argument: BiCGSTAB iterations on each intermediate level (the default is 2); third: Eq. 16's
// weights, 0 the paper's, 1 linear-exact (hierarchy.h).
BENCHMARK(BM_MultigridSetupAfterEdit)
    ->ArgsProduct({{50000, 500000}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK(BM_MultiresTo1Percent)
    ->ArgsProduct({{50000, 500000}, {2, 10}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK(BM_CascadicTo1Percent)
    ->ArgsProduct({{50000, 500000}, {0, 4, 16}, {10, 20}, {0, 1}, {20}})
    ->ArgsProduct({{50000, 500000}, {1, 4, 16}, {10}, {0, 1}, {0}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK(BM_MultiresBuildAndSolve)->WAXWORK_SIZES;
BENCHMARK(BM_MultiresSolveToEstimated1Percent)->WAXWORK_SIZES;
BENCHMARK(BM_MultigridCgTo1Percent)
    ->ArgsProduct({{50000, 500000}, {1, 0}, {0, 20, 50, 100}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK(BM_MultigridCgFrameTo1Percent)
    ->ArgsProduct({{50000, 500000}, {2, 3}, {8}, {0, 1}})
    ->Args({500000, 2, 4, 0})
    ->Args({500000, 3, 16, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK(BM_LightTurn10Degrees)
    ->ArgsProduct({{50000, 500000}, {0, 1, 2, 3, 4, 5, 6, 7, 8}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK(BM_PaintUpdate)
    ->ArgsProduct({{50000, 500000}, {0, 1, 2, 3}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK(BM_MultigridSetup)
    ->ArgsProduct({{50000, 500000}, {0, 20, 50, 100}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();

}  // namespace
}  // namespace waxwork

WAXWORK_BENCHMARK_MAIN()
