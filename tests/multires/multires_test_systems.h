// Small assembled diffusion systems for the multires tests.
#pragma once

#include "base/error.h"
#include "multires/gpu_multigrid_frame_solver.h"
#include "multires/hierarchy.h"
#include "multires/multigrid_frame_cg.h"
#include "multires/multigrid_frame_solver.h"
#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "tetops/box_mesh.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/relaxation.h"
#include "tetops/sliver_maker.h"
#include "tetops/test_meshes.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <span>
#include <vector>

namespace waxwork::testing {

struct TestSystem {
    TetMesh mesh;
    TetConnectivity connectivity;
    DiffusionMatrix matrix;
    std::array<std::vector<double>, 3> b;  // right-hand side per channel
};

// Default hierarchy options that keep coarsening down to `min_coarse` vertices (the test systems are
// small, so the default stopping size would leave one or two levels).
inline HierarchyOptions small_levels(int64_t min_coarse) {
    HierarchyOptions options;
    options.min_coarse_vertices = min_coarse;
    return options;
}

// The material of every tet of make_test_system.
inline TetMaterial test_material() { return TetMaterial{{0.01, 0.05, 0.2}, {1, 1, 1}, 1.3}; }

// A cube of n^3 * 6 tets with a different absorption per channel, lit unevenly on its boundary.
inline TestSystem make_test_system(int n, double size = 4.0) {
    TestSystem s;
    s.mesh = make_cube_mesh(n, Eigen::Vector3d::Zero(), size);
    s.connectivity = build_connectivity(s.mesh);
    const std::vector<TetMaterial> materials(s.mesh.tet_count(), test_material());
    s.matrix = assemble_diffusion_matrix(s.mesh, s.connectivity, materials);
    std::vector<std::array<double, 3>> q(s.mesh.vertex_count());
    for (size_t v = 0; v < q.size(); ++v) {
        const Eigen::Vector3d& x = s.mesh.positions[v];
        const double light = x.z() > 0.75 * size ? 1.0 + x.x() : 0.1;  // a bright top, a dim rest
        q[v] = {light, 0.5 * light, 0.25 * light};
    }
    for (int c = 0; c < 3; ++c) {
        s.b[static_cast<size_t>(c)].resize(s.mesh.vertex_count());
        diffusion_right_hand_side(s.matrix, q, c, s.b[static_cast<size_t>(c)]);
    }
    return s;
}

// The right-hand sides of the test cube lit by the key light turned by `degrees` about the vertical.
inline std::array<std::vector<double>, 3> light_rhs(const TestSystem& s, double degrees) {
    const std::vector<TetMaterial> materials(s.mesh.tet_count(), test_material());
    Lighting lighting;
    Light light;
    light.vector = Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d::UnitY()) *
                   Eigen::Vector3d(1, -1, -1).normalized();
    lighting.lights.push_back(light);
    const std::vector<Rgb> q = incident_light(s.mesh, s.connectivity, materials, lighting);
    std::array<std::vector<double>, 3> b;
    for (int c = 0; c < 3; ++c) {
        b[static_cast<size_t>(c)].resize(s.matrix.size());
        diffusion_right_hand_side(s.matrix, q, c, b[static_cast<size_t>(c)]);
    }
    return b;
}

// Paints `count` tets (every `stride`-th) of a make_test_system volume with another material and
// updates the matrix in place; returns the rewritten rows (update_diffusion_matrix).
inline std::vector<int32_t> paint_test_system(TestSystem& s, int count, int stride) {
    std::vector<TetMaterial> materials(s.mesh.tet_count(), test_material());
    std::vector<int32_t> painted;
    for (int32_t t = 0; t < count; ++t) {
        painted.push_back(t * stride);
        materials[static_cast<size_t>(t * stride)] = TetMaterial{{0.3, 0.02, 0.1}, {2, 1, 0.5}, 1.4};
    }
    return update_diffusion_matrix(s.matrix, s.mesh, s.connectivity, materials, painted);
}

