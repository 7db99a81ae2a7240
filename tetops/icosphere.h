// A sphere surface for analytic references and tests: an icosahedron subdivided `level` times
// (20 * 4^level triangles), projected onto the sphere of radius r centred at the origin, outward
// oriented. Hand-written rather than CGAL's make_icosahedron + subdivision: it is twenty lines and
// returns the project's TriangleSurface directly.
#pragma once

#include "tetops/triangle_surface.h"

namespace waxwork {

// Throws InvalidArgumentError for level < 0 or > 8, or a non-positive radius.
TriangleSurface make_icosphere(int level, double radius);

}  // namespace waxwork
