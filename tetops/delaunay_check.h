// The local Delaunay (empty circumsphere) property of a tet mesh, decided with CGAL's exact predicate.
//
// A mesh is locally Delaunay when, for every interior face, the vertex of the neighbouring tet opposite
// the face lies outside (or on) the circumsphere of the tet on the other side. On a volume whose
// boundary is convex this is equivalent to being the Delaunay triangulation of the vertices; then the
// circumcentric dual of every interior edge is a Voronoi face of positive area (what finite volumes on
// Voronoi cells need, solver/methods/voronoi_dual.h). The in-sphere test is the classic case where
// floating point lies on nearly cospherical points (every regular grid), so the exact filtered predicate
// of CGAL decides it rather than a determinant in double.
#pragma once

#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <cstddef>

namespace waxwork {

struct DelaunayCheck {
    size_t interior_faces = 0;
    // Interior faces whose opposite vertex lies strictly inside the neighbour's circumsphere.
    size_t non_delaunay_faces = 0;
    bool locally_delaunay() const { return non_delaunay_faces == 0; }
};

// Tests every interior face (in parallel). `connectivity` must be built from `mesh`; tets are positively
// oriented (a TetMesh invariant). Throws InvalidArgumentError when the sizes disagree.
DelaunayCheck check_local_delaunay(const TetMesh& mesh, const TetConnectivity& connectivity);

}  // namespace waxwork
