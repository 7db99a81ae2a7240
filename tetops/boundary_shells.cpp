#include "tetops/boundary_shells.h"

#include "tetops/cut.h"

#include <algorithm>

namespace waxwork {

BoundaryShells boundary_shells(const TetMesh& mesh, const TetConnectivity& connectivity, ShellGrouping grouping) {
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    const size_t shells = grouping == ShellGrouping::Merged ? 1 : static_cast<size_t>(connectivity.component_count);
    auto shell_of = [&](const BoundaryFace& face) {
        return grouping == ShellGrouping::Merged ? 0 : static_cast<size_t>(connectivity.tet_component[face.tet]);
    };

    // Faces by shell, keeping boundary_faces' order within a shell.
    std::vector<std::vector<int32_t>> faces(shells);
    for (size_t f = 0; f < connectivity.boundary_faces.size(); ++f)
        faces[shell_of(connectivity.boundary_faces[f])].push_back(static_cast<int32_t>(f));

    BoundaryShells result;
    result.grouping = grouping;
    result.triangles.reserve(connectivity.boundary_faces.size());
    // Per volume vertex: its surface vertex in the shell being built (-1: none yet). With Merged the
    // one shell numbers the boundary vertices in the volume's order.
    std::vector<int32_t> surface_vertex(mesh.vertex_count(), -1);
    std::vector<uint8_t> used(mesh.vertex_count(), 0);
    for (size_t s = 0; s < shells; ++s) {
        for (int32_t f : faces[s])
            for (int32_t v : connectivity.boundary_faces[f].vertices) used[v] = 1;
        // Volume order within the shell: one pass over the shell's vertices, sorted.
        std::vector<int32_t> vertices;
        for (int32_t f : faces[s])
            for (int32_t v : connectivity.boundary_faces[f].vertices)
                if (used[v] == 1) {
                    used[v] = 2;
                    vertices.push_back(v);
                }
        std::sort(vertices.begin(), vertices.end());
        for (int32_t v : vertices) {
            surface_vertex[v] = static_cast<int32_t>(result.positions.size());
            result.positions.push_back(world[v]);
            result.volume_vertices.push_back(v);
            used[v] = 0;
        }
        for (int32_t f : faces[s]) {
            const auto& face = connectivity.boundary_faces[f].vertices;
            result.triangles.push_back({surface_vertex[face[0]], surface_vertex[face[1]], surface_vertex[face[2]]});
        }
        result.shell_offsets.push_back(static_cast<int32_t>(result.triangles.size()));
        result.vertex_offsets.push_back(static_cast<int32_t>(result.positions.size()));
    }
    return result;
}

}  // namespace waxwork
