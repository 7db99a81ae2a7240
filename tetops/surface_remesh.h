// Remeshing a closed surface at a uniform edge length (CGAL's isotropic remeshing, Botsch and Kobbelt,
// "A remeshing approach to multiresolution modeling", SGP 2004): what lets TetGen, which keeps every
// input triangle, mesh a surface far more detailed than the size or the tet budget asks for.
#pragma once

#include "tetops/triangle_surface.h"

#include <cstddef>

namespace waxwork {

class Progress;

struct SurfaceRemeshReport {
    size_t triangles_in = 0;
    size_t triangles_out = 0;
    double edge = 0;  // the target edge length, model units
};

struct RemeshedSurface {
    TriangleSurface surface;  // closed, 2-manifold, outward oriented, free of self-intersections
    SurfaceRemeshReport report;
};

// The mean length of the surface's edges (each triangle's three; shared edges count twice).
double mean_edge_length(const TriangleSurface& surface);

// Remeshes a closed, outward-oriented, self-intersection-free surface towards edges of `edge` model
// units (split above 4/3 edge, collapse below 4/5 edge, flips and tangential relaxation), projecting
// every moved or new vertex onto the input surface. Nothing is protected: features narrower than the
// edge are smoothed over, which is the point. Throws AlgorithmError when the result is not closed,
// is not outward oriented or intersects itself (a part thinner than the edge can fold through
// itself), and CancelledError when `progress` asks it to stop (checked between iterations).
RemeshedSurface remesh_surface(const TriangleSurface& surface, double edge, Progress* progress = nullptr);

}  // namespace waxwork
