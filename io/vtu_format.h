// Waxwork's native volume format: a VTK XML UnstructuredGrid (.vtu) that ParaView opens directly and
// that stores every field of a TetMesh bit-exactly.
//
// Layout (waxwork_format_version 1):
//   FieldData  waxwork_format_version  Int32, 1 value
//              piece_transforms        Float64, 12 components per piece: the rotation row-major
//                                      (r00 r01 r02 r10 ... r22), then the translation (tx ty tz)
//              mm_per_unit             Float64, 1 value, when the scale is stored (volume_metadata.h)
//   Points     Float64 x 3             rest-frame positions
//   Cells      connectivity Int32, offsets Int64, types UInt8 (all VTK_TETRA = 10; VTK's tetra
//              ordering has the same positive orientation as TetMesh, so tets are stored as is)
//   CellData   mua, musp Float64 x 3 and eta Float64 (all three omitted when no materials are stored),
//              original_id Int32, piece Int32
//
// Encoding: format="binary", i.e. base64 of a UInt64 byte count followed by the little-endian
// values, uncompressed, one base64 stream per array as VTK itself writes. Binary rather than ascii
// because it is exact by construction (the stored bytes are the doubles) and about half the size of
// a %.17g text that would also round-trip; base64 rather than "appended raw" because the file stays
// well-formed XML that a real parser (pugixml) reads without special cases; uncompressed because
// zlib would add a dependency and CPU time to every save for a file that is rewritten often.
//
// Reading also accepts format="ascii", UInt32 headers and any integer/float DataArray types that
// convert exactly. A .vtu without waxwork_format_version (written by ParaView, meshio, ...) is
// imported like a foreign format: its tetra cells only, other cells ignored, orientation fixed,
// no materials or pieces. Compressed, appended and big-endian data are rejected with a FileError.
#pragma once

#include "io/volume_metadata.h"
#include "tetops/tet_mesh.h"

#include <filesystem>
#include <ostream>
#include <string>

namespace waxwork {

inline constexpr int kVtuFormatVersion = 1;

// Writes `mesh` as .vtu to `out` (binary mode). The mesh should satisfy validate().
void format_vtu(const TetMesh& mesh, std::ostream& out, const VolumeMetadata& metadata = {});

// Parses .vtu text; `file_name` is used in error messages. Throws FileError on malformed,
// inconsistent or invalid content. Takes the text by value because the XML is parsed in place.
// Fills `metadata` when given (nothing is stored in a .vtu from another program).
TetMesh parse_vtu(std::string contents, const std::string& file_name, VolumeMetadata* metadata = nullptr);

// File versions: the write is atomic (see atomic_file.h).
void write_vtu(const TetMesh& mesh, const std::filesystem::path& path, const VolumeMetadata& metadata = {});
TetMesh read_vtu(const std::filesystem::path& path, VolumeMetadata* metadata = nullptr);

}  // namespace waxwork
