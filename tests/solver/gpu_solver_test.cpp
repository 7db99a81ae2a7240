// The GPU solver (OpenGL 4.3 compute shaders) against the CPU path, on Mesa's llvmpipe through OSMesa
// in CI: kernels, CG on spot and on a cut spot, the per-frame warm start, row updates after painting,
// and the fallback to the CPU when a shader fails.
#include "gl/gl_context.h"
#include "io/surface_reader.h"
#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "solver/diffusion_solve.h"
#include "solver/gpu/gpu_conjugate_gradient.h"
#include "solver/gpu/gpu_kernels.h"
#include "solver/gpu/gpu_matrix.h"
#include "solver/gpu/gpu_radiance.h"
#include "solver/gpu_test_context.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "solver/radiance.h"
#include "solver/solver_test_meshes.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/relaxation.h"
#include "tetops/tetrahedralize.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>

namespace waxwork {
namespace {

struct System {
    TetMesh mesh;
    TetConnectivity conn;
    std::vector<TetMaterial> materials;
    DiffusionMatrix matrix;
    std::vector<std::array<double, 3>> q;
};

System make_system(TetMesh mesh, double mm_per_unit, const Eigen::Vector3d& light_direction) {
    System s;
    s.mesh = std::move(mesh);
    s.conn = build_connectivity(s.mesh);
    s.materials.assign(s.mesh.tet_count(), material_preset("marble"));
    AssemblyOptions assembly;
    assembly.mm_per_unit = mm_per_unit;
    s.matrix = assemble_diffusion_matrix(s.mesh, s.conn, s.materials, assembly);
    Lighting lighting;
    Light light;
    light.vector = light_direction;
    lighting.lights.push_back(light);
    s.q = incident_light(s.mesh, s.conn, s.materials, lighting);
    return s;
}

const System& cube_system() {
    static const System s = make_system(test::make_cube_mesh(8, 2.0), 1.0, Eigen::Vector3d(-1, -2, -1));
    return s;
}

TetMesh spot_mesh() {
    MeshingOptions options;
    options.sizing.target_tets = 50'000;  // TetGen keeps spot's triangles: about the smallest spot volume
    return tetrahedralize(load_closed_surface(std::string(WAXWORK_ASSET_DIR) + "/meshes/spot.obj").surface, options)
        .mesh;
}

// Spot cut in half along its longest axis (remove_cut_away_tets + relax_cut_vertices), lit on the cut.
const System& cut_spot_system() {
    static const System s = [] {
        TetMesh mesh = spot_mesh();
        Eigen::AlignedBox3d box;
        for (const auto& p : mesh.positions) box.extend(p);
        Eigen::Index axis = 0;
        box.sizes().maxCoeff(&axis);
        const Eigen::Vector3d normal = Eigen::Vector3d::Unit(axis);
        const PlaneCut plane(normal, normal.dot(box.center()));
        remove_cut_away_tets(mesh, plane);
        relax_cut_vertices(mesh, build_connectivity(mesh), plane);
        return make_system(std::move(mesh), 60.0 / box.sizes().maxCoeff(), -normal + Eigen::Vector3d(0, -0.5, 0.3));
    }();
    return s;
}

const System& spot_system() {
    static const System s = [] {
        TetMesh mesh = spot_mesh();
        Eigen::AlignedBox3d box;
        for (const auto& p : mesh.positions) box.extend(p);
        return make_system(std::move(mesh), 60.0 / box.sizes().maxCoeff(), Eigen::Vector3d(-1, -2, -1));
    }();
    return s;
}

std::vector<float> interleaved(const std::vector<std::array<double, 3>>& v) {
    std::vector<float> out;
    for (const auto& x : v)
        for (double c : x) out.push_back(static_cast<float>(c));
    return out;
}

std::vector<std::array<double, 3>> random_vector(size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<std::array<double, 3>> v(n);
    for (auto& x : v) x = {u(rng), u(rng), u(rng)};
    return v;
}

// max_i |a - b| / max_i |b| per channel, the worst channel.
double relative_difference(const std::vector<std::array<double, 3>>& a, const std::vector<std::array<double, 3>>& b) {
    double worst = 0;
    for (int c = 0; c < 3; ++c) {
        double diff = 0, peak = 0;
        for (size_t i = 0; i < b.size(); ++i) {
            diff = std::max(diff, std::abs(a[i][c] - b[i][c]));
            peak = std::max(peak, std::abs(b[i][c]));
        }
        worst = std::max(worst, diff / peak);
    }
    return worst;
}

std::vector<std::array<double, 3>> cpu_double_solution(const System& s, double tolerance) {
    DiffusionOptions options;
    options.relative_tolerance = tolerance;
    DiffusionSolution solution;
    solve_diffusion_system(s.matrix, s.q, options, solution);
    return solution.phi;
}

TEST(GpuMatrixLayout, SlicedFormatsStoreEveryEntryOnceAndKeepRows) {
    const DiffusionMatrix& m = cube_system().matrix;
    for (GpuMatrixFormat f : {GpuMatrixFormat::Ell, GpuMatrixFormat::SellCSigma}) {
        const GpuMatrixLayout layout = make_gpu_matrix_layout(rgb_csr_view(m), f, 32, 128);
        std::vector<int> used(layout.stored_entries(), 0);
        for (size_t k = 0; k < m.nonzeros(); ++k) {
            ASSERT_EQ(layout.columns[layout.stored_index[k]], m.columns[k]);
            ++used[layout.stored_index[k]];
        }
        EXPECT_EQ(*std::max_element(used.begin(), used.end()), 1) << to_string(f);
        std::vector<int> seen(m.size(), 0);
        for (int32_t row : layout.slot_rows)
            if (row >= 0) ++seen[row];
        EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<long>(m.size())) << to_string(f);
        for (size_t i = 0; i < m.size(); ++i) EXPECT_EQ(layout.diagonal[i], layout.stored_index[m.diagonal[i]]);
    }
    // Sorting within sigma windows pads less than ELLPACK's global width.
    EXPECT_LT(make_gpu_matrix_layout(rgb_csr_view(m), GpuMatrixFormat::SellCSigma).stored_entries(),
              make_gpu_matrix_layout(rgb_csr_view(m), GpuMatrixFormat::Ell).stored_entries());
}

TEST(GpuKernels, ProductDotAndAxpbyMatchTheCpu) {
    WAXWORK_REQUIRE_GL(context);
    const DiffusionMatrix& m = spot_system().matrix;
    const size_t n = m.size();
    GpuKernels kernels(context->gl());
    const auto x = random_vector(n, 1), y = random_vector(n, 2);
    const GpuBuffer xg = kernels.vector(n, interleaved(x).data());
    for (GpuMatrixFormat f : {GpuMatrixFormat::Csr, GpuMatrixFormat::Ell, GpuMatrixFormat::SellCSigma}) {
        const GpuMatrix gm(context->gl(), rgb_csr_view(m), f);
        GpuBuffer qg = kernels.vector(n);
        const Rgbd pq = kernels.multiply_dot(gm, xg, qg);
        const std::vector<float> q = qg.download<float>();
        for (int c = 0; c < 3; ++c) {
            std::vector<double> xc(n), qc(n);
            for (size_t i = 0; i < n; ++i) xc[i] = static_cast<float>(x[i][c]);
            const CsrMatrixView<double> view{n, m.offsets.data(), m.columns.data(), m.values[c].data()};
            multiply<double>(view, xc, qc);
            double worst = 0, peak = 0, dot = 0;
            for (size_t i = 0; i < n; ++i) {
                worst = std::max(worst, std::abs(q[3 * i + c] - qc[i]));
                peak = std::max(peak, std::abs(qc[i]));
                dot += xc[i] * qc[i];
            }
            EXPECT_LT(worst, 1e-5 * peak) << to_string(f) << " channel " << c;
            EXPECT_NEAR(pq[c], dot, 1e-5 * std::abs(dot) + 1e-6 * peak) << to_string(f) << " channel " << c;
        }
    }
    const GpuBuffer yg = kernels.vector(n, interleaved(y).data());
    const Rgbd d = kernels.dot(n, xg, yg);
    GpuBuffer zg = kernels.vector(n, interleaved(y).data());
    kernels.axpby(n, {2, -1, 0.5}, xg, {1, 3, 0}, zg);
    const std::vector<float> z = zg.download<float>();
    const Rgbd a{2, -1, 0.5}, b{1, 3, 0};
    for (int c = 0; c < 3; ++c) {
        double dot = 0;
        for (size_t i = 0; i < n; ++i) {
            const double xi = static_cast<float>(x[i][c]), yi = static_cast<float>(y[i][c]);
            dot += xi * yi;
            ASSERT_NEAR(z[3 * i + c], a[c] * xi + b[c] * yi, 1e-6) << "axpby channel " << c << " row " << i;
        }
        EXPECT_NEAR(d[c], dot, 1e-4 * std::sqrt(static_cast<double>(n))) << "dot channel " << c;
    }
}

// The correctness bar: float GPU CG at a tight tolerance against double CPU CG, 1e-4 relative.
void expect_gpu_matches_cpu(const System& s, GpuMatrixFormat format, const char* label) {
    WAXWORK_REQUIRE_GL(context);
    const auto reference = cpu_double_solution(s, 1e-9);
    GpuCgOptions options;
    options.relative_tolerance = 1e-5;
    std::vector<std::array<double, 3>> phi;
    const auto results = solve_diffusion_gpu(context->gl(), s.matrix, s.q, options, phi, format);
    for (int c = 0; c < 3; ++c) {
        EXPECT_TRUE(results[c].converged) << label << " channel " << c << " error "
                                          << results[c].estimated_relative_error;
        EXPECT_GT(results[c].iterations, 0);
    }
    const double difference = relative_difference(phi, reference);
    std::printf("%s (%s, %zu vertices): GPU float vs CPU double max relative difference %.2e, iterations %d %d %d\n",
                label, to_string(format).c_str(), s.matrix.size(), difference, results[0].iterations,
                results[1].iterations, results[2].iterations);
    EXPECT_LT(difference, 1e-4) << label;
}

TEST(GpuConjugateGradient, MatchesCpuDoubleOnSpot) { expect_gpu_matches_cpu(spot_system(), GpuMatrixFormat::Csr, "spot"); }

TEST(GpuConjugateGradient, MatchesCpuDoubleOnCutSpot) {
    expect_gpu_matches_cpu(cut_spot_system(), GpuMatrixFormat::Csr, "cut spot");
}

TEST(GpuConjugateGradient, SellCSigmaGivesTheSameSolution) {
    expect_gpu_matches_cpu(cube_system(), GpuMatrixFormat::SellCSigma, "cube");
}

TEST(GpuConjugateGradient, StopsByTheSameRuleAsTheCpuFloatPath) {
    WAXWORK_REQUIRE_GL(context);
    const System& s = spot_system();
    DiffusionOptions cpu;
    cpu.precision = SolverPrecision::Float;
    cpu.relative_tolerance = 1e-3;
    DiffusionSolution cpu_solution;
    solve_diffusion_system(s.matrix, s.q, cpu, cpu_solution);
    DiffusionOptions gpu = cpu;
    gpu.backend = SolverBackend::Gpu;
    gpu.gl = &context->gl();
    DiffusionSolution gpu_solution;
    solve_diffusion_system(s.matrix, s.q, gpu, gpu_solution);
    EXPECT_EQ(gpu_solution.backend, SolverBackend::Gpu) << gpu_solution.gpu_fallback_reason;
    for (int c = 0; c < 3; ++c) {
        // Same algorithm in float, different summation order: iteration counts within a few.
        EXPECT_NEAR(gpu_solution.iterations[c], cpu_solution.iterations[c], 3 + 0.05 * cpu_solution.iterations[c]);
        EXPECT_LE(gpu_solution.estimated_relative_error[c], 1e-3);
    }
    EXPECT_LT(relative_difference(gpu_solution.phi, cpu_double_solution(s, 1e-9)), 1e-2);
}

TEST(GpuDiffusionSolver, FrameBudgetsWarmStartAndConverge) {
    WAXWORK_REQUIRE_GL(context);
    const System& s = spot_system();
    GpuDiffusionSolver solver(context->gl(), s.matrix);
    solver.set_light(s.matrix, s.q);
    const double tolerance = 1e-4;
    bool converged = false;
    int frames = 0;
    for (; frames < 200 && !converged; ++frames) converged = solver.solve_frame(10, tolerance);
    ASSERT_TRUE(converged) << "10-iteration frames did not converge in 200 frames";
    EXPECT_GT(frames, 1) << "a cold start cannot converge within one 10-iteration frame";
    EXPECT_LT(relative_difference(solver.solution(), cpu_double_solution(s, 1e-9)), 1e-3);
    // Converged and unchanged: the next frame stops at once with the remembered eigenvalue estimates.
    GpuCgOptions again;
    again.relative_tolerance = tolerance;
    again.use_eigenvalue_hints = true;
    const auto results = solver.solve(again);
    for (const auto& r : results) {
        EXPECT_TRUE(r.converged);
        EXPECT_LE(r.iterations, 1);
    }
    // A small change of the light is absorbed from the warm start in fewer iterations than cold.
    auto q2 = s.q;
    for (auto& v : q2) v[0] *= 1.05;
    solver.set_light(s.matrix, q2);
    GpuCgOptions options;
    options.relative_tolerance = tolerance;
    const int warm = solver.solve(options)[0].iterations;
    std::vector<std::array<double, 3>> cold_phi;
    const int cold = solve_diffusion_gpu(context->gl(), s.matrix, q2, options, cold_phi)[0].iterations;
    EXPECT_LT(warm, cold);
}

TEST(GpuDiffusionSolver, RowUpdateAfterPaintingEqualsReupload) {
    WAXWORK_REQUIRE_GL(context);
    System s = cube_system();
    GpuDiffusionSolver updated(context->gl(), s.matrix, GpuMatrixFormat::SellCSigma);
    // "Paint" a blob of tets with ketchup.
    std::vector<int32_t> painted;
    for (size_t t = 0; t < s.mesh.tet_count(); t += 7) {
        s.materials[t] = material_preset("ketchup");
        painted.push_back(static_cast<int32_t>(t));
    }
    const std::vector<int32_t> rows = update_diffusion_matrix(s.matrix, s.mesh, s.conn, s.materials, painted);
    ASSERT_FALSE(rows.empty());
    updated.update_rows(s.matrix, rows);
    const GpuDiffusionSolver fresh(context->gl(), s.matrix, GpuMatrixFormat::SellCSigma);
    EXPECT_EQ(updated.matrix().values.download<float>(), fresh.matrix().values.download<float>());
    // And solving gives the same answer bit for bit (same values, same deterministic reductions).
    updated.set_light(s.matrix, s.q);
    GpuCgOptions options;
    options.relative_tolerance = 1e-4;
    updated.solve(options);
    std::vector<std::array<double, 3>> phi;
    solve_diffusion_gpu(context->gl(), s.matrix, s.q, options, phi, GpuMatrixFormat::SellCSigma);
    EXPECT_EQ(updated.solution(), phi);
}

TEST(GpuDiffusionSolver, ShaderFailureFallsBackToTheCpuWithTheDriverLog) {
    WAXWORK_REQUIRE_GL(context);
    const System& s = cube_system();
    setenv("WAXWORK_GPU_FORCE_FAIL", "cg_update", 1);
    try {
        GpuDiffusionSolver solver(context->gl(), s.matrix);
        ADD_FAILURE() << "a corrupted shader compiled";
    } catch (const GpuError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("cg_update"), std::string::npos) << what;
        EXPECT_NE(what.find("failed to compile"), std::string::npos) << what;
        EXPECT_NE(what.find("WAXWORK_GPU_FORCE_FAIL"), std::string::npos) << "driver log missing: " << what;
    }
    DiffusionOptions options;
    options.backend = SolverBackend::Gpu;
    options.gl = &context->gl();
    DiffusionSolution solution;
    solve_diffusion_system(s.matrix, s.q, options, solution);
    unsetenv("WAXWORK_GPU_FORCE_FAIL");
    EXPECT_EQ(solution.backend, SolverBackend::Cpu);
    EXPECT_NE(solution.gpu_fallback_reason.find("cg_update"), std::string::npos);
    EXPECT_LT(relative_difference(solution.phi, cpu_double_solution(s, 1e-9)), 1e-2);

