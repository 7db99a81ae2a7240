// The GPU solver (OpenGL 4.3 compute shaders, solver/gpu_*) on spot at ~50K and ~500K tets: the sparse
// product in the three storage formats, and Jacobi CG (three channels, float) to an estimated 1% error,
// cold and warm, as bench/solver_bench.cpp measures the CPU path (same scene: spot 100 mm across,
// marble, a directional light along -z without shadows).
//
// Which device runs it: the context of gl/gl_context.h, i.e. Mesa's llvmpipe through OSMesa by
// default -- a software rasteriser running the compute shaders on this machine's CPU cores, so these
// numbers say nothing about GPU speed. On a machine with a GPU the same binary runs on it with
// WAXWORK_GL_DEVICE=egl (EGL without a display; see gl_context.h). The first lines of the output name
// the renderer that ran.
//
// Run: build/bench/gpu_solver_bench [--benchmark_filter=...]
#include "gl/gl_context.h"
#include "multires/gpu_independent_set.h"
#include "multires/gpu_multigrid_frame_solver.h"
#include "multires/gpu_multires_solver.h"
#include "multires/hierarchy.h"
#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "solver/diffusion_solve.h"
#include "solver/gpu/gpu_assembly.h"
#include "solver/gpu/gpu_conjugate_gradient.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "tetops/connectivity.h"
#include "bench_main.h"
#include "bench_meshes.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
#include <memory>

