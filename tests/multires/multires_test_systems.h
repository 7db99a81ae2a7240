// Small assembled diffusion systems for the multires tests.
#pragma once

#include "solver/diffusion_matrix.h"
#include "tetops/connectivity.h"
#include "tetops/test_meshes.h"

#include <array>
#include <vector>

namespace waxwork::testing {

struct TestSystem {
    TetMesh mesh;
    TetConnectivity connectivity;
    DiffusionMatrix matrix;
    std::array<std::vector<double>, 3> b;  // right-hand side per channel
};

// A cube of n^3 * 6 tets with a different absorption per channel, lit unevenly on its boundary.
inline TestSystem make_test_system(int n, double size = 4.0) {
    TestSystem s;
    s.mesh = make_cube_mesh(n, Eigen::Vector3d::Zero(), size);
    s.connectivity = build_connectivity(s.mesh);
    const std::vector<TetMaterial> materials(s.mesh.tet_count(), TetMaterial{{0.01, 0.05, 0.2}, {1, 1, 1}, 1.3});
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

}  // namespace waxwork::testing
