// Surface meshes in: OBJ, OFF, PLY (ascii and binary) and STL (ascii and binary).
//
// read_surface_file() returns the triangle soup exactly as the file states it (polygons fan-split into
// triangles, nothing merged, nothing checked). load_closed_surface() is what the application uses: it
// reads, applies the safe repairs of tetops/surface_check.h, and refuses anything a mesher cannot fill.
#pragma once

#include "base/error.h"
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

// The refusal of a surface that stays defective after the repairs asked for: what() is the message
// load_closed_surface documents; defects() are those of the refused surface (after the safe repairs
// and any hard repairs tried), so that a caller can offer the repairs that apply instead of parsing
// the text. Only surfaces refused for their defects throw it: an unreadable file is a FileError, a
// surface with too many triangles or a wrap that stays defective a plain InvalidMeshError.
class SurfaceRefusedError : public InvalidMeshError {
public:
    SurfaceRefusedError(const std::string& message, const SurfaceDefects& defects, bool wrapping_would_fix)
        : InvalidMeshError(message), defects_(defects), wrapping_would_fix_(wrapping_would_fix) {}
    const SurfaceDefects& defects() const { return defects_; }
    // --repair wrap would give a surface the meshers take (every defect but missing or non-finite vertices).
    bool wrapping_would_fix() const { return wrapping_would_fix_; }

private:
    SurfaceDefects defects_;
    bool wrapping_would_fix_ = false;
};

// Reads the file, applies the safe repairs, then (only if asked in options) the hard repairs, and
// validates the result. With options.wrap the file's triangles are wrapped instead (before any check:
// tetops/alpha_wrap.h) and the wrap is validated the same way. Throws FileError for unreadable files
// and SurfaceRefusedError (an InvalidMeshError) for surfaces that stay defective; what() is "FILE: DEFECT; DEFECT; ...", FILE as
// the caller spelled it, e.g. "bad_cow.obj: 81 self-intersecting triangle pairs (first: faces 10 and
// 2411)", followed by "; --repair wrap rebuilds it as a closed surface" when wrapping would give a
// surface the meshers take (any defect but a missing or non-finite vertex).
// `progress`, when given, is told each stage (reading, checking, each repair).
LoadedSurface load_closed_surface(const std::filesystem::path& path,
                                  const SurfaceRepairOptions& options = {}, Progress* progress = nullptr);

}  // namespace waxwork