    options.gl = nullptr;  // no context at all: also a fallback, not an error
    solve_diffusion_system(s.matrix, s.q, options, solution);
    EXPECT_EQ(solution.backend, SolverBackend::Cpu);
    EXPECT_FALSE(solution.gpu_fallback_reason.empty());
}

TEST(GpuRadiance, ExitantRadianceFactorsMatchTheCpuPerShadingVertex) {
    WAXWORK_REQUIRE_GL(context);
    const System& s = spot_system();
    GpuDiffusionSolver solver(context->gl(), s.matrix);
    solver.set_light(s.matrix, s.q);
    GpuCgOptions options;
    options.relative_tolerance = 1e-4;
    solver.solve(options);
    const auto phi = solver.solution();
    // Shading vertices: spot's boundary split at a small crease angle, so that many surface vertices
    // have copies; each copy gets its own q (here: its vertex's scaled by the copy's rank), several
    // rows then read the same phi.
    const BoundarySurface surface = extract_boundary_surface(s.mesh, s.conn, s.materials);
    const ShadingSurface shading = split_at_creases(surface, 10.0);
    ASSERT_GT(shading.size(), surface.vertices.size());
    std::vector<Rgb> q(shading.size());
    for (size_t d = 0; d < shading.size(); ++d) {
        const Rgb& vertex_q = s.q[surface.vertices[shading.surface_vertex[d]]];
        const double scale = d < surface.vertices.size() ? 1.0 : 0.25;
        for (int c = 0; c < 3; ++c) q[d][c] = scale * vertex_q[c];
    }
    GpuRadiance radiance(solver.kernels(), shading_radiance_rows(surface, shading), s.matrix.size());
    ASSERT_EQ(radiance.size(), shading.size());
    radiance.set_light(q);
    for (const bool clamp : {true, false}) {
        GpuBuffer e = solver.kernels().vector(shading.size());
        radiance.compute(solver.solution_buffer(), e, RadianceOptions{clamp});
        const std::vector<float> gpu = e.download<float>();
        const auto cpu = shading_radiance_factors(surface, shading, phi, q, RadianceOptions{clamp});
        double peak = 0, diff = 0;
        for (size_t i = 0; i < cpu.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                peak = std::max(peak, static_cast<double>(std::abs(cpu[i][c])));
                diff = std::max(diff, static_cast<double>(std::abs(cpu[i][c] - gpu[3 * i + c])));
            }
        ASSERT_GT(peak, 0);
        EXPECT_LT(diff, 1e-5 * peak) << (clamp ? "clamped" : "unclamped");
    }
    // Rows that read no vertex of phi, or whose eta no material has, are refused.
    const auto rows = [](std::vector<int32_t> vertex, std::vector<double> eta) {
        return RadianceRows{std::move(vertex), std::move(eta)};
    };
    EXPECT_THROW(GpuRadiance(solver.kernels(), rows({0, static_cast<int32_t>(s.matrix.size())}, {1.3, 1.3}),
                             s.matrix.size()),
                 InvalidArgumentError);
    EXPECT_THROW(GpuRadiance(solver.kernels(), rows({0}, {std::nan("")}), s.matrix.size()), InvalidArgumentError);
    EXPECT_THROW(GpuRadiance(solver.kernels(), rows({0, 1}, {1.3}), s.matrix.size()), InvalidArgumentError);
    ShadingSurface stray = shading;
    stray.surface_vertex.back() = static_cast<int32_t>(surface.vertices.size());
    EXPECT_THROW(shading_radiance_rows(surface, stray), InvalidArgumentError);
}

// WAXWORK_GL_DEVICE=egl: the path to a real GPU without a display. Here EGL finds llvmpipe again
// (through a software device or Mesa's surfaceless platform); the solver must give the same answer.
TEST(GpuDiffusionSolver, RunsOnAnEglContext) {
    const System& s = cube_system();
    std::vector<std::array<double, 3>> phi;
    std::string renderer;
    {
        std::unique_ptr<HeadlessGlContext> egl;
        try {
            egl = std::make_unique<HeadlessGlContext>(GlDevice::Egl);
        } catch (const Error& e) {
            GTEST_SKIP() << "no EGL OpenGL 4.3 context here: " << e.what();
        }
        renderer = egl->renderer();
        GpuCgOptions options;
        options.relative_tolerance = 1e-5;
        solve_diffusion_gpu(egl->gl(), s.matrix, s.q, options, phi);
    }
    std::printf("EGL renderer: %s\n", renderer.c_str());
    EXPECT_LT(relative_difference(phi, cpu_double_solution(s, 1e-9)), 1e-4);
}

}  // namespace
}  // namespace waxwork
