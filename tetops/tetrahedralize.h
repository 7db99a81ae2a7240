// Surface-to-volume meshing: TetGen (default) or CGAL Mesh_3, with quality and size bounds.
#pragma once

#include "tetops/quality.h"
#include "tetops/tet_mesh.h"
#include "tetops/triangle_surface.h"

#include <optional>

namespace waxwork {

enum class Mesher { TetGen, Cgal };

// How fine the volume is. Exactly one of the three ways is used, in this order of precedence:
// an explicit edge length, a target tet count, or a graded size (fine near the surface, where the
// light varies over the diffusion length, coarser inside).
struct MeshSizing {
    std::optional<double> edge_length;   // target edge length in model units, uniform
    std::optional<size_t> target_tets;   // about this many tets (within 20%)
    // Graded: edge length at the surface and the growth rate inward (edge(d) = surface_edge + grading*d,
    // capped at max_edge). Used when neither of the above is set.
    double surface_edge = 0;
    double grading = 0.5;
    double max_edge = 0;
};

struct MeshingOptions {
    Mesher mesher = Mesher::TetGen;
    MeshSizing sizing;
    double max_radius_edge_ratio = 2.0;  // TetGen -q bound
    double min_dihedral_deg = 10.0;      // TetGen -q/ bound (and CGAL exuder goal)
    bool quiet = true;
};

struct MeshingResult {
    TetMesh mesh;
    QualityReport quality;
    double milliseconds = 0;
};

// Fills a closed, outward-oriented, self-intersection-free surface with tets. Throws
// InvalidArgumentError on absurd options and AlgorithmError when the mesher fails.
MeshingResult tetrahedralize(const TriangleSurface& surface, const MeshingOptions& options);

}  // namespace waxwork
