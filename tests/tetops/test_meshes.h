// Small hand-made tet meshes for tests.
#pragma once

#include "tetops/box_mesh.h"
#include "tetops/tet_mesh.h"

namespace waxwork::testing {

// The box [lo, hi] split into n^3 Kuhn cells (tetops/box_mesh.h).
inline TetMesh make_box_mesh(int n, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    return waxwork::make_box_mesh({n, n, n}, lo, hi);
}

// The cube [origin, origin + size]^3 split into n^3 Kuhn cells.
inline TetMesh make_cube_mesh(int n, const Eigen::Vector3d& origin = Eigen::Vector3d::Zero(), double size = 1.0) {
    return make_box_mesh(n, origin, origin + Eigen::Vector3d::Constant(size));
}

// Appends mesh b to mesh a as further tets (vertex indices shifted), keeping piece 0.
inline TetMesh concatenate(const TetMesh& a, const TetMesh& b) {
    std::vector<Eigen::Vector3d> points = a.positions;
    points.insert(points.end(), b.positions.begin(), b.positions.end());
    std::vector<Tet> tets = a.tets;
    const auto shift = static_cast<int32_t>(a.positions.size());
    for (Tet t : b.tets) {
        for (int32_t& v : t) v += shift;
        tets.push_back(t);
    }
    return make_tet_mesh(std::move(points), std::move(tets));
}

}  // namespace waxwork::testing