namespace waxwork {
namespace {

using Scene = bench::LitSpot;

HeadlessGlContext& context() {
    static std::unique_ptr<HeadlessGlContext> c;
    if (!c) {
        c = std::make_unique<HeadlessGlContext>();
        std::fprintf(stderr, "OpenGL %s on %s\n", c->version().c_str(), c->renderer().c_str());
    }
    c->make_current();
    return *c;
}

const Scene& scene(size_t target_tets) {
    static std::set<size_t> reported;
    const Scene& s = bench::lit_spot(target_tets);
    if (reported.insert(target_tets).second)
        std::fprintf(stderr, "spot: %zu tets, %zu vertices, %zu nonzeros\n", s.mesh.tet_count(), s.mesh.vertex_count(),
                     s.matrix.nonzeros());
    return s;
}

// q = M p for the three channels with the fused p . q reduction (what a CG iteration runs), including
// the read-back of the reduction partials that ends each call.
template <GpuMatrixFormat F>
void BM_GpuProduct(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    GpuKernels kernels(context().gl(), {F});
    const GpuMatrix m(context().gl(), rgb_csr_view(s.matrix), F);
    const std::vector<float> ones(3 * s.matrix.size(), 1.0f);
    const GpuBuffer p = kernels.vector(s.matrix.size(), ones.data());
    GpuBuffer q = kernels.vector(s.matrix.size());
    for (auto _ : state) benchmark::DoNotOptimize(kernels.multiply_dot(m, p, q));
    state.counters["stored_per_nnz"] = static_cast<double>(m.layout.stored_entries()) / s.matrix.nonzeros();
    state.counters["nnz_rgb_per_s"] =
        benchmark::Counter(3.0 * s.matrix.nonzeros(), benchmark::Counter::kIsIterationInvariantRate);
}

// The two vector kernels of an iteration: a three-channel dot product (reduction + read-back) and axpby.
void BM_GpuDot(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    GpuKernels kernels(context().gl(), {});
    const std::vector<float> ones(3 * s.matrix.size(), 1.0f);
    const GpuBuffer u = kernels.vector(s.matrix.size(), ones.data());
    for (auto _ : state) benchmark::DoNotOptimize(kernels.dot(s.matrix.size(), u, u));
}

void BM_GpuAxpby(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    GpuKernels kernels(context().gl(), {});
    const std::vector<float> ones(3 * s.matrix.size(), 1.0f);
    const GpuBuffer x = kernels.vector(s.matrix.size(), ones.data());
    GpuBuffer y = kernels.vector(s.matrix.size(), ones.data());
    for (auto _ : state) {
        kernels.axpby(s.matrix.size(), {0.5, 0.5, 0.5}, x, {0.5, 0.5, 0.5}, y);
        context().gl().Finish();
    }
}

// Cold start to an estimated 1% error, matrix resident (upload and compilation excluded).
template <GpuMatrixFormat F>
void BM_GpuCg(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    GpuDiffusionSolver solver(context().gl(), s.matrix, F);
    solver.set_light(s.matrix, s.q);
    const std::vector<std::array<double, 3>> zero(s.matrix.size(), {0.0, 0.0, 0.0});
    GpuCgOptions options;
    options.relative_tolerance = 1e-2;
    std::array<ConjugateGradientResult, 3> r;
    for (auto _ : state) {
        solver.set_solution(zero);
        r = solver.solve(options);
    }
    state.counters["iters_g"] = r[1].iterations;
    state.counters["converged"] = r[0].converged && r[1].converged && r[2].converged;
}

// A frame after a 5% light change, warm-started from the previous frame's solution.
void BM_GpuCgWarm(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    GpuDiffusionSolver solver(context().gl(), s.matrix);
    solver.set_light(s.matrix, s.q);
    GpuCgOptions options;
    options.relative_tolerance = 1e-2;
    solver.solve(options);
    const auto previous = solver.solution();
    auto q2 = s.q;
    for (auto& v : q2)
        for (double& c : v) c *= 1.05;
    solver.set_light(s.matrix, q2);
    std::array<ConjugateGradientResult, 3> r;
    for (auto _ : state) {
        solver.set_solution(previous);
        r = solver.solve(options);
    }
    state.counters["iters_g"] = r[1].iterations;
}

// The GPU multires path: coarse-to-fine BiCGSTAB (hierarchy built once on the CPU, excluded), then the
// level-0 CG to an estimated 1% error.
void BM_GpuMultires(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    const MultiresHierarchy hierarchy = build_multires_hierarchy(s.matrix, s.mesh.positions);
    GpuMultiresSolver solver(context().gl(), s.matrix, hierarchy);
    solver.set_light(s.matrix, s.q);
    MultiresSolveOptions options;
    options.relative_tolerance = 1e-2;
    GpuMultiresReport report;
    for (auto _ : state) report = solver.solve(options);
    state.counters["levels"] = static_cast<double>(hierarchy.level_count());
    state.counters["fine_iters_g"] = report.fine[1].iterations;
    state.counters["coarsest_iters_g"] = report.coarse_levels.empty() ? 0 : report.coarse_levels.front()[1].iterations;
}

// The GPU multigrid CG (multires/gpu_multigrid_frame_solver.h) from phi = 0 to an estimated 1% error,
// hierarchy and levels resident (their setup excluded): compare with BM_GpuCg<SellCSigma>, GPU Jacobi CG
// on the same system to the same estimate. V-cycles per frame are unlimited; counters: V-cycles run.
void BM_GpuMultigridCg(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    FrameSolverOptions options;
    options.relative_tolerance = 1e-2;
    GpuMultigridFrameSolver solver(context().gl(), s.matrix, s.mesh.positions, options);
    std::array<std::vector<double>, 3> b;
    for (int c = 0; c < 3; ++c) {
        b[c].resize(s.matrix.size());
        diffusion_right_hand_side(s.matrix, s.q, c, b[c]);
    }
    solver.set_right_hand_side({b[0], b[1], b[2]});
    FrameStep step;
    for (auto _ : state) {
        solver.reset();
        step = solver.step(1000);
    }
    state.counters["vcycles"] = step.vcycles;
    state.counters["converged"] = step.converged;
    state.counters["levels"] = static_cast<double>(solver.preconditioner().level_count());
}

// A frame after a 5% light change, warm from the previous solution (as BM_GpuCgWarm): the residual
// follows the change of b on the device, then V-cycles to an estimated 1%.
void BM_GpuMultigridCgWarm(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    FrameSolverOptions options;
    options.relative_tolerance = 1e-2;
    GpuMultigridFrameSolver solver(context().gl(), s.matrix, s.mesh.positions, options);
    std::array<std::vector<double>, 3> b, b2;
    for (int c = 0; c < 3; ++c) {
        b[c].resize(s.matrix.size());
        diffusion_right_hand_side(s.matrix, s.q, c, b[c]);
        b2[c] = b[c];
        for (double& v : b2[c]) v *= 1.05;
    }
    solver.set_right_hand_side({b[0], b[1], b[2]});
    solver.step(1000);
    const auto previous = solver.phi();
    FrameStep step;
    for (auto _ : state) {
        solver.set_phi({previous[0], previous[1], previous[2]});  // back to the previous frame's phi
        solver.set_right_hand_side({b2[0], b2[1], b2[2]});
        step = solver.step(1000);
        solver.set_right_hand_side({b[0], b[1], b[2]});
    }
    state.counters["vcycles"] = step.vcycles;
}

// One device V-cycle z = B r (gpu_multigrid_preconditioner.h), and arg 2 = 1: only its coarsest solve's
// round trip (read-back of the coarsest right-hand side, the host LDL^T solve, upload of x), to weigh the
// choice of a host solve against the whole V-cycle.
void BM_GpuMultigridVcycle(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    const MultiresHierarchy hierarchy = build_multires_hierarchy(s.matrix, s.mesh.positions);
    MultigridPreconditioner cpu(hierarchy);
    GpuKernels kernels(context().gl(), {GpuMatrixFormat::SellCSigma});
    GpuMultigridPreconditioner gpu(kernels, cpu);
    const size_t n = s.matrix.size(), coarse = cpu.rows(cpu.level_count() - 1);
    const std::vector<float> ones(3 * n, 1.0f);
    const GpuBuffer r = kernels.vector(n, ones.data());
    GpuBuffer z = kernels.vector(n), cb = kernels.vector(coarse, ones.data()), cx = kernels.vector(coarse);
    std::vector<float> hb(3 * coarse), hx(3 * coarse);
    const bool round_trip_only = state.range(1) == 1;
    for (auto _ : state) {
        if (round_trip_only) {
            cb.read(0, hb.size() * sizeof(float), hb.data());
            cpu.solve_coarsest_rgb(hb, hx);
            cx.write(0, hx.size() * sizeof(float), hx.data());
        } else {
            gpu.apply(r, z);
        }
        context().gl().Finish();
    }
    state.counters["levels"] = static_cast<double>(cpu.level_count());
    state.counters["coarsest_rows"] = static_cast<double>(coarse);
}

// What a scene load costs: kernels compiled, pattern and values uploaded, diagonal extracted.
void BM_GpuSetup(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    for (auto _ : state) {
        GpuDiffusionSolver solver(context().gl(), s.matrix);
        context().gl().Finish();
    }
}

// Paint strokes over the first ~1% of the tets, alternately ketchup and marble; `update` applies one
// (its materials and tets) and returns the rows it rewrote.
template <typename Update>
void run_paint_strokes(benchmark::State& state, const Scene& s, Update&& update) {
    std::vector<TetMaterial> materials = s.materials;
    std::vector<int32_t> stroke;
    for (size_t t = 0; t < s.mesh.tet_count() / 100; ++t) stroke.push_back(static_cast<int32_t>(t));
    bool ketchup = false;
    size_t rows = 0;
    for (auto _ : state) {
        ketchup = !ketchup;
        for (int32_t t : stroke) materials[t] = material_preset(ketchup ? "ketchup" : "marble");
        rows = update(materials, stroke);
    }
    state.counters["rows"] = static_cast<double>(rows);
}

// A paint stroke: ~1% of the tets change material; the CPU rewrites their rows (update_diffusion_matrix)
// and the GPU receives only those rows.
void BM_GpuPaintRowUpdate(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    DiffusionMatrix matrix = s.matrix;
    GpuDiffusionSolver solver(context().gl(), matrix);
    run_paint_strokes(state, s, [&](const std::vector<TetMaterial>& materials, const std::vector<int32_t>& stroke) {
        const std::vector<int32_t> changed = update_diffusion_matrix(matrix, s.mesh, s.conn, materials, stroke);
        solver.update_rows(matrix, changed);
        context().gl().Finish();
        return changed.size();
    });
}

// The matrix values assembled on the device (gpu_assembly.h): every row from the positions and the
// materials (what a wholesale material change or a relaxation costs; the host only computes and
// uploads the per-tet coefficients), and a paint stroke of ~1% of the tets (the rows of their vertices).
// Compare with solver_bench's BM_AssembleValues (host, from cached geometry) and BM_GpuPaintRowUpdate.
void BM_GpuAssembleValues(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    GpuMatrix m(context().gl(), rgb_csr_view(s.matrix), GpuMatrixFormat::SellCSigma);
    GpuMatrixAssembly assembly(context().gl(), s.mesh, s.conn, s.matrix, m.layout);
    for (auto _ : state) assembly.assemble(s.materials, m);  // ends with a read-back: synchronous
}

void BM_GpuAssemblePaintUpdate(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    GpuMatrix m(context().gl(), rgb_csr_view(s.matrix), GpuMatrixFormat::SellCSigma);
    GpuMatrixAssembly assembly(context().gl(), s.mesh, s.conn, s.matrix, m.layout);
    run_paint_strokes(state, s, [&](const std::vector<TetMaterial>& materials, const std::vector<int32_t>& stroke) {
        return assembly.update(s.mesh, materials, stroke, m).size();  // ends with a read-back
    });
}

// The hierarchy's first vertex selection (independent set + enhancement, Sec. 4.1) on level 0's graph:
// on the device (gpu_independent_set.h, graph upload and read-back included) and on the CPU (TBB), same
// result. Argument 2: 0 = device, 1 = CPU.
void BM_SelectCoarseVertices(benchmark::State& state) {
    const Scene& s = scene(state.range(0));
    const bool on_device = state.range(1) == 0;
    std::unique_ptr<GpuVertexSelector> gpu;
    if (on_device) gpu = std::make_unique<GpuVertexSelector>(context().gl());
    size_t retained = 0;
    for (auto _ : state) {
        const VertexSelection selection = on_device ? gpu->select(s.conn.vertex_vertices, 1)
                                                    : select_coarse_vertices(s.conn.vertex_vertices, 1);
        retained = static_cast<size_t>(std::count(selection.retained.begin(), selection.retained.end(), 1));
    }
    state.counters["retained"] = static_cast<double>(retained);
}

#define WAXWORK_SIZES Arg(50000)->Arg(500000)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime()
BENCHMARK(BM_GpuProduct<GpuMatrixFormat::Csr>)->WAXWORK_SIZES;
BENCHMARK(BM_GpuProduct<GpuMatrixFormat::Ell>)->WAXWORK_SIZES;
BENCHMARK(BM_GpuProduct<GpuMatrixFormat::SellCSigma>)->WAXWORK_SIZES;
BENCHMARK(BM_GpuDot)->WAXWORK_SIZES;
BENCHMARK(BM_GpuAxpby)->WAXWORK_SIZES;
BENCHMARK(BM_GpuCg<GpuMatrixFormat::Csr>)->WAXWORK_SIZES;
BENCHMARK(BM_GpuCg<GpuMatrixFormat::SellCSigma>)->WAXWORK_SIZES;
BENCHMARK(BM_GpuCgWarm)->WAXWORK_SIZES;
BENCHMARK(BM_GpuMultires)->WAXWORK_SIZES;
BENCHMARK(BM_GpuMultigridCg)->WAXWORK_SIZES;
BENCHMARK(BM_GpuMultigridCgWarm)->WAXWORK_SIZES;
BENCHMARK(BM_GpuMultigridVcycle)->ArgsProduct({{50000, 500000}, {0, 1}})->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();
BENCHMARK(BM_GpuSetup)->WAXWORK_SIZES;
BENCHMARK(BM_GpuPaintRowUpdate)->WAXWORK_SIZES;
BENCHMARK(BM_GpuAssembleValues)->WAXWORK_SIZES;
BENCHMARK(BM_GpuAssemblePaintUpdate)->WAXWORK_SIZES;
BENCHMARK(BM_SelectCoarseVertices)->ArgsProduct({{50000, 500000}, {0, 1}})->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

}  // namespace
}  // namespace waxwork

WAXWORK_BENCHMARK_MAIN()
