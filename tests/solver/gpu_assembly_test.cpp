// The device assembly of the diffusion matrix (solver/gpu/gpu_assembly.h) against the CPU assembly, on
// Mesa's llvmpipe through OSMesa in CI: every stored value of both discretisations, painted materials,
// the row update after painting, moved vertices, bad input, and a GPU solve on device-assembled values.
#include "solver/gpu/gpu_assembly.h"

#include "base/error.h"
#include "solver/diffusion_matrix.h"
#include "solver/diffusion_solve.h"
#include "solver/gpu/gpu_conjugate_gradient.h"
#include "solver/gpu/gpu_matrix.h"
#include "solver/gpu_test_context.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "solver/solver_test_meshes.h"
#include "tetops/connectivity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace waxwork {
namespace {

struct Scene {
    TetMesh mesh;
    TetConnectivity conn;
    std::vector<TetMaterial> materials;
};

// A cube of 8^3 x 6 tets with its vertices jittered (no two tets alike), half marble, half skin.
Scene jittered_cube() {
    Scene s;
    s.mesh = test::make_cube_mesh(8, 0.25);  // side 2
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> jitter(-0.04, 0.04);
    const double h = 2.0 / 8;
    for (auto& p : s.mesh.positions)
        for (int k = 0; k < 3; ++k)
            if (p[k] > 1e-9 && p[k] < 2.0 - 1e-9) p[k] += jitter(rng) * h;
    s.conn = build_connectivity(s.mesh);
    for (size_t t = 0; t < s.mesh.tet_count(); ++t)
        s.materials.push_back(material_preset(s.mesh.positions[s.mesh.tets[t][0]].x() < 1.0 ? "marble" : "skin1"));
    return s;
}

// Largest |device - host| over the stored values, relative to the largest diagonal of the row.
double worst_relative_difference(const GpuMatrix& device, const DiffusionMatrix& host) {
    const std::vector<float> got = device.values.download<float>();
    const std::vector<float> want = gpu_matrix_values(device.layout, rgb_csr_view(host));
    double worst = 0;
    for (size_t i = 0; i < host.size(); ++i) {
        for (int c = 0; c < 3; ++c) {
            const double scale = std::abs(host.values[c][host.diagonal[i]]);
            for (int32_t k = host.offsets[i]; k < host.offsets[i + 1]; ++k) {
                const size_t s = 3 * static_cast<size_t>(device.layout.stored_index[k]) + c;
                worst = std::max(worst, std::abs(double(got[s]) - double(want[s])) / scale);
            }
        }
    }
    return worst;
}

void expect_device_assembly_matches(const Scene& s, const AssemblyOptions& options, GpuMatrixFormat format) {
    WAXWORK_REQUIRE_GL(context);
    const DiffusionMatrix host = assemble_diffusion_matrix(s.mesh, s.conn, s.materials, options);
    // The device starts from zeros: only the assembly can make the values match.
    DiffusionMatrix zeros = host;
    for (auto& v : zeros.values) std::fill(v.begin(), v.end(), 0.0);
    GpuMatrix device(context->gl(), rgb_csr_view(zeros), format);
    GpuMatrixAssembly assembly(context->gl(), s.mesh, s.conn, assemble_diffusion_pattern(s.mesh, s.conn, options),
                               device.layout);
    assembly.assemble(s.materials, device);
    // Float storage of values accumulated in double from float coefficients: a few float roundings.
    EXPECT_LT(worst_relative_difference(device, host), 1e-6);
}

TEST(GpuMatrixAssembly, TransCutValuesEqualTheHostAssemblyInEveryFormat) {
    const Scene s = jittered_cube();
    AssemblyOptions options;
    options.mm_per_unit = 30.0;
    for (GpuMatrixFormat f : {GpuMatrixFormat::Csr, GpuMatrixFormat::Ell, GpuMatrixFormat::SellCSigma})
        expect_device_assembly_matches(s, options, f);
}

TEST(GpuMatrixAssembly, FemValuesEqualTheHostAssembly) {
    const Scene s = jittered_cube();
    AssemblyOptions options;
    options.discretization = Discretization::Fem;
    options.mm_per_unit = 7.0;
    expect_device_assembly_matches(s, options, GpuMatrixFormat::SellCSigma);
}

TEST(GpuMatrixAssembly, UpdateAfterPaintingRewritesExactlyTheHostRows) {
    WAXWORK_REQUIRE_GL(context);
    Scene s = jittered_cube();
    AssemblyOptions options;
    options.mm_per_unit = 30.0;
    DiffusionMatrix host = assemble_diffusion_matrix(s.mesh, s.conn, s.materials, options);
    GpuMatrix device(context->gl(), rgb_csr_view(host), GpuMatrixFormat::SellCSigma);
    GpuMatrixAssembly assembly(context->gl(), s.mesh, s.conn, host, device.layout);
    assembly.assemble(s.materials, device);
    // Paint skin2 into the tets near a point (ids not contiguous: several upload runs).
    std::vector<int32_t> painted;
    for (size_t t = 0; t < s.mesh.tet_count(); ++t)
        if ((s.mesh.positions[s.mesh.tets[t][0]] - Eigen::Vector3d(0.6, 1.0, 1.4)).norm() < 0.45)
            painted.push_back(static_cast<int32_t>(t));
    ASSERT_GT(painted.size(), 20u);
    for (int32_t t : painted) s.materials[t] = material_preset("skin2");
    const std::vector<int32_t> host_rows = update_diffusion_matrix(host, s.mesh, s.conn, s.materials, painted);
    const std::vector<int32_t> device_rows = assembly.update(s.mesh, s.materials, painted, device);
    EXPECT_EQ(device_rows, host_rows);
    EXPECT_LT(worst_relative_difference(device, host), 1e-6);
}

// The host assembly of a scene and a device matrix + assembly for it (values from the host).
struct DeviceScene {
    DiffusionMatrix host;
    GpuMatrix device;
    GpuMatrixAssembly assembly;

