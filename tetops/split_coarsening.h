// Undoing splits that an operation no longer needs (the exact Voronoi fracture).
//
// fracture_voronoi builds the diagram one seed at a time (fracture.h), so a wall between two cells
// that a later cell swallows stays inside that cell as a layer of split tets: it is no crack, but it
// multiplies the tets (spot at 49,405 tets, 100 pieces: 38,258 of the vertices the split made lie
// inside one cell). This pass collapses such vertices into a neighbour.
//
// Written by hand: CGAL's and OpenMesh's edge collapses work on surface meshes, and TetGen's mesh
// improvement would re-mesh the cracks and lose the per-tet labels, ids and vertex origins the
// editor carries across the fracture. Throws InvalidArgumentError for array sizes that do not match
// the mesh, keep_angle_deg outside (0, 70) or guard_deg outside [0, 70).
#pragma once

#include "tetops/cut.h"
#include "tetops/tet_mesh.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace waxwork {

struct SplitCoarsening {
    size_t vertices_collapsed = 0;
    size_t tets_removed = 0;
};

// Collapses vertices v >= first_candidate made on an edge (vertex_origins[v] = edge ab; crack copies
// and vertices kept from before are never collapsed) into the neighbour that leaves the best worst
// angle, when:
//  - no face through v must keep its plane (kept_faces_at, split_quality.h): v is on no wall between
//    labels and not on the boundary;
//  - no vertex left after the pass names v in its origin (candidates go newest first, so the origins
//    of the vertices left stay exact);
//  - every tet the collapse reshapes stays positively oriented (the star of an interior vertex is a
//    ball, and a cone from a point of its boundary over the rest of it, every tet positive, tiles the
//    same ball), at or above min(keep_angle_deg, the worst angle around v before), and at or above
//    min(guard_deg, its reference angle): no collapse adds a tet under the split's guard.
// The tets around v that hold the target vertex go; the others keep their label, material, original
// id, piece and reference angle (NaN, untouched, becomes the tet's angle before: it is reshaped now).
// An original id can thus disappear, as a cut removes ids. Vertices and tets are then compacted in
// order: per-tet arrays (mesh, `labels`, `reference_deg`) follow their tets, `vertex_origins` is
// compacted and renumbered.
SplitCoarsening collapse_unneeded_split_vertices(TetMesh& mesh, std::vector<int64_t>& labels,
                                                 std::vector<double>& reference_deg,
                                                 std::vector<VertexOrigin>& vertex_origins, size_t first_candidate,
                                                 double keep_angle_deg, double guard_deg);

}  // namespace waxwork
