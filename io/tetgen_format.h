// TetGen node/element files: PATH.node (vertices) beside PATH.ele (tetrahedra).
//
// Either file may be given as the path; the other is found by swapping the extension.
//
// Reading: .node header "<#points> 3 <#attributes> <0|1 boundary markers>", then
// "<index> x y z [attributes...] [marker]"; .ele header "<#tets> <4|10 nodes per tet> <0|1 region
// attribute>", then "<index> n0 n1 n2 n3 [6 more for 10-node tets] [region]". '#' starts a comment.
// Numbering starts at 0 or 1, detected from the first point (as TetGen does) and must then be
// consecutive; the .ele node numbers use the same base. For 10-node tets the four corners are used.
// Attributes, markers and regions are ignored. TetGen's own tets are positively oriented in the
// TetMesh sense (checked with libtet 1.5: every tet of a tetrahedralized cube has
// (p1-p0).((p2-p0)x(p3-p0)) > 0), but hand-made or converted files may not be, so each negatively
// oriented tet is reoriented; points used by no tet are dropped; the result has no materials and
// one piece.
//
// Writing: 0-based numbering, no point attributes, boundary markers all 0 (unmarked; the column makes
// truncation detectable), and the region attribute set to the piece id. Both files are replaced
// atomically (write_files_atomically). Rest-frame positions, exact shortest-round-trip decimals; the
// scale in a comment of the .node file (volume_metadata.h).
#pragma once

#include "io/volume_metadata.h"
#include "tetops/tet_mesh.h"

#include <filesystem>
#include <ostream>
#include <string>
#include <string_view>

namespace waxwork {

// `metadata` is written to the .node file as volume_metadata.h says; parsing fills `metadata` when given.
void format_tetgen_node(const TetMesh& mesh, std::ostream& out, const VolumeMetadata& metadata = {});
void format_tetgen_ele(const TetMesh& mesh, std::ostream& out);
TetMesh parse_tetgen(std::string_view node_contents, const std::string& node_file_name,
                     std::string_view ele_contents, const std::string& ele_file_name,
                     VolumeMetadata* metadata = nullptr);

// `path` may end in .node or .ele (or anything else: .node and .ele are substituted).
void write_tetgen(const TetMesh& mesh, const std::filesystem::path& path, const VolumeMetadata& metadata = {});
TetMesh read_tetgen(const std::filesystem::path& path, VolumeMetadata* metadata = nullptr);

}  // namespace waxwork
