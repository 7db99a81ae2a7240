// What a volume file stores beside the mesh: the model's scale (millimetres per model unit), so a
// volume reopens at the size it was meshed, painted and saved at (tetops/model_scale.h).
//
// Where each format keeps it:
//   .vtu          FieldData array 'mm_per_unit' (Float64, one value)
//   .msh          a $Comments section holding the line "waxwork mm_per_unit X" (Gmsh skips sections
//                 it does not know, as Waxwork's reader does)
//   .mesh, .node  the comment line "# waxwork mm_per_unit X" at the top
// X is the shortest text that reads back to the same double. The text formats' line is looked for in
// the file's first 4096 bytes only, where the writers put it. A file without it has no stored scale.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace waxwork {

struct VolumeMetadata {
    std::optional<double> mm_per_unit;
    friend bool operator==(const VolumeMetadata&, const VolumeMetadata&) = default;
};

// "waxwork mm_per_unit X\n" after `comment_prefix` ("" when nothing is stored).
std::string metadata_comment_lines(const VolumeMetadata& metadata, std::string_view comment_prefix);

// The metadata in the lines of `contents` that start with `comment_prefix` + "waxwork ". Throws
// FileError naming `file` when a stored scale is not a number or outside the scale's range.
VolumeMetadata find_metadata_comments(std::string_view contents, std::string_view comment_prefix,
                                      const std::string& file);

// Throws FileError "FILE: stored mm_per_unit must be ..." when the scale is out of range.
void check_metadata(const VolumeMetadata& metadata, const std::string& file);

}  // namespace waxwork
