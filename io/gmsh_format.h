// Gmsh MSH 4.1 ASCII volume meshes (.msh).
//
// Reading: $MeshFormat must say "4.1 0 8" (ASCII); $Nodes and $Elements are read block by block;
// node tags may be sparse and in any order; only 4-node tetrahedra (element type 4) are imported,
// other elements (points, lines, triangles, higher-order cells) are skipped; $Entities,
// $PhysicalNames and every other section are skipped. Gmsh's reference tetrahedron (0,0,0),
// (1,0,0), (0,1,0), (0,0,1) is positively oriented in the TetMesh sense, but files from other tools
// are not always consistent, so each negatively oriented tet is reoriented (volume_checks.h).
// Nodes used by no tetrahedron are dropped. The result has no materials and one piece.
//
// Writing: a minimal valid file with one volume entity (tag 1, no physical groups) holding every
// node (tags 1..N, TetMesh order) and every tet (tags 1..M, TetMesh order); rest-frame positions,
// exact shortest-round-trip decimals. Materials, original ids and pieces are not stored; the scale
// is (volume_metadata.h).
#pragma once

#include "io/volume_metadata.h"
#include "tetops/tet_mesh.h"

#include <filesystem>
#include <ostream>
#include <string>
#include <string_view>

namespace waxwork {

// `metadata` is written as volume_metadata.h says; parsing fills `metadata` when given.
void format_gmsh(const TetMesh& mesh, std::ostream& out, const VolumeMetadata& metadata = {});
TetMesh parse_gmsh(std::string_view contents, const std::string& file_name, VolumeMetadata* metadata = nullptr);

void write_gmsh(const TetMesh& mesh, const std::filesystem::path& path, const VolumeMetadata& metadata = {});
TetMesh read_gmsh(const std::filesystem::path& path, VolumeMetadata* metadata = nullptr);

}  // namespace waxwork
