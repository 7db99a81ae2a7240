// Validation and repair of a triangle surface before it is filled with tetrahedra.
//
// A mesher needs a closed, manifold, consistently and outward oriented surface without
// self-intersections that encloses a positive volume. find_surface_defects() measures every way a
// TriangleSurface falls short; repair_safe_defects() fixes only what has a single obvious answer
// (duplicate or unused vertices, triangles that repeat a vertex, zero-area slivers whose removal
// leaves no hole, orientation); repair_hard_defects() changes the shape (fills holes, removes
// self-intersections) and runs only when the user opts in. Rebuilding a surface by alpha wrapping,
// which replaces all of these, is tetops/alpha_wrap.h.
#pragma once

#include "tetops/alpha_wrap.h"
#include "tetops/triangle_surface.h"

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace waxwork {

class Progress;

// Opt-in repairs that change the shape of the surface.
struct SurfaceRepairOptions {
    bool fill_holes = false;  // close every boundary loop with a refined, faired patch
    bool autorefine = false;  // remove self-intersections (CGAL's experimental local remeshing)
    // More triangles than this are refused before any check or repair (0: no limit): the meshers'
    // limit (kMaxSurfaceTriangles), so that a surface too large to mesh is refused at once.
    size_t max_triangles = 0;
    // Set: the file's triangles are wrapped (tetops/alpha_wrap.h) before any check, instead of the
    // repairs above, and the wrap is validated as any surface is.
    std::optional<WrapOptions> wrap = std::nullopt;
};

// The problem of a surface with `triangles` triangles where at most `limit` are taken ("" if none):
// "N triangles, more than the meshers take (M); simplify the surface to at most M triangles first".
std::string triangle_count_problem(size_t triangles, size_t limit);

// Where each element of a repaired surface came from: its index before the repairs (for messages
// that name elements by their index in the user's file), or -1 for one a repair made.
struct SurfaceIndexMap {
    std::vector<int32_t> points;
    std::vector<int32_t> triangles;
};

// Every defect found, as a count plus the first example (smallest indices) so a message can point at
// it. Examples are meaningful only when their count is non-zero.
struct SurfaceDefects {
    size_t point_count = 0;
    size_t triangle_count = 0;

    size_t non_finite_points = 0;  // NaN or infinite coordinates
    int32_t first_non_finite_point = -1;
    size_t invalid_indices = 0;  // triangles referring to a vertex that does not exist
    int32_t first_invalid_triangle = -1;

    // Repairable by repair_safe_defects().
    size_t duplicate_points = 0;  // vertices at exactly the position of an earlier vertex
    size_t unreferenced_points = 0;
    size_t repeated_index_triangles = 0;  // a vertex index used twice in one triangle
    size_t zero_area_triangles = 0;       // three distinct but collinear vertices
    int32_t first_zero_area_triangle = -1;

    // Topology, counted after identifying vertices at identical positions (a file may store one point
    // twice for two faces; the shape is what matters).
    size_t boundary_edges = 0;  // edges used by exactly one triangle
    std::array<int32_t, 2> first_boundary_edge{-1, -1};
    size_t non_manifold_edges = 0;  // edges used by more than two triangles
    std::array<int32_t, 2> first_non_manifold_edge{-1, -1};
    size_t non_manifold_vertices = 0;  // pinched: the triangles around it form several fans
    int32_t first_non_manifold_vertex = -1;
    size_t inconsistent_edges = 0;  // two triangles traverse their shared edge the same way
    std::array<int32_t, 2> first_inconsistent_edge{-1, -1};

    // Geometry.
    size_t self_intersecting_pairs = 0;  // pairs that meet beyond a shared vertex or edge
    std::array<int32_t, 2> first_self_intersecting_pair{-1, -1};
    double signed_volume = 0.0;  // enclosed volume, meaningful for closed oriented surfaces

    // True when the surface can be meshed as it is: nothing to repair, nothing to reject.
    bool is_clean() const;
    // True when repair_safe_defects() has something to do.
    bool has_safe_repairs() const;

    // One line per defect that repair_safe_defects() cannot fix, most important first, e.g.
    // "223 boundary edges (the surface is open; first: vertices 10 and 11)"; empty when the surface
    // is acceptable after the safe repairs. Element indices are translated through origin if given;
    // one it maps to -1 is written "[new I]" with I its index in this surface.
    std::vector<std::string> describe(const SurfaceIndexMap* origin = nullptr) const;
};

// Measures every defect. Never throws for bad geometry; cost O(n log n) (self-intersections use
// CGAL's box intersection and exact predicates).
SurfaceDefects find_surface_defects(const TriangleSurface& surface);

// Applies the repairs that do not change the shape: merges vertices at identical positions, drops
// triangles repeating a vertex, drops zero-area triangles when that opens no hole, drops unreferenced
// vertices, makes the orientation consistent on a closed manifold surface and flips it outward when
// the enclosed volume is negative. Returns one line per repair made. When origin is given it receives,
// for every remaining point and triangle, its index in the surface as passed in.
std::vector<std::string> repair_safe_defects(TriangleSurface& surface,
                                             SurfaceIndexMap* origin = nullptr);

// Applies the shape-changing repairs selected in options (hole filling, self-intersection removal),
// then the safe repairs again. Returns one line per repair made, or a line saying why a requested
// repair could not run (it needs an edge- and vertex-manifold surface). The caller re-validates.
// `progress`, when given, is told each repair as it starts.
std::vector<std::string> repair_hard_defects(TriangleSurface& surface,
                                             const SurfaceRepairOptions& options, Progress* progress = nullptr);

}  // namespace waxwork
