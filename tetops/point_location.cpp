#include "tetops/point_location.h"

#include "tetops/cut.h"

#include <cmath>
#include <vector>

namespace waxwork {

bool point_inside_volume(const TetMesh& mesh, const Eigen::Vector3d& point) {
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    for (const Tet& tet : mesh.tets) {
        const Eigen::Vector3d &a = world[tet[0]], &b = world[tet[1]], &c = world[tet[2]], &d = world[tet[3]];
        // The tet's box first: far from the tet the sub-volumes below are differences of huge
        // products, whose rounding exceeds any tolerance relative to the tet (a light at 1e8 passed
        // the signs of a unit cube's tets).
        const Eigen::Vector3d lo = a.cwiseMin(b).cwiseMin(c).cwiseMin(d), hi = a.cwiseMax(b).cwiseMax(c).cwiseMax(d);
        const double margin = 1e-9 * (hi - lo).maxCoeff();
        if ((point.array() < lo.array() - margin).any() || (point.array() > hi.array() + margin).any()) continue;
        const double volume = signed_volume(a, b, c, d);
        // Barycentric signs with a relative tolerance, so a point on a shared face counts.
        const double tolerance = -1e-12 * std::abs(volume);
        if (signed_volume(point, b, c, d) >= tolerance && signed_volume(a, point, c, d) >= tolerance &&
            signed_volume(a, b, point, d) >= tolerance && signed_volume(a, b, c, point) >= tolerance)
            return true;
    }
    return false;
}

}  // namespace waxwork