    DeviceScene(const GlApi& gl, const Scene& s)
        : host(assemble_diffusion_matrix(s.mesh, s.conn, s.materials)),
          device(gl, rgb_csr_view(host), GpuMatrixFormat::SellCSigma),
          assembly(gl, s.mesh, s.conn, host, device.layout) {}
};

TEST(GpuMatrixAssembly, MovedVerticesAreAssembledFromTheNewPositions) {
    WAXWORK_REQUIRE_GL(context);
    Scene s = jittered_cube();
    DeviceScene d(context->gl(), s);
    const DiffusionMatrix& before = d.host;
    GpuMatrix& device = d.device;
    GpuMatrixAssembly& assembly = d.assembly;
    for (auto& p : s.mesh.positions) p = Eigen::Vector3d(1.3 * p.x(), p.y() + 0.1 * p.x() * p.x(), 0.8 * p.z());
    assembly.set_positions(s.mesh);
    assembly.assemble(s.materials, device);
    const DiffusionMatrix after = assemble_diffusion_matrix(s.mesh, s.conn, s.materials);
    EXPECT_LT(worst_relative_difference(device, after), 1e-6);
    EXPECT_GT(worst_relative_difference(device, before), 1e-2);  // the change is visible
}

TEST(GpuMatrixAssembly, UnreferencedVerticesGetIdentityRows) {
    WAXWORK_REQUIRE_GL(context);
    Scene s = jittered_cube();
    s.mesh.positions.push_back(Eigen::Vector3d(5, 5, 5));  // no tet uses it
    s.conn = build_connectivity(s.mesh);
    expect_device_assembly_matches(s, {}, GpuMatrixFormat::Csr);
}

TEST(GpuMatrixAssembly, AnInvertedTetIsNamed) {
    WAXWORK_REQUIRE_GL(context);
    Scene s = jittered_cube();
    DeviceScene d(context->gl(), s);
    GpuMatrix& device = d.device;
    GpuMatrixAssembly& assembly = d.assembly;
    // Collapse tet 17 by moving its first vertex onto the plane of its other three... and beyond.
    TetMesh moved = s.mesh;
    const Tet& t = moved.tets[17];
    const Eigen::Vector3d centre = (moved.positions[t[1]] + moved.positions[t[2]] + moved.positions[t[3]]) / 3.0;
    moved.positions[t[0]] = centre + 1.5 * (centre - moved.positions[t[0]]);
    assembly.set_positions(moved);
    try {
        assembly.assemble(s.materials, device);
        FAIL() << "expected InvalidMeshError";
    } catch (const InvalidMeshError& e) {
        EXPECT_NE(std::string(e.what()).find("non-positive volume"), std::string::npos) << e.what();
    }
}

TEST(GpuMatrixAssembly, RejectsBadInput) {
    WAXWORK_REQUIRE_GL(context);
    Scene s = jittered_cube();
    DeviceScene d(context->gl(), s);
    GpuMatrix& device = d.device;
    GpuMatrixAssembly& assembly = d.assembly;
    AssemblyOptions cotangent;
    cotangent.stiffness_form = StiffnessForm::Cotangent;
    EXPECT_THROW(GpuMatrixAssembly(context->gl(), s.mesh, s.conn, assemble_diffusion_pattern(s.mesh, s.conn, cotangent),
                                   device.layout),
                 InvalidArgumentError);
    std::vector<TetMaterial> bad = s.materials;
    bad[5].mua[1] = std::nan("");
    try {
        assembly.assemble(bad, device);
        FAIL() << "expected InvalidArgumentError";
    } catch (const InvalidArgumentError& e) {
        EXPECT_NE(std::string(e.what()).find("tet 5"), std::string::npos) << e.what();
    }
    EXPECT_THROW(assembly.assemble(std::vector<TetMaterial>(3, s.materials[0]), device), InvalidArgumentError);
    const std::vector<int32_t> out_of_range = {static_cast<int32_t>(s.mesh.tet_count())};
    EXPECT_THROW(assembly.update(s.mesh, s.materials, out_of_range, device), InvalidArgumentError);
}

TEST(GpuMatrixAssembly, GpuSolveOnDeviceAssembledValuesMatchesTheCpuSolve) {
    WAXWORK_REQUIRE_GL(context);
    const Scene s = jittered_cube();
    AssemblyOptions options;
    options.mm_per_unit = 30.0;
    const DiffusionMatrix host = assemble_diffusion_matrix(s.mesh, s.conn, s.materials, options);
    Lighting lighting;
    lighting.lights.push_back(Light{});
    const std::vector<Rgb> q3 = incident_light(s.mesh, s.conn, s.materials, lighting);

    // The solver is created on a matrix of other materials; the device assembly replaces its values.
    const std::vector<TetMaterial> wrong(s.mesh.tet_count(), material_preset("ketchup"));
    GpuDiffusionSolver solver(context->gl(), assemble_diffusion_matrix(s.mesh, s.conn, wrong, options));
    GpuMatrixAssembly assembly(context->gl(), s.mesh, s.conn, host, solver.matrix().layout);
    assembly.assemble(s.materials, solver.matrix());
    solver.values_changed_on_device();
    solver.set_light(host, q3);
    GpuCgOptions gpu_options;
    gpu_options.relative_tolerance = 1e-6;
    for (const auto& r : solver.solve(gpu_options)) EXPECT_TRUE(r.converged);
    const std::vector<std::array<double, 3>> gpu = solver.solution();

    DiffusionOptions cpu_options;
    cpu_options.relative_tolerance = 1e-9;
    DiffusionSolution cpu;
    solve_diffusion_system(host, q3, cpu_options, cpu);
    for (int c = 0; c < 3; ++c) {
        double diff = 0, peak = 0;
        for (size_t i = 0; i < cpu.phi.size(); ++i) {
            diff = std::max(diff, std::abs(gpu[i][c] - cpu.phi[i][c]));
            peak = std::max(peak, std::abs(cpu.phi[i][c]));
        }
        EXPECT_LT(diff / peak, 1e-4) << "channel " << c;
    }
}

}  // namespace
}  // namespace waxwork
