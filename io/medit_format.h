// MEDIT ASCII meshes (.mesh), as used by Medit, Mmg, TetGen (-g) and CGAL.
//
// Reading: MeshVersionFormatted 1 to 4 (the versions differ only in binary .meshb word sizes),
// Dimension 3, Vertices (x y z ref), Tetrahedra (four 1-based vertex numbers and a ref), End.
// Keywords are case-insensitive, '#' starts a comment, and every other section (Triangles, Edges,
// Corners, Normals, ...) is skipped by skipping its numbers. The End keyword is required, so a
// truncated file is detected. MEDIT tets are positively oriented in the TetMesh sense (Mmg's
// oriented volume is det(p1-p0, p2-p0, p3-p0) > 0, the same triple product), but not every writer
// complies, so each negatively oriented tet is reoriented; vertices used by no tet are dropped.
// Refs are ignored on import: the result has no materials and one piece.
//
// Writing: MeshVersionFormatted 2 (double precision), vertex ref 0, and each tet's ref set to its
// piece id so a fractured volume keeps its pieces distinguishable in other tools. Rest-frame
// positions, exact shortest-round-trip decimals; the scale in a comment (volume_metadata.h).
#pragma once

#include "io/volume_metadata.h"
#include "tetops/tet_mesh.h"

#include <filesystem>
#include <ostream>
#include <string>
#include <string_view>

namespace waxwork {

// `metadata` is written as volume_metadata.h says; parsing fills `metadata` when given.
void format_medit(const TetMesh& mesh, std::ostream& out, const VolumeMetadata& metadata = {});
TetMesh parse_medit(std::string_view contents, const std::string& file_name, VolumeMetadata* metadata = nullptr);

void write_medit(const TetMesh& mesh, const std::filesystem::path& path, const VolumeMetadata& metadata = {});
TetMesh read_medit(const std::filesystem::path& path, VolumeMetadata* metadata = nullptr);

}  // namespace waxwork
