// Small hand-made tet meshes for tests.
#pragma once

#include "tetops/box_mesh.h"
#include "tetops/tet_mesh.h"

#include <algorithm>
#include <numeric>
#include <random>
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

// A cube of n^3 Kuhn cells with its vertices and tets shuffled and a share of its tets dropped (which
// leaves holes, several components, edges and vertices shared by otherwise separate parts, and
// vertices without tets).
inline TetMesh shuffled_holed_cube(int n, double drop, uint32_t seed) {
    const TetMesh cube = make_cube_mesh(n);
    std::mt19937 rng(seed);
    std::vector<int32_t> order(cube.vertex_count());
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<Eigen::Vector3d> positions(cube.vertex_count());
    for (size_t v = 0; v < order.size(); ++v) positions[order[v]] = cube.positions[v];
    std::vector<Tet> tets;
    std::bernoulli_distribution dropped(drop);
    for (const Tet& tet : cube.tets) {
        if (dropped(rng)) continue;
        Tet renamed;
        for (int k = 0; k < 4; ++k) renamed[k] = order[tet[k]];
        // An even permutation of the corners keeps the orientation.
        const int turns = static_cast<int>(rng() % 3);
        for (int r = 0; r < turns; ++r) renamed = {renamed[0], renamed[2], renamed[3], renamed[1]};
        tets.push_back(renamed);
    }
    std::shuffle(tets.begin(), tets.end(), rng);
    return make_tet_mesh(std::move(positions), std::move(tets));
}

}  // namespace waxwork::testing