// A make_test_system volume after a plane cut: the cut mesh's system and the cut's vertex map.
struct CutSystem {
    TetMesh mesh;
    TetConnectivity connectivity;
    DiffusionMatrix matrix;
    std::vector<int32_t> new_of_old;
};

inline CutSystem cut_system(const TetMesh& mesh, const Eigen::Vector3d& normal, double offset, int relax_sweeps = 0) {
    CutSystem c;
    c.mesh = mesh;
    const PlaneCut plane(normal, offset);
    c.new_of_old = remove_cut_away_tets(c.mesh, plane).old_to_new_vertex;
    c.connectivity = build_connectivity(c.mesh);
    if (relax_sweeps > 0) {
        RelaxationOptions relax;
        relax.max_iterations = relax_sweeps;
        relax.step = 0.3;
        relax_cut_vertices(c.mesh, c.connectivity, plane, relax);
    }
    const std::vector<TetMaterial> materials(c.mesh.tet_count(), testing::test_material());
    c.matrix = assemble_diffusion_matrix(c.mesh, c.connectivity, materials);
    return c;
}

// Frames of `budget` V-cycles until a frame converges, at most `max_frames`; the last frame's step.
inline FrameStep step_until_converged(MultigridFrameCg& solver, int budget, int max_frames) {
    FrameStep step;
    for (int frames = 0; frames < max_frames && !step.converged; ++frames) step = solver.step(budget);
    return step;
}

// The three channels as the frame solvers take them.
inline std::array<std::span<const double>, 3> spans(const std::array<std::vector<double>, 3>& v) {
    return {v[0], v[1], v[2]};
}

// A frame solver's phi, per channel, on the host.
inline std::array<std::vector<double>, 3> phi_of(const MultigridFrameSolver& solver) {
    std::array<std::vector<double>, 3> phi;
    for (int c = 0; c < 3; ++c) {
        const std::span<const double> channel = solver.phi(c);
        phi[static_cast<size_t>(c)].assign(channel.begin(), channel.end());
    }
    return phi;
}
inline std::array<std::vector<double>, 3> phi_of(const GpuMultigridFrameSolver& solver) { return solver.phi(); }

// sqrt(sum (x - reference)^2 / sum reference^2).
inline double relative_error(std::span<const double> x, std::span<const double> reference) {
    double e = 0, r = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        e += (x[i] - reference[i]) * (x[i] - reference[i]);
        r += reference[i] * reference[i];
    }
    return std::sqrt(e / r);
}

// The level-0 solution of `channel` for right-hand side `b`: Jacobi CG in double to `tolerance`.
inline std::vector<double> reference_solution(const DiffusionMatrix& m, std::span<const double> b, int channel,
                                              double tolerance = 1e-12) {
    std::vector<double> x(b.size(), 0.0);
    ConjugateGradientOptions options;
    options.relative_tolerance = tolerance;
    const CsrMatrixView<double> view{m.size(), m.offsets.data(), m.columns.data(),
                                     m.values[static_cast<size_t>(channel)].data()};
    EXPECT_TRUE(solve_jacobi_cg<double>(view, b, x, options).converged);
    return x;
}

// A box of 10^3 cells (10 mm, marble) whose interior vertices are pushed into caps of relative height
// 1e-5 (0.0009 degree dihedrals, as in the stability study), with a right-hand side on its boundary
// and the hierarchy of its system: where row-sum lumped Galerkin operators lose definiteness.
// Either frame solver on `s`: converges, follows 40 painted vertices (update_values) and converges
// again, each channel then within `bound` of the painted system's double solution.
template <class Solver>
void expect_follows_painted_values(Solver& solver, TestSystem& s, double bound) {
    solver.set_right_hand_side(spans(s.b));
    FrameStep step = step_until_converged(solver, 5, 20);
    ASSERT_TRUE(step.converged);
    const std::vector<int32_t> rows = paint_test_system(s, 40, 7);
    solver.update_values(s.matrix, rows);
    step = step_until_converged(solver, 5, 20);
    EXPECT_TRUE(step.converged);
    const auto phi = phi_of(solver);
    for (int c = 0; c < 3; ++c) {
        const auto reference = reference_solution(s.matrix, s.b[static_cast<size_t>(c)], c);
        EXPECT_LT(relative_error(phi[static_cast<size_t>(c)], reference), bound) << "channel " << c;
    }
}

