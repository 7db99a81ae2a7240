// The solver comparison behind `waxwork bench solvers`: one lit diffusion system, every solver of the
// project on it, and for each the relative error of phi against a direct reference as a function of
// solve time.
//
// Error. Relative L2 over all three channels together, sqrt(sum_c |x_c - ref_c|^2 / sum_c |ref_c|^2):
// one number per run, dominated by the brightest channel, the same for every solver. The reference is
// CHOLMOD's (or Eigen's) direct solution in double with one step of iterative refinement; the
// `direct` entry is that method timed again, so its error only shows rounding.
//
// Curves. Each iterative solver is run from a cold start (zero; multires: its coarse-to-fine pass) for
// an increasing schedule of iteration caps (0, 1, 2, ... growing by a quarter), all three channels per
// run; a point is (time of that run, its error). Measuring the error is outside the timed region.
// Statistic (timing_statistic): by default a run under 100 ms is repeated three times and the fastest
// kept; with options.repeats = N every point is the median of N runs, and its fastest and slowest run
// are kept too (the chart's error band). Each iterative solver gets one untimed warm-up run first. A
// point is kept only if it ran faster than every later point (noise that made a small cap slower than a
// larger one drops the small cap), so every curve is strictly monotone in time. A curve ends below
// floor_error, when the error stops falling (float's precision floor), or after max_seconds of
// measuring. time_to_1pct_ms: the smallest cap with error <= target_error is found by bisection between
// the curve's bracketing caps and timed again.
//
// What is timed. The curves are solve time only. Each solver's per-mesh setup, which a frame does not
// repeat, is its setup_ms (0 where there is none): the multires hierarchy (multires), the hierarchy
// plus the multigrid Galerkin operators and coarsest factorisation (multigrid_cg, and cascadic_cg,
// which borrows them), the frame solver's own hierarchy, Galerkin operators and interleaved matrix
// (multigrid_cg_rgb), Eigen's incomplete Cholesky factorisation of the three channels (eigen_ic_cg),
// the direct solver's symbolic and numeric factorisation of the three channels (direct: its point is
// the three triangular solves; it has no warm-up run, a factorisation being the costliest step here),
// and the GPU solvers' construction (uploads, and their own hierarchies where they build one). Setup
// plus solve is setup_ms + a point's time. The hierarchy and multigrid setups are also reported
// separately, as their first run in the process and as a rebuild (SolverComparison); setup_ms uses the
// first run for those and the statistic for the two factorisations. The float copies of the matrices
// and the Eigen sparse matrices are not timed.
//
// Peers (builds with PETSc, solver/petsc_peers.h): petsc_cg_gamg and petsc_cg_boomeramg, CG with
// PETSc's GAMG or hypre's BoomerAMG on the same three matrices and right-hand sides; cap = CG
// iterations per channel, measured like every other curve. Their setup_ms is the first build: the
// conversion of the three channels to PETSc's AIJ matrices plus the preconditioners' setup (PETSc's
// and MPI's start-up excluded); the rebuild copies the same values in again and sets the
// preconditioners up from scratch (SolverComparison::peers). PETSc runs one thread per process.
#pragma once

#include "gl/gl_context.h"
#include "solver/lighting.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace waxwork {

struct SolverComparisonOptions {
    double mm_per_unit = 1.0;
    double target_error = 1e-2;   // time_to_1pct_ms
    double floor_error = 1e-4;    // a curve stops once below this
    double max_seconds = 60.0;    // per solver, measuring included
    int repeats = 0;              // 0: fastest of 3 for runs under 100 ms; N >= 1: median of N runs
    // When set (a current OpenGL >= 4.3 context): also the GPU curves gpu_cg (solver/gpu/gpu_conjugate_gradient.h),
    // gpu_multires (multires/gpu_multires_solver.h) and gpu_multigrid_cg (multires/gpu_multigrid_frame_solver.h);
    // their times include reading phi back.
    const GlApi* gl = nullptr;
};

struct SolverCurve {
    std::string name;
    std::vector<std::pair<double, double>> curve;     // (ms, relative error), time strictly increasing
    std::vector<std::pair<double, double>> ms_range;  // per curve point, (fastest, slowest) of its runs
    std::optional<double> time_to_target_ms;          // nullopt when the target was not reached
    std::pair<double, double> time_to_target_range{};  // its (fastest, slowest) run
    double setup_ms = 0;                               // per-mesh setup, not in the curve's times
    double parallelism = 0;                            // CPU seconds per wall second over its measurements
    double other_load_cores = -1;                      // other processes' busy cores meanwhile (cpu_usage.h)
    std::optional<int> cap_to_target;              // the smallest cap reaching it (nullopt: not reached,
                                                   // or no cap, as for direct)
};

// A PETSc peer's setup (solver/petsc_peers.h): the first build and a rebuild, with its settings.
struct PeerSetup {
    std::string name;              // its row in `solvers`, e.g. "petsc_cg_gamg"
    double conversion_ms = 0;      // first build: the three channels into AIJ matrices
    double preconditioner_ms = 0;  // first build: the three preconditioners' setup
    double rebuild_ms = 0;         // median of three rebuilds: values copied in again + setup again
    std::vector<std::pair<std::string, std::string>> settings;  // PETSc options, e.g. {"pc_type", "gamg"}
};

