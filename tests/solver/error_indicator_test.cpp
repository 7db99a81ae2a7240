// The gradient-jump error indicator (solver/error_indicator.h): zero where the discrete flux is
// continuous, nonzero exactly at the tets of faces where it jumps (a kink of phi, a change of material),
// and clear errors for bad input.
#include "solver/error_indicator.h"

#include "base/error.h"
#include "solver/material.h"
#include "tetops/connectivity.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace waxwork {
namespace {

using Phi = std::vector<std::array<double, 3>>;

template <class F>
Phi sample(const TetMesh& mesh, F f) {
    Phi phi(mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        const double value = f(mesh.positions[v]);
        phi[v] = {value, 2 * value, 0.5 * value};
    }
    return phi;
}

// The tet has a face with all three vertices on the plane x = 0.5 that is shared with another tet.
bool has_interior_face_on_mid_plane(const TetMesh& mesh, const TetConnectivity& c, size_t t) {
    for (int f = 0; f < 4; ++f) {
        if (c.tet_neighbors[t][f] < 0) continue;
        bool on_plane = true;
        for (const int k : kTetFaces[f]) on_plane = on_plane && mesh.positions[mesh.tets[t][k]].x() == 0.5;
        if (on_plane) return true;
    }
    return false;
}

TEST(ErrorIndicator, VanishesForALinearFluenceInOneMaterial) {
    const TetMesh mesh = testing::make_cube_mesh(4);
    const TetConnectivity c = build_connectivity(mesh);
    const std::vector<TetMaterial> materials(mesh.tet_count(), material_preset("marble"));
    const std::vector<double> linear = gradient_jump_indicator(
        mesh, c, sample(mesh, [](const Eigen::Vector3d& p) { return 1 + 0.3 * p.x() - 0.2 * p.y() + 0.1 * p.z(); }),
        materials);
    const std::vector<double> kinked = gradient_jump_indicator(
        mesh, c, sample(mesh, [](const Eigen::Vector3d& p) { return 1 + std::abs(p.x() - 0.5); }), materials);
    const double largest = *std::max_element(kinked.begin(), kinked.end());
    ASSERT_GT(largest, 0);
    for (const double eta : linear) EXPECT_LT(eta, 1e-10 * largest);
}

TEST(ErrorIndicator, MarksExactlyTheTetsAtAKinkOrAMaterialChange) {
    const TetMesh mesh = testing::make_cube_mesh(4);
    const TetConnectivity c = build_connectivity(mesh);
    // A kink of phi across the plane x = 0.5 in one material.
    const std::vector<TetMaterial> marble(mesh.tet_count(), material_preset("marble"));
    const std::vector<double> kink = gradient_jump_indicator(
        mesh, c, sample(mesh, [](const Eigen::Vector3d& p) { return 1 + std::abs(p.x() - 0.5); }), marble, 10.0);
    // A linear phi across a change of material at the same plane: the flux kappa grad(phi) jumps.
    std::vector<TetMaterial> two = marble;
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        double x = 0;
        for (const int32_t v : mesh.tets[t]) x += mesh.positions[v].x() / 4;
        if (x > 0.5) two[t] = material_preset("skin1");
    }
    ASSERT_NE(diffusion_coefficient(marble[0].mua[0], marble[0].musp[0]),
              diffusion_coefficient(material_preset("skin1").mua[0], material_preset("skin1").musp[0]));
    const std::vector<double> change = gradient_jump_indicator(
        mesh, c, sample(mesh, [](const Eigen::Vector3d& p) { return 1 + p.x(); }), two, 10.0);
    size_t at_plane = 0;
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const bool expected = has_interior_face_on_mid_plane(mesh, c, t);
        at_plane += expected;
        EXPECT_EQ(kink[t] > 1e-12, expected) << t;
        EXPECT_EQ(change[t] > 1e-12, expected) << t;
    }
    EXPECT_GT(at_plane, 0u);
}

TEST(ErrorIndicator, RefusesBadInputNamingIt) {
    const TetMesh mesh = testing::make_cube_mesh(2);
    const TetConnectivity c = build_connectivity(mesh);
    const std::vector<TetMaterial> materials(mesh.tet_count(), material_preset("marble"));
    Phi phi = sample(mesh, [](const Eigen::Vector3d& p) { return p.x(); });
    const auto message = [&](const Phi& f, const std::vector<TetMaterial>& m, double mm) {
        try {
            gradient_jump_indicator(mesh, c, f, m, mm);
        } catch (const InvalidArgumentError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    Phi nan = phi;
    nan[5][1] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_NE(message(nan, materials, 1).find("not finite at vertex 5"), std::string::npos);
    EXPECT_NE(message(Phi(3), materials, 1).find("phi values"), std::string::npos);
    EXPECT_NE(message(phi, std::vector<TetMaterial>(2), 1).find("materials"), std::string::npos);
    EXPECT_NE(message(phi, materials, 0).find("mm per unit"), std::string::npos);
}

}  // namespace
}  // namespace waxwork
