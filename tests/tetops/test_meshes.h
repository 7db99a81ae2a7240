// Small hand-made tet meshes for tests.
#pragma once

#include "tetops/box_mesh.h"
#include "tetops/tet_mesh.h"

#include <vector>

namespace waxwork::testing {

// The box [lo, hi] split into n^3 Kuhn cells (tetops/box_mesh.h).
inline TetMesh make_box_mesh(int n, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    return waxwork::make_box_mesh({n, n, n}, lo, hi);
}

// The cube [origin, origin + size]^3 split into n^3 Kuhn cells.
inline TetMesh make_cube_mesh(int n, const Eigen::Vector3d& origin = Eigen::Vector3d::Zero(), double size = 1.0) {
    return make_box_mesh(n, origin, origin + Eigen::Vector3d::Constant(size));
}

// Unit cells of a grid (Kuhn subdivision, as make_cube_mesh) where `inside(i, j, k)` holds, with
// unused grid points dropped: lets a test build a U or any other blocky shape that conforms.
template <class Inside>
inline TetMesh make_cell_mesh(int nx, int ny, int nz, Inside inside) {
    auto index = [&](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
    std::vector<int32_t> remap((nx + 1) * (ny + 1) * (nz + 1), -1);
    std::vector<Eigen::Vector3d> points;
    auto vertex = [&](int i, int j, int k) {
        int32_t& slot = remap[index(i, j, k)];
        if (slot < 0) {
            slot = static_cast<int32_t>(points.size());
            points.emplace_back(i, j, k);
        }
        return slot;
    };
    const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    std::vector<Tet> tets;
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                if (!inside(i, j, k)) continue;
                for (const auto& p : perms) {
                    int c[3] = {i, j, k};
                    Tet tet;
                    tet[0] = vertex(c[0], c[1], c[2]);
                    for (int s = 0; s < 3; ++s) {
                        c[p[s]] += 1;
                        tet[s + 1] = vertex(c[0], c[1], c[2]);
                    }
                    tets.push_back(tet);
                }
            }
    return make_tet_mesh(std::move(points), std::move(tets));
}

}  // namespace waxwork::testing
