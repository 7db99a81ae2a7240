// The device multigrid CG (multires/gpu_multigrid_frame_solver.h) against the CPU frame solver and the
// double-precision solution, on llvmpipe in CI.
#include "base/error.h"
#include "multires/gpu_multigrid_frame_solver.h"
#include "multires/multigrid_frame_solver.h"
#include "solver/gpu/gpu_conjugate_gradient.h"
#include "solver/gpu_test_context.h"
#include "solver/material.h"
#include "tetops/box_mesh.h"
#include "tetops/sliver_maker.h"
#include "multires_test_systems.h"

#include <gtest/gtest.h>

#include <cmath>

namespace waxwork {
namespace {

using testing::reference_solution;
using testing::relative_error;

FrameSolverOptions frame_options(int64_t min_coarse, double tolerance) {
    FrameSolverOptions options;
    options.hierarchy.min_coarse_vertices = min_coarse;
    options.relative_tolerance = tolerance;
    return options;
}

using testing::spans;

// The device frame solver and the CPU one on the same system, with the same options and b.
struct BothBackends {
    GpuMultigridFrameSolver gpu;
    MultigridFrameSolver cpu;
    BothBackends(const GlApi& gl, const testing::TestSystem& s, const FrameSolverOptions& options)
        : gpu(gl, s.matrix, s.mesh.positions, options), cpu(s.matrix, s.mesh.positions, options) {}
    void set_right_hand_side(const std::array<std::vector<double>, 3>& b) {
        gpu.set_right_hand_side(spans(b));
        cpu.set_right_hand_side(spans(b));
    }
};

// The bound the other GPU tests hold float solvers to against the double solution.
constexpr double kFloatSolutionBound = 1e-4;

TEST(GpuMultigridFrameSolver, ConvergesToTheDoublePrecisionSolutionInFarFewerIterationsThanJacobiCg) {
    WAXWORK_REQUIRE_GL(context);
    const auto s = testing::make_test_system(12);  // 2197 vertices
    GpuMultigridFrameSolver solver(context->gl(), s.matrix, s.mesh.positions, frame_options(100, 1e-6));
    ASSERT_GE(solver.hierarchy().level_count(), 3u);
    solver.set_right_hand_side(spans(s.b));
    FrameStep step;
    int vcycles = 0;
    for (int frames = 0; frames < 20 && !step.converged; ++frames) {
        step = solver.step(5);
        vcycles += step.vcycles;
    }
    EXPECT_TRUE(step.converged);
    const auto phi = solver.phi();
    for (int c = 0; c < 3; ++c) {
        const auto cu = static_cast<size_t>(c);
        EXPECT_LE(step.estimated_relative_error[cu], 1e-6);
        EXPECT_LT(relative_error(phi[cu], reference_solution(s.matrix, s.b[cu], c)), kFloatSolutionBound)
            << "channel " << c;
    }
    // GPU Jacobi CG on the same system to the same tolerance.
    GpuDiffusionSolver jacobi(context->gl(), s.matrix);
    jacobi.set_right_hand_side(s.b);
    GpuCgOptions options;
    options.relative_tolerance = 1e-6;
    const auto results = jacobi.solve(options);
    int jacobi_iterations = 0;
    for (const auto& r : results) jacobi_iterations = std::max(jacobi_iterations, r.iterations);
    std::printf("[ measured ] %d V-cycles against %d Jacobi CG iterations to 1e-6\n", vcycles, jacobi_iterations);
    EXPECT_LT(4 * vcycles, jacobi_iterations);
}

// A hierarchy built elsewhere (rebuilt after an edit) gives the same device solver as its own build;
// one built for another matrix is refused (the checks are the CPU solver's, multigrid_frame_cg.h).
TEST(GpuMultigridFrameSolver, TakesAHierarchyBuiltForItsMatrix) {
    WAXWORK_REQUIRE_GL(context);
    const auto s = testing::make_test_system(8);
    const FrameSolverOptions options;
    GpuMultigridFrameSolver own(context->gl(), s.matrix, s.mesh.positions, options);
    GpuMultigridFrameSolver given(context->gl(), s.matrix,
                                  build_multires_hierarchy(s.matrix, s.mesh.positions, options.hierarchy), options);
    own.set_right_hand_side(spans(s.b));
    given.set_right_hand_side(spans(s.b));
    own.step(3);
    given.step(3);
    EXPECT_EQ(own.phi(), given.phi());
    // With its preconditioner built beforehand on the host (MultigridOperators), too.
    MultigridOperators operators;
    operators.hierarchy =
        std::make_unique<MultiresHierarchy>(build_multires_hierarchy(s.matrix, s.mesh.positions, options.hierarchy));
    operators.preconditioner = std::make_unique<MultigridPreconditioner>(*operators.hierarchy, options.multigrid);
    GpuMultigridFrameSolver prebuilt(context->gl(), s.matrix, std::move(operators), options);
    prebuilt.set_right_hand_side(spans(s.b));
    prebuilt.step(3);
    EXPECT_EQ(own.phi(), prebuilt.phi());
    MultigridOperators mismatched;
    mismatched.hierarchy =
        std::make_unique<MultiresHierarchy>(build_multires_hierarchy(s.matrix, s.mesh.positions, options.hierarchy));
    mismatched.preconditioner = std::make_unique<MultigridPreconditioner>(own.hierarchy(), options.multigrid);
    EXPECT_THROW(GpuMultigridFrameSolver(context->gl(), s.matrix, std::move(mismatched), options), InvalidArgumentError);
    EXPECT_THROW(GpuMultigridFrameSolver(context->gl(), s.matrix, MultigridOperators{}, options), InvalidArgumentError);
    const auto small = testing::make_test_system(4);
    EXPECT_THROW(GpuMultigridFrameSolver(context->gl(), s.matrix,
                                         build_multires_hierarchy(small.matrix, small.mesh.positions), options),
                 InvalidArgumentError);
}

// The CPU frame solver and the device one take the same steps: after the same V-cycle budget their
// iterates agree to float precision (the CPU runs phi, r and the products in double).
TEST(GpuMultigridFrameSolver, FollowsTheCpuFrameSolverStepByStep) {
    WAXWORK_REQUIRE_GL(context);
    const auto s = testing::make_test_system(10);
    BothBackends both(context->gl(), s, frame_options(60, 1e-8));
    both.set_right_hand_side(s.b);
    for (int frame = 0; frame < 3; ++frame) {
        const FrameStep g = both.gpu.step(2), c = both.cpu.step(2);
        EXPECT_EQ(g.vcycles, c.vcycles);
        const auto phi = both.gpu.phi();
        for (int ch = 0; ch < 3; ++ch) {
            const auto cu = static_cast<size_t>(ch);
            EXPECT_NEAR(g.estimated_relative_error[cu], c.estimated_relative_error[cu],
                        1e-3 * c.estimated_relative_error[cu] + 1e-6);
            EXPECT_LT(relative_error(phi[cu], both.cpu.phi(ch)), kFloatSolutionBound) << "frame " << frame;
        }
    }
}

// A frame's claim of convergence is confirmed against the double residual without a V-cycle of its
// own where that residual barely moved: at 1e-2 the device takes the CPU's V-cycles, cold and warm.
TEST(GpuMultigridFrameSolver, ConfirmsAFramesClaimWithoutAnExtraVcycle) {
    WAXWORK_REQUIRE_GL(context);
    const auto s = testing::make_test_system(16);
    BothBackends both(context->gl(), s, frame_options(100, 1e-2));
    for (const double degrees : {0.0, 10.0}) {
        both.set_right_hand_side(testing::light_rhs(s, degrees));
        const FrameStep g = both.gpu.step(50), c = both.cpu.step(50);
        EXPECT_TRUE(g.converged);
        EXPECT_TRUE(c.converged);
        EXPECT_EQ(g.vcycles, c.vcycles) << degrees;
    }
}

TEST(GpuMultigridFrameSolver, WarmStartAfterALightTurnIsBackUnderOnePercentInAFewVcycles) {
    WAXWORK_REQUIRE_GL(context);
    const auto s = testing::make_test_system(12);
    GpuMultigridFrameSolver solver(context->gl(), s.matrix, s.mesh.positions, frame_options(100, 1e-2));
    const auto before = testing::light_rhs(s, 0), after = testing::light_rhs(s, 10);
    solver.set_right_hand_side(spans(before));
    FrameStep step = testing::step_until_converged(solver, 4, 20);
    ASSERT_TRUE(step.converged);
    std::array<std::vector<double>, 3> reference;
    auto phi = solver.phi();
    for (int c = 0; c < 3; ++c) {
        const auto cu = static_cast<size_t>(c);
        reference[cu] = reference_solution(s.matrix, after[cu], c);
        ASSERT_GT(relative_error(phi[cu], reference[cu]), 2e-2) << "the turn must change the solution";
    }
    solver.set_right_hand_side(spans(after));
    step = solver.step(2);
    EXPECT_LE(step.vcycles, 2);
    phi = solver.phi();
    for (int c = 0; c < 3; ++c)
        EXPECT_LT(relative_error(phi[static_cast<size_t>(c)], reference[static_cast<size_t>(c)]), 1e-2) << "channel " << c;
    if (!step.converged) step = testing::step_until_converged(solver, 1, 10);
    EXPECT_TRUE(step.converged);
}

// On a box whose interior is pushed into caps of relative height 1e-5, the device's float copy of M
// solves a system about 2e-4 from the double one. The residual the device solver trusts is the double
// system's: a tolerance float reaches is met against the double solution, and one below float's floor
// on this mesh stops early, saying so, with phi refined towards the double solution all the same.
TEST(GpuMultigridFrameSolver, OnSliversMeasuresTheDoubleSystemAndStopsAtItsFloor) {
    WAXWORK_REQUIRE_GL(context);
    TetMesh mesh = make_box_mesh({10, 10, 10}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(1));
    const TetConnectivity connectivity = build_connectivity(mesh);
    flatten_into_slivers(mesh, connectivity, 6, 1e-5);
    const std::vector<TetMaterial> materials(mesh.tet_count(), material_preset("marble"));
    const DiffusionMatrix matrix = assemble_diffusion_matrix(mesh, connectivity, materials);
    std::array<std::vector<double>, 3> b;
    for (auto& channel : b) channel.assign(matrix.size(), 0.0);
    for (const int32_t v : connectivity.boundary_vertices)
        for (size_t c = 0; c < 3; ++c) b[c][static_cast<size_t>(v)] = (1.0 + 0.1 * mesh.positions[v].x()) * double(c + 1);
    MultigridFrameSolver cpu(matrix, mesh.positions, frame_options(64, 1e-10));
    cpu.set_right_hand_side(spans(b));
    ASSERT_TRUE(cpu.step(500).converged);

    constexpr int kBudget = 2000;
    for (const double tolerance : {1e-4, 1e-8}) {
        SCOPED_TRACE(tolerance);
        FrameSolverOptions options;
        options.relative_tolerance = tolerance;
        GpuMultigridFrameSolver gpu(context->gl(), matrix, mesh.positions, options);
        gpu.set_right_hand_side(spans(b));
        const FrameStep step = gpu.step(kBudget);
        const auto phi = gpu.phi();
        for (int c = 0; c < 3; ++c) {
            const std::span<const double> reference = cpu.phi(c);
            const double error = relative_error(phi[static_cast<size_t>(c)], {reference.begin(), reference.end()});
            if (tolerance == 1e-4) EXPECT_LT(error, tolerance) << "channel " << c;
            else EXPECT_LT(error, 1e-6) << "channel " << c;  // refined towards the double solution
        }
        if (tolerance == 1e-4) {
            EXPECT_TRUE(step.converged);
            EXPECT_FALSE(step.at_precision_floor);
        } else {
            EXPECT_FALSE(step.converged);
            EXPECT_TRUE(step.at_precision_floor);
            EXPECT_LT(step.vcycles, kBudget);
            for (double e : step.estimated_relative_error) EXPECT_GT(e, tolerance);
        }
    }
}

TEST(GpuMultigridFrameSolver, FollowsPaintedValues) {
    WAXWORK_REQUIRE_GL(context);
    auto s = testing::make_test_system(8);
    GpuMultigridFrameSolver solver(context->gl(), s.matrix, s.mesh.positions, frame_options(30, 1e-6));
    testing::expect_follows_painted_values(solver, s, kFloatSolutionBound);
}

// A time budget stops between V-cycles (a fake clock: no timing in unit tests), and a budget that ran k
// V-cycles equals step(k).
TEST(GpuMultigridFrameSolver, TimeBudgetStopsBetweenVcyclesLikeAVcycleBudget) {
    WAXWORK_REQUIRE_GL(context);
    const auto s = testing::make_test_system(8);
    const FrameSolverOptions options = frame_options(30, 1e-12);
    GpuMultigridFrameSolver timed(context->gl(), s.matrix, s.mesh.positions, options);
    GpuMultigridFrameSolver counted(context->gl(), s.matrix, s.mesh.positions, options);
    timed.set_right_hand_side(spans(s.b));
    counted.set_right_hand_side(spans(s.b));
    double now = 0;
    // Each clock read advances 1 ms: the deadline (3.5 ms) reads 0 at the start, then once per V-cycle.
    const MillisecondClock clock = [&now] { return now++; };
    const FrameStep step = timed.step(FrameBudget::milliseconds(3.5), clock);
    EXPECT_GT(step.vcycles, 1);  // the deadline allows several reads
    EXPECT_LT(step.vcycles, 10);
    counted.step(step.vcycles);
    const auto a = timed.phi(), b = counted.phi();
    EXPECT_EQ(a, b);
    EXPECT_EQ(timed.step(FrameBudget::iterations(2)).vcycles, 2);
}

TEST(GpuMultigridFrameSolver, RejectsBadInput) {
    WAXWORK_REQUIRE_GL(context);
    const auto s = testing::make_test_system(5);
    GpuMultigridFrameSolver solver(context->gl(), s.matrix, s.mesh.positions, frame_options(20, 1e-2));
    testing::expect_refuses_steps_without_a_valid_b(solver, s);
    std::vector<double> nan_b = s.b[0];
    nan_b[3] = std::nan("");
    EXPECT_THROW(solver.set_phi({nan_b, s.b[1], s.b[2]}), AlgorithmError);
    solver.set_right_hand_side(spans(s.b));
    EXPECT_THROW(solver.step(0), InvalidArgumentError);
    EXPECT_THROW(solver.step(FrameBudget{}), InvalidArgumentError);
    EXPECT_THROW(solver.set_relative_tolerance(-1), InvalidArgumentError);
    EXPECT_THROW(solver.update_values(s.matrix, std::vector<int32_t>{-1}), InvalidArgumentError);
    testing::expect_zero_b_solved_at_once(solver);
}

}  // namespace
}  // namespace waxwork
