// The problems the grid methods' tests solve: volumes with cracks and slits narrower than any cell.
#pragma once

#include "solver/methods/method_problem.h"
#include "tetops/box_mesh.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <cmath>
#include <vector>

namespace waxwork::test {

// A volume with everything a MethodProblem refers to: one material everywhere (the ball's standard
// one unless given), no light until a test sets q.
struct MethodScene {
    TetMesh mesh;
    TetConnectivity connectivity;
    std::vector<TetMaterial> materials;
    std::vector<std::array<double, 3>> q;

    explicit MethodScene(TetMesh m, const TetMaterial& material = {{0.01, 0.01, 0.01}, {1, 1, 1}, 1.3})
        : mesh(std::move(m)), connectivity(build_connectivity(mesh)), materials(mesh.tet_count(), material),
          q(mesh.vertex_count(), std::array<double, 3>{}) {}
    MethodProblem problem(double mm_per_unit = 1.0, Progress* progress = nullptr) const {
        return MethodProblem{mesh, connectivity, materials, q, mm_per_unit, progress};
    }
};

// The box [0,4]^3 in 8^3 cubes with a slit of zero width, as a cut leaves it: the faces on the plane
// x = 2 with y < `depth` are split (the tets on the x > 2 side get their own copies of those
// vertices), so the two sides touch there only through coincident boundary faces, and stay connected
// for y > depth.
inline TetMesh make_slit_box(double depth) {
    TetMesh box = make_box_mesh({8, 8, 8}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(4));
    std::vector<Eigen::Vector3d> positions = box.positions;
    std::vector<int32_t> copy(positions.size(), -1);
    for (size_t v = 0; v < box.positions.size(); ++v) {
        const Eigen::Vector3d& p = box.positions[v];
        if (std::abs(p.x() - 2) < 1e-12 && p.y() < depth - 1e-12) {
            copy[v] = static_cast<int32_t>(positions.size());
            positions.push_back(p);
        }
    }
    std::vector<Tet> tets = box.tets;
    for (Tet& t : tets) {
        double x = 0;
        for (int32_t v : t) x += box.positions[v].x() / 4;
        if (x > 2)
            for (int32_t& v : t)
                if (copy[v] >= 0) v = copy[v];
    }
    return make_tet_mesh(std::move(positions), std::move(tets));
}

}  // namespace waxwork::test
