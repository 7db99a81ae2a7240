// A lit block of one material (mm units): light from +z on the top face only, channel 0 assembled.
// Shared by the solver tests that need a small, realistic diffusion system.
#pragma once

#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "solver/material.h"
#include "solver/reference/reference_solvers.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <utility>
#include <vector>

namespace waxwork::test {

struct LitBlockSystem {
    TetMesh mesh;
    TetConnectivity conn;
    std::vector<TetMaterial> materials;
    DiffusionMatrix matrix;
    std::vector<double> b;

    explicit LitBlockSystem(TetMesh m, const char* material = "marble", double mm = 1.0) : mesh(std::move(m)) {
        conn = build_connectivity(mesh);
        materials.assign(mesh.tet_count(), material_preset(material));
        AssemblyOptions options;
        options.mm_per_unit = mm;
        matrix = assemble_diffusion_matrix(mesh, conn, materials, options);
        const double top = bounding_box(mesh)[1].z();
        std::vector<std::array<double, 3>> q(mesh.vertex_count(), {0, 0, 0});
        for (size_t v = 0; v < mesh.vertex_count(); ++v)
            if (mesh.positions[v].z() > top - 1e-9) q[v] = {1, 1, 1};
        b.resize(mesh.vertex_count());
        diffusion_right_hand_side(matrix, q, 0, b);
    }
    template <typename Scalar>
    std::vector<Scalar> values() const {
        return std::vector<Scalar>(matrix.values[0].begin(), matrix.values[0].end());
    }
    template <typename Scalar>
    CsrMatrixView<Scalar> view(const std::vector<Scalar>& v) const {
        return {matrix.size(), matrix.offsets.data(), matrix.columns.data(), v.data()};
    }
    // Channel 0 in double.
    CsrMatrixView<double> view() const { return view(matrix.values[0]); }
    Eigen::VectorXd exact() const {
        return DirectSolver(to_eigen_sparse(matrix, 0)).solve(Eigen::Map<const Eigen::VectorXd>(b.data(), b.size()));
    }
    // Relative error in the D-norm (the norm the CG estimate is stated in).
    template <typename Scalar>
    double d_error(const std::vector<Scalar>& x, const Eigen::VectorXd& ref) const {
        double e = 0, n = 0;
        for (size_t i = 0; i < x.size(); ++i) {
            const double d = matrix.values[0][static_cast<size_t>(matrix.diagonal[i])];
            e += d * std::pow(x[i] - ref[i], 2);
            n += d * ref[i] * ref[i];
        }
        return std::sqrt(e / n);
    }
};

}  // namespace waxwork::test
