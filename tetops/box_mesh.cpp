#include "tetops/box_mesh.h"

#include "base/error.h"

#include <cmath>

namespace waxwork {

TetMesh make_box_mesh(const std::array<int, 3>& cells, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    int64_t vertex_count = 1;
    for (int axis = 0; axis < 3; ++axis) {
        if (cells[axis] < 1) throw InvalidArgumentError("box mesh: every axis needs at least one cell");
        if (!(lo[axis] < hi[axis]) || !std::isfinite(lo[axis]) || !std::isfinite(hi[axis]))
            throw InvalidArgumentError("box mesh: the box corners must be finite with lo < hi on every axis");
        vertex_count *= cells[axis] + 1;
    }
    if (vertex_count > (int64_t{1} << 31) - 1) throw InvalidArgumentError("box mesh: too many cells");

    std::vector<Eigen::Vector3d> points;
    points.reserve(static_cast<size_t>(vertex_count));
    const Eigen::Vector3d n(cells[0], cells[1], cells[2]);
    for (int k = 0; k <= cells[2]; ++k)
        for (int j = 0; j <= cells[1]; ++j)
            for (int i = 0; i <= cells[0]; ++i)
                points.push_back(lo + (hi - lo).cwiseProduct(Eigen::Vector3d(i, j, k).cwiseQuotient(n)));

    constexpr int kPermutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    std::vector<Tet> tets;
    tets.reserve(static_cast<size_t>(cells[0]) * cells[1] * cells[2] * 6);
    for (int k = 0; k < cells[2]; ++k)
        for (int j = 0; j < cells[1]; ++j)
            for (int i = 0; i < cells[0]; ++i)
                for (const auto& permutation : kPermutations) {
                    // Walk from the cell's low corner to its high corner one axis at a time.
                    int c[3] = {i, j, k};
                    Tet tet;
                    tet[0] = box_vertex_index(cells, c[0], c[1], c[2]);
                    for (int step = 0; step < 3; ++step) {
                        c[permutation[step]] += 1;
                        tet[step + 1] = box_vertex_index(cells, c[0], c[1], c[2]);
                    }
                    tets.push_back(tet);
                }
    return make_tet_mesh(std::move(points), std::move(tets));
}

}  // namespace waxwork
