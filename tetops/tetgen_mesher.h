// TetGen 1.5 as Waxwork's default mesher: a quality constrained Delaunay tetrahedralization of the
// surface (the input triangles are kept, possibly split by Steiner points on them).
#pragma once

#include "tetops/size_field.h"
#include "tetops/tet_mesh.h"
#include "tetops/triangle_surface.h"

namespace waxwork {

class Progress;

struct TetGenSettings {
    SizeField size;                      // unbounded: only the quality bounds refine
    double max_radius_edge_ratio = 2.0;  // -q ratio
    double min_dihedral_deg = 10.0;      // -q /angle
    bool quality = true;                 // false: the bare constrained Delaunay tetrahedralization
    bool quiet = true;                   // -Q
    // -S: the points TetGen may add to the surface's (boundary recovery and refinement; -1: no limit).
    // A graded size applies it to both of its runs.
    long max_added_points = -1;
    Progress* progress = nullptr;  // told the stage of a graded run (sizing field, graded)
};

// Uniform size: one run with a volume bound (-a). Graded size: one run from the surface refines to
// a background mesh whose vertices carry edge(depth) (-m): the Delaunay tetrahedralization of the
// surface's points and a grid of points inside it. Throws AlgorithmError with TetGen's reason when it gives up.
// With settings.max_added_points, `stopped_at_point_limit` (when given) says whether TetGen added
// that many points, so that the mesh is its refinement cut short rather than a finished one.
TetMesh tetgen_tetrahedralize(const TriangleSurface& surface, const TetGenSettings& settings,
                              bool* stopped_at_point_limit = nullptr);

// The TetGen volume bound (-a) that gives tets of mean edge length `edge`: a regular tet of edge L has
// volume L^3 / (6 sqrt 2); TetGen's tets under a bound a have mean volume ~0.31 a and mean edge
// ~(2.85 a * 6 sqrt 2)^(1/3) (measured on spot, 230K tets).
double tetgen_volume_bound_for_edge(double edge);

}  // namespace waxwork
