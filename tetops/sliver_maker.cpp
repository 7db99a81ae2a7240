#include "tetops/sliver_maker.h"

#include "base/error.h"

namespace waxwork {

std::vector<int32_t> flatten_into_slivers(TetMesh& mesh, const TetConnectivity& connectivity, int count,
                                          double flatness) {
    if (!(flatness > 0 && flatness <= 1)) throw InvalidArgumentError("slivers: flatness must be in (0, 1]");
    if (count < 0) throw InvalidArgumentError("slivers: count must be >= 0");
    std::vector<int32_t> slivers;
    std::vector<uint8_t> touched(mesh.vertex_count(), 0);
    // Every 37th vertex spreads the slivers through the volume instead of clustering them.
    for (size_t v = 0; v < mesh.vertex_count() && static_cast<int>(slivers.size()) < count; v += 37) {
        if (connectivity.is_boundary_vertex[v] || touched[v] || connectivity.vertex_tets.row(v).empty()) continue;
        // The first tet of the star towards whose opposite face the vertex can move without turning any
        // tet of its star over (on a box mesh, always the first; on a Delaunay ball the star need not be
        // star-shaped from every face centroid).
        const Eigen::Vector3d old = mesh.positions[v];
        int32_t flattened = -1;
        for (int32_t t : connectivity.vertex_tets.row(v)) {
            Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
            for (int32_t w : mesh.tets[t])
                if (w != static_cast<int32_t>(v)) centroid += mesh.positions[w] / 3.0;
            mesh.positions[v] = centroid + flatness * (old - centroid);
            bool positive = true;
            for (int32_t s : connectivity.vertex_tets.row(v)) positive = positive && signed_volume(mesh, s) > 0;
            if (positive) {
                flattened = t;
                break;
            }
            mesh.positions[v] = old;
        }
        if (flattened < 0) continue;
        for (int32_t w : connectivity.vertex_vertices.row(v)) touched[w] = 1;
        touched[v] = 1;
        slivers.push_back(flattened);
    }
    return slivers;
}

}  // namespace waxwork
