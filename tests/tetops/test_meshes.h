// Small hand-made tet meshes for tests.
#pragma once

#include "tetops/tet_mesh.h"

namespace waxwork::testing {

// The box [lo, hi] split into n^3 cells of 6 tets each (Kuhn subdivision, conforming: the six tets of
// a cell share its main diagonal, one per permutation of the axes, so neighbouring cells match without
// any flipping; dihedral angles 45-90 degrees on a cube).
inline TetMesh make_box_mesh(int n, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    std::vector<Eigen::Vector3d> points;
    auto index = [n](int i, int j, int k) { return static_cast<int32_t>((k * (n + 1) + j) * (n + 1) + i); };
    for (int k = 0; k <= n; ++k)
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i)
                points.push_back(lo + (hi - lo).cwiseProduct(Eigen::Vector3d(i, j, k) / n));
    const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    std::vector<Tet> tets;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                for (const auto& p : perms) {
                    int c[3] = {i, j, k};
                    Tet tet;
                    tet[0] = index(c[0], c[1], c[2]);
                    for (int s = 0; s < 3; ++s) {
                        c[p[s]] += 1;
                        tet[s + 1] = index(c[0], c[1], c[2]);
                    }
                    tets.push_back(tet);
                }
    return make_tet_mesh(std::move(points), std::move(tets));
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