// Either frame solver on `s`, before any right-hand side: a step, and a b of the wrong size or with a
// NaN, are refused.
inline void expect_refuses_steps_without_a_valid_b(MultigridFrameCg& solver, const TestSystem& s) {
    EXPECT_THROW(solver.step(1), InvalidArgumentError);  // no right-hand side yet
    std::vector<double> short_b(s.b[0].size() - 1);
    EXPECT_THROW(solver.set_right_hand_side({short_b, s.b[1], s.b[2]}), InvalidArgumentError);
    std::vector<double> nan_b = s.b[0];
    nan_b[3] = std::nan("");
    EXPECT_THROW(solver.set_right_hand_side({nan_b, s.b[1], s.b[2]}), AlgorithmError);
}

// Either frame solver: a zero right-hand side is solved by phi = 0 at once.
template <class Solver>
void expect_zero_b_solved_at_once(Solver& solver) {
    const std::vector<double> zero(solver.size(), 0.0);
    solver.set_right_hand_side({zero, zero, zero});
    solver.reset();
    const FrameStep step = solver.step(1);
    EXPECT_TRUE(step.converged);
    for (const auto& channel : phi_of(solver))
        for (double v : channel) EXPECT_EQ(v, 0.0);
}

struct SliverSystem {
    TetMesh mesh;
    TetConnectivity connectivity;
    DiffusionMatrix matrix;
    std::vector<double> b;
    MultiresHierarchy hierarchy;
};

inline SliverSystem make_sliver_system() {
    SliverSystem s;
    s.mesh = waxwork::make_box_mesh(std::array<int, 3>{10, 10, 10}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(10));
    s.connectivity = build_connectivity(s.mesh);
    flatten_into_slivers(s.mesh, s.connectivity, 6, 1e-5);
    const std::vector<TetMaterial> materials(s.mesh.tet_count(), material_preset("marble"));
    s.matrix = assemble_diffusion_matrix(s.mesh, s.connectivity, materials);
    s.b.assign(s.matrix.size(), 0.0);
    for (const int32_t v : s.connectivity.boundary_vertices)
        s.b[static_cast<size_t>(v)] = 1.0 + 0.1 * s.mesh.positions[static_cast<size_t>(v)].x();
    s.hierarchy = build_multires_hierarchy(s.matrix, s.mesh.positions);
    return s;
}

// Dense copies of a compressed-row matrix and of an interpolation operator (coarse_rows columns), for
// checks against dense linear algebra on small systems.
inline Eigen::MatrixXd dense(const CsrMatrixView<double>& m) {
    const auto n = static_cast<Eigen::Index>(m.rows);
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(n, n);
    for (Eigen::Index i = 0; i < n; ++i)
        for (int32_t k = m.offsets[i]; k < m.offsets[i + 1]; ++k) d(i, m.columns[k]) += m.values[k];
    return d;
}

inline Eigen::MatrixXd dense(const InterpolationOperator& p, Eigen::Index coarse_rows) {
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(p.rows()), coarse_rows);
    for (size_t v = 0; v < p.rows(); ++v)
        for (int32_t q = p.offsets[v]; q < p.offsets[v + 1]; ++q)
            d(static_cast<Eigen::Index>(v), p.columns[static_cast<size_t>(q)]) += p.weights[static_cast<size_t>(q)];
    return d;
}

inline bool all_finite(std::span<const double> x) {
    for (double v : x)
        if (!std::isfinite(v)) return false;
    return true;
}

}  // namespace waxwork::testing
