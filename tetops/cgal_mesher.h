// CGAL Mesh_3 as Waxwork's second mesher: Delaunay refinement that also remeshes the surface (so, unlike
// TetGen, it can go coarser than the input triangles), followed by sliver exudation.
#pragma once

#include "tetops/size_field.h"
#include "tetops/tet_mesh.h"
#include "tetops/triangle_surface.h"

namespace waxwork {

struct CgalSettings {
    SizeField size;                      // unbounded: a size from the bounding box is used
    double max_radius_edge_ratio = 2.0;  // cell_radius_edge_ratio (raised to 2, where termination holds)
    double min_dihedral_deg = 10.0;      // sliver bound of the exuder
};

// Sharp edges (dihedral angle under 120 degrees, CGAL's 60-degree feature angle) are protected so
// that cubes and CAD parts keep their corners. Deterministic: every random generator is seeded.
// Throws AlgorithmError when CGAL fails or produces no tets.
TetMesh cgal_tetrahedralize(const TriangleSurface& surface, const CgalSettings& settings);

}  // namespace waxwork
