// Deliberately degenerate tets for stability tests and studies ("slivers, min dihedral 0.01
// to 1 degree"): interior vertices are pushed towards the opposite face of one tet of their star, which
// flattens that tet into a cap of relative height `flatness` while every tet stays positively oriented
// (the first tet of the star for which that holds; a vertex for which none does is left where it is).
#pragma once

#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <vector>

namespace waxwork {

// Moves up to `count` interior vertices (every 37th, skipping neighbours of moved ones) so one tet per
// moved vertex becomes a cap of relative height `flatness` in (0, 1]. Returns the flattened tets.
// Throws InvalidArgumentError for flatness outside (0, 1] or a negative count.
std::vector<int32_t> flatten_into_slivers(TetMesh& mesh, const TetConnectivity& connectivity, int count,
                                          double flatness);

}  // namespace waxwork
