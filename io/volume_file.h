// Reading and saving tetrahedral volumes, the format chosen by the file extension
// (case-insensitive):
//   .vtu          VTK XML UnstructuredGrid, Waxwork's native format: everything stored bit-exactly
//                 (materials, original ids, pieces and their transforms); see vtu_format.h
//   .msh          Gmsh 4.1 ASCII (gmsh_format.h)
//   .mesh         MEDIT ASCII (medit_format.h)
//   .node / .ele  TetGen, PATH.node and PATH.ele side by side (tetgen_format.h)
// Foreign formats keep geometry and topology exactly but not materials, original ids or pieces;
// importing one gives make_tet_mesh's defaults. Every format stores the scale (volume_metadata.h).
#pragma once

#include "io/volume_metadata.h"
#include "tetops/tet_mesh.h"

#include <filesystem>

namespace waxwork {

// Whether the extension names one of the formats above (case-insensitive), so that read_volume and
// write_volume accept the path: what a surface or any other file is not.
bool is_volume_path(const std::filesystem::path& path);

// Throws FileError ("PATH: problem") when the file is missing, malformed, truncated, inconsistent
// or describes an invalid mesh, or when the extension is not one of the above.
TetMesh read_volume(const std::filesystem::path& path);

// A volume with what its file stores beside the mesh.
struct VolumeFile {
    TetMesh mesh;
    VolumeMetadata metadata;
};
// read_volume with the metadata; the same errors, and FileError for a stored scale out of range.
VolumeFile read_volume_file(const std::filesystem::path& path);

// Saves atomically (atomic_file.h): on failure the previous file is intact. Throws FileError on
// I/O failure or an unknown extension, and InvalidMeshError (naming the file) when `mesh` breaks a
// TetMesh invariant, since such a file could not be read back.
void write_volume(const TetMesh& mesh, const std::filesystem::path& path, const VolumeMetadata& metadata = {});

}  // namespace waxwork