struct SolverComparison {
    size_t tets = 0, vertices = 0, levels = 0;
    // Per-mesh setup, each twice: its first run in the process (which also maps every fresh page it
    // touches), and *_rebuild_ms, the median of three runs after it, which reuse the memory freed by
    // the run before, as the editor's rebuild after a cut does (base/memory_reuse.h).
    double hierarchy_ms = 0, hierarchy_rebuild_ms = 0;
    double multigrid_setup_ms = 0, multigrid_setup_rebuild_ms = 0;
    // MultigridFrameSolver's constructor (its own hierarchy included).
    double multigrid_rgb_setup_ms = 0, multigrid_rgb_setup_rebuild_ms = 0;
    std::vector<SolverCurve> solvers;  // jacobi_cg, jacobi_cg_double, multires, multigrid_cg, cascadic_cg, multigrid_cg_rgb,
                                       // eigen_ic_cg, [petsc_cg_gamg, petsc_cg_boomeramg,]
                                       // [gpu_cg, gpu_multires, gpu_multigrid_cg,] direct
    std::string gpu_fallback_reason;   // options.gl given but the GPU could not run (curves left out)
    std::vector<PeerSetup> peers;      // petsc_cg_gamg, petsc_cg_boomeramg (builds with PETSc)
    std::string peers_missing_reason;  // why there are no PETSc rows ("" when there are)
    int repeats = 0;                   // options.repeats, for timing_statistic
};

// One warning naming every solver during whose measurements other processes kept more than
// kBusyMachineCores cores busy on average (provenance.h), or "" when none.
std::string busy_machine_warning(const SolverComparison& comparison);

// The warning for a comparison without the PETSc peers ("PETSc peer rows missing: REASON"), or "" when
// they ran.
std::string missing_peers_warning(const SolverComparison& comparison);

// The statistic a comparison's times are, in words, e.g. "median of 5 runs after one warm-up".
std::string timing_statistic(int repeats);

// Assembles the TransCut system (materials per tet), lights it (q from `lighting`) and compares the
// solvers. Throws InvalidArgumentError for bad materials, lighting or options, AlgorithmError when a
// solver breaks down.
SolverComparison compare_solvers(const TetMesh& mesh, const TetConnectivity& connectivity,
                                 const std::vector<TetMaterial>& materials, const Lighting& lighting,
                                 const SolverComparisonOptions& options);

// The setup times as (JSON key, ms) in the order written: hierarchy_ms, hierarchy_rebuild_ms,
// multigrid_setup_ms, multigrid_setup_rebuild_ms, multigrid_rgb_setup_ms, multigrid_rgb_setup_rebuild_ms.
std::vector<std::pair<std::string, double>> setup_times(const SolverComparison& comparison);

// What a comparison solved, recorded with it: the mesh file as given, the materials (a preset's name,
// "custom" coefficients, or "stored" for the volume's own) and the millimetres per model unit the
// coefficients (per mm) were applied at.
struct ComparedScene {
    std::string mesh;
    std::string material;
    double mm_per_unit = 0;
};

// How the comparison's chart is drawn: solve time (default) or setup + solve on the x axis, and "(quick
// run)" in the title.
struct SolverChartOptions {
    bool include_setup = false;
    bool quick = false;
};

// What every number of the comparison means (the provenance block's "definitions").
nlohmann::ordered_json solver_comparison_definitions(const SolverComparisonOptions& options);

// Writes DIR/STEM.json, {"provenance" (bench/studies/provenance.h), "mesh", "material", "mm_per_unit",
// "tets", "vertices", "levels", setup_times..., "statistic", "repeats", "solvers": {NAME:
// {"time_to_1pct_ms", "time_to_1pct_ms_min", "time_to_1pct_ms_max", "cap_to_1pct", "setup_ms",
// "setup_plus_time_to_1pct_ms", "parallelism", "other_load_cores", "curve": [[ms, rel_error], ...], "curve_ms_min": [...],
// "curve_ms_max": [...]}}, "peers": {"petsc": version or "not run: REASON", NAME: {"setup_ms",
// "setup_rebuild_ms", "conversion_ms", "preconditioner_setup_ms", "settings": {option: value}}}}
// (ms: the statistic; _min, _max: the fastest and slowest run), and
// DIR/STEM.svg and STEM.pdf (error against time, one line per solver, the direct solve pinned to the
// bottom edge, the 1% target dashed, the caption from the provenance), atomically.
void write_solver_comparison(const std::filesystem::path& dir, const std::string& stem, const ComparedScene& scene,
                             const SolverComparison& comparison, const nlohmann::ordered_json& provenance,
                             const SolverChartOptions& chart = {});

// The caption of a comparison's chart: provenance_caption (date, CPU, threads, commit), the statistic
// and, when the GPU curves ran on a software rasteriser, "GPU curves: software GPU (llvmpipe)".
std::string solver_chart_caption(const SolverComparison& comparison, const nlohmann::ordered_json& provenance);

// For the GPU curves: a headless OpenGL context (OSMesa's llvmpipe unless WAXWORK_GL_DEVICE=egl finds a
// GPU) set as options.gl. Returns null, with one warning line on stderr, when none can be created; the
// CPU curves are measured either way.
std::unique_ptr<HeadlessGlContext> open_gpu_for_comparison(SolverComparisonOptions& options);

}  // namespace waxwork
