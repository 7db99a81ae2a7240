// CGAL Mesh_3 as Waxwork's second mesher: Delaunay refinement that also remeshes the surface (so, unlike
// TetGen, it can go coarser than the input triangles), then sliver perturbation and exudation.
#pragma once

#include "tetops/size_field.h"
#include "tetops/tet_mesh.h"
#include "tetops/triangle_surface.h"

namespace waxwork {

class Progress;

struct CgalSettings {
    SizeField size;                      // unbounded: a size from the bounding box is used
    double max_radius_edge_ratio = 2.0;  // cell_radius_edge_ratio (raised to 2, where termination holds)
    // The sliver bound of the perturber and the exuder: a target, not a guarantee (each stops when it
    // can no longer raise the worst angle). Exudation alone left fandisk (8K tets) at 0.07 degrees and
    // armadillo (29K) at 3.5; with the perturber first, 8.8 and 5.0 (spot at 50K: 6.6 -> 10.0) for
    // about 1 s more (TetrahedralizeTest.CgalPerturbsSliversTowardsTheBound).
    double min_dihedral_deg = 10.0;
    // Mesh_3's own bound on its work: refinement stops at this many vertices and the run fails with
    // AlgorithmError. 0: no limit. tetrahedralize() sets it to many times the vertices the size
    // predicts. It does not bound the protection of sharp edges, which can shrink its balls for hours
    // without adding vertices; needle tips that would make it do so are refused first (sharp_tips.h).
    size_t max_vertices = 0;
    size_t predicted_vertices = 0;  // for the message when max_vertices is reached
    Progress* progress = nullptr;   // stages, and its cancel flag stops the refinement
};

// Sharp edges (dihedral angle under 120 degrees, CGAL's 60-degree feature angle) are protected so
// that cubes and CAD parts keep their corners. Deterministic: every random generator is seeded.
// Throws AlgorithmError when the surface has a needle tip (sharp_tips.h), CGAL fails, reaches
// settings.max_vertices or produces no tets, and
// CancelledError when settings.progress asks it to stop.
TetMesh cgal_tetrahedralize(const TriangleSurface& surface, const CgalSettings& settings);

}  // namespace waxwork
