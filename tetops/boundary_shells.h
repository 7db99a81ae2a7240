// The boundary of a volume as a triangle surface to hand to other programs (`waxwork export`): the
// tet faces without a neighbour (TetConnectivity::boundary_faces), in world space, grouped into shells.
#pragma once

#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace waxwork {

enum class ShellGrouping {
    // One surface whose vertices are shared as the tets share them: one vertex per boundary vertex of
    // the volume, so pieces that touch (share volume vertices) stay welded where they touch.
    Merged,
    // One shell per face-connected part of the volume (TetConnectivity::tet_component: the pieces of a
    // fracture, the parts a cut leaves): each with its own copy of every vertex, so no two shells share
    // a vertex even where their parts touch at a vertex or an edge.
    Separate,
};

struct BoundaryShells {
    ShellGrouping grouping = ShellGrouping::Merged;
    std::vector<Eigen::Vector3d> positions;          // world space (piece transforms applied), model units
    std::vector<int32_t> volume_vertices;            // the volume vertex of each surface vertex
    std::vector<std::array<int32_t, 3>> triangles;   // counter-clockwise seen from outside
    // Shell s holds triangles [shell_offsets[s], shell_offsets[s+1]) and vertices
    // [vertex_offsets[s], vertex_offsets[s+1]); Merged gives one shell holding every vertex.
    std::vector<int32_t> shell_offsets{0};
    std::vector<int32_t> vertex_offsets{0};

    size_t shell_count() const { return shell_offsets.size() - 1; }
};

// The boundary of `mesh` grouped as asked. A boundary face is outward: its normal points away from
// the fourth vertex of its tet (kTetFaces). Surface vertices follow the volume's order within a shell;
// shells are ordered by their lowest tet (TetConnectivity's component numbering).
BoundaryShells boundary_shells(const TetMesh& mesh, const TetConnectivity& connectivity, ShellGrouping grouping);

}  // namespace waxwork
