// Checks shared by the volume readers: a file that parses is still rejected when the mesh it
// describes breaks a TetMesh invariant, with an error naming the file.
#pragma once

#include "tetops/tet_mesh.h"

#include <string>
#include <vector>

namespace waxwork {

// Throws FileError(file, "invalid volume: ...") listing the first few violations of the TetMesh
// invariants (find_invariant_violations).
void check_volume(const TetMesh& mesh, const std::string& file);

// Builds a TetMesh from the geometry of a foreign format (Gmsh, MEDIT, TetGen), which carries no
// materials or pieces. Every tet index must already be in range. Foreign writers differ in their
// orientation convention, so negatively oriented tets are reoriented (two vertices swapped) rather
// than rejected; a zero-volume tet is rejected. Vertices no tet uses (Gmsh geometry points, MEDIT
// vertices of surface-only elements) are dropped, keeping the order of the others, since a TetMesh
// has none. The result has make_tet_mesh's defaults and is checked with check_volume.
TetMesh mesh_from_foreign_geometry(std::vector<Eigen::Vector3d> positions, std::vector<Tet> tets,
                                   const std::string& file);

}  // namespace waxwork
