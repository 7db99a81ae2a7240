// Moving the vertices left on the cut-away side of a cut onto the cross-section (TransCut Sec. 5,
// "Cutting Interaction"): each such vertex steps toward the uniform average of its one-ring,
// x <- x + rho (x' - x), unless the step would cross the cutting surface (it is shortened to land on
// the surface, where the vertex stops) or would leave a tet of its star inverted or with a minimum
// dihedral angle under the guard. The guard is the paper's fix for Fig. 9: without it the vertices
// squeeze tets flat and the cotangent weights of the diffusion matrix (Eq. 10) blow up in single
// precision.
#pragma once

#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/tet_mesh.h"

namespace waxwork {

struct RelaxationOptions {
    int max_iterations = 10;
    double step = 0.1;  // rho in the paper
    // A move is rejected when it leaves a tet of the vertex's star under this minimum dihedral angle
    // (degrees); a tet already under it may not get worse. 0 disables the guard (paper Fig. 9(a)):
    // only moves that invert a tet or leave it exactly zero volume are then rejected, so tets can be
    // squeezed to angles of 0.0 degrees (a cube's corner tet at volume 4.5e-20 after 100 sweeps).
    double min_dihedral_guard_deg = 0.5;
};

struct RelaxationReport {
    int iterations = 0;            // sweeps run (the last one may have moved nothing)
    size_t movable_vertices = 0;   // vertices strictly on the cut-away side at the start
    size_t vertices_moved = 0;     // distinct vertices moved at least once
    size_t moves_accepted = 0;
    size_t moves_rejected = 0;     // by the quality guard or the inversion test
    size_t vertices_on_surface = 0;  // vertices whose step was shortened to land on the surface
    double min_dihedral_deg = 0;   // smallest dihedral angle of the whole mesh afterwards (0 if empty)
};

// Relaxes `mesh` in place. `connectivity` must be built from `mesh` (positions may differ: relaxation
// changes positions only, so the connectivity stays valid afterwards). Vertices move in their piece's
// rest frame; the side test is in world space. Deterministic: movable vertices are greedily coloured
// (by index) so that no two of one colour share a tet, and each colour is updated in parallel against
// the current positions, every move tested on its whole star before it is applied.
// Throws InvalidArgumentError for a non-positive step, a negative guard or negative iteration count.
RelaxationReport relax_cut_vertices(TetMesh& mesh, const TetConnectivity& connectivity,
                                    const CuttingSurface& surface, const RelaxationOptions& options = {});

}  // namespace waxwork
