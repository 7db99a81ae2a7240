// Saving a volume's boundary surface for other programs (Blender, MeshLab, slicers), the format chosen
// by the file extension (case-insensitive):
//   .ply  binary little-endian PLY: double x, y, z (exact), and with colours uchar red, green, blue
//   .obj  Wavefront OBJ: shortest round-trip decimals (exact); colours as `v x y z r g b` with r, g, b
//         in [0, 1] (the extension MeshLab, Blender and OpenMesh read); one `o piece_N` per shell when
//         the shells are separate
//   .stl  binary STL: float32 coordinates (the format's own precision) and facet normals; no colours
//         (STL has no standard for them)
// Written directly rather than through OpenMesh: OpenMesh 9's writers store coordinates as float, its
// OBJ writer refuses vertex colours and writes no groups, and its halfedge mesh refuses the
// non-manifold vertices where two parts of a cut volume touch.
#pragma once

#include "tetops/boundary_shells.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>

namespace waxwork {

enum class SurfaceFormat { Ply, Obj, Stl };

// The format `path` names. Throws InvalidArgumentError ("PATH: unknown surface format '.x' (write
// .ply, .obj or .stl)") for any other extension.
SurfaceFormat surface_format(const std::filesystem::path& path);

// Whether the format stores per-vertex colours.
bool stores_vertex_colours(SurfaceFormat format);

// Saves atomically (atomic_file.h). `colours` is empty or holds one sRGB colour per surface vertex.
// Throws InvalidArgumentError naming the file for colours the format cannot store or a count that
// does not match, FileError on I/O failure.
void write_surface(const std::filesystem::path& path, const BoundaryShells& shells,
                   std::span<const std::array<uint8_t, 3>> colours = {});

}  // namespace waxwork
