// Surface meshes in: OBJ, OFF, PLY (ascii and binary) and STL (ascii and binary).
//
// read_surface_file() returns the triangle soup exactly as the file states it (polygons fan-split into
// triangles, nothing merged, nothing checked). load_closed_surface() is what the application uses: it
// reads, applies the safe repairs of tetops/surface_check.h, and refuses anything a mesher cannot fill.
#pragma once

#include "tetops/surface_check.h"
#include "tetops/triangle_surface.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace waxwork {

class Progress;

// The file's vertices and faces in file order (indices count from 0), with polygons split into fans
// of triangles. Faces that repeat a vertex are kept (validation reports or drops them); vertices that
// no face uses are kept. Throws FileError("PATH: PROBLEM") for an unknown extension, a missing, empty,
// unreadable, truncated or malformed file, or a file without any face.
TriangleSurface read_surface_file(const std::filesystem::path& path);

struct LoadedSurface {
    TriangleSurface surface;          // closed, manifold, outward oriented, free of self-intersections
    std::vector<std::string> repairs; // what was changed to get there, one line each; empty if nothing
    std::optional<WrapReport> wrap;   // when the options asked for the alpha wrap: what it did
};

// Reads the file, applies the safe repairs, then (only if asked in options) the hard repairs, and
// validates the result. With options.wrap the file's triangles are wrapped instead (before any check:
// tetops/alpha_wrap.h) and the wrap is validated the same way. Throws FileError for unreadable files
// and InvalidMeshError for surfaces that stay defective; what() is "FILE: DEFECT; DEFECT; ...", FILE as
// the caller spelled it, e.g. "bad_cow.obj: 81 self-intersecting triangle pairs (first: faces 10 and
// 2411)", followed by "; --repair wrap rebuilds it as a closed surface" when wrapping would give a
// surface the meshers take (any defect but a missing or non-finite vertex).
// `progress`, when given, is told each stage (reading, checking, each repair).
LoadedSurface load_closed_surface(const std::filesystem::path& path,
                                  const SurfaceRepairOptions& options = {}, Progress* progress = nullptr);

}  // namespace waxwork
