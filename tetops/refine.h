// Conforming local refinement of a tet mesh by longest-edge bisection (Rivara 1984, "Algorithms for
// refining triangular grids suitable for adaptive and multigrid techniques", IJNME 20; in 3D Rivara and
// Levin 1992, "A 3-D refinement algorithm suitable for adaptive and multi-grid techniques", Comm. Appl.
// Numer. Methods 8): a marked tet is split in two at the midpoint of its longest edge, and every tet
// around that edge is split there too, first along its own longest edge when that is another one
// (the propagation), so the result has no hanging vertex.
//
// Guarantees, each tested (tests/tetops/refine_test.cpp):
//   - conforming: every interior face is shared by exactly two tets, and the boundary is the same point
//     set (new boundary vertices are midpoints of boundary edges; nothing is projected or moved);
//   - nested: every vertex before keeps its index and position, new vertices are appended, and every
//     tet after lies inside one tet before (RefineResult::new_to_old_tet);
//   - exact per-tet data: a child inherits its parent's material, original id and piece id bit for bit;
//   - volume: the children of a tet fill it exactly (in exact arithmetic; to rounding of the midpoints);
//   - orientation: children are positively oriented (a vertex replaced by a point on one of its edges);
//   - quality: no tet is created under min(guard, the minimum dihedral angle of the tet before it came
//     from). Longest-edge bisection keeps shapes well in practice (its children's angles stay bounded
//     over repeated refinement: Rivara and Levin report it in 3D, and the test measures it), but a
//     bound on its similarity classes is proven only in 2D (Rosenberg and Stenger 1975); in 3D it is
//     open (Korotov, Plaza and Suarez 2016, "Longest-edge n-section algorithms: properties and open
//     problems", J. Comput. Appl. Math. 293). So the guard is enforced, not assumed: the refinement of
//     one mark is a transaction, and when it would create a tet under the guard it is undone whole and
//     the mark skipped (counted in RefineResult).
//
// Written by hand rather than with a library: CGAL 5.5's tetrahedral_isotropic_remeshing evaluates its
// sizing field at the origin only (Tetrahedral_remeshing/internal/tetrahedral_adaptive_remeshing_impl.h:
// m_sizing(CGAL::ORIGIN); "@todo implement non-uniform sizing field"), so it cannot refine locally, and
// it flips, collapses and moves vertices: the old vertices and the tets' materials (a subdomain index
// there, against a painted material per tet here) would not survive exactly. TetGen's refinement with a
// background size (-r -m) re-inserts Steiner points Delaunay-style and keeps region attributes only.
// Bisection keeps every old vertex, nests the new mesh in the old one and carries per-tet data exactly,
// which undo, the warm start and the multigrid rebuild around an edit rely on.
#pragma once

#include "tetops/cut.h"
#include "tetops/tet_mesh.h"

#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

class Progress;

// Tets are indexed with int32_t: a refinement may not grow a mesh past this many tets.
inline constexpr size_t kMaxRefinedTets = size_t{1} << 30;

struct RefineOptions {
    // No tet is created under min(guard_deg, the angle of the tet it came from); 0 disables the guard.
    double guard_deg = 0.5;
    // The refined mesh has at most this many tets (0: no budget). Marks are refined in the order given
    // until the next one would pass the budget.
    size_t max_tets = 0;
};

struct RefineResult {
    size_t marks = 0;                // marks given
    size_t marks_refined = 0;        // marked tets bisected, by their own mark or an earlier mark's propagation
    size_t marks_skipped_guard = 0;  // marks whose refinement would have created a tet under the guard
    size_t marks_skipped_budget = 0; // marks left when the budget was reached
    size_t bisections = 0;           // tets bisected (each adds one tet)
    double min_dihedral_deg = 0;     // of the whole mesh after (0 when empty)
    // Per tet after: the tet before that contains it.
    std::vector<int32_t> new_to_old_tet;
    // Per vertex after: itself for a vertex before (same index), else the midpoint (t = 0.5) of the edge
    // a-b it was made on; a and b may be vertices made earlier by the same refinement (lower indices).
    std::vector<VertexOrigin> vertex_origins;
};

// Bisects each marked tet (an index into mesh.tets before the call) once along its longest edge, with
// propagation, in the order given (marks of tets already bisected by an earlier mark's propagation,
// and repeated marks, do nothing more). Deterministic: the same mesh and marks give the same result bit
// for bit. Throws InvalidArgumentError for a mark out of range, a guard outside [0, 60) degrees or a
// budget below the mesh's tet count or above kMaxRefinedTets; CancelledError when `progress` asks to
// stop (the mesh is then valid and conforming, refined by the marks done so far).
RefineResult refine_tets(TetMesh& mesh, std::span<const int32_t> marks, const RefineOptions& options = {},
                         Progress* progress = nullptr);

// Refines around `points` (world space) to a size: in rounds, the tets whose centroid (through its
// piece's transform) lies within `radius` of a point and whose longest edge is longer than
// `edge_length` are marked (ascending) and bisected as refine_tets bisects them, until none is left,
// a round bisects nothing (the guard) or the budget stops it. Longest-edge bisection halves a tet's
// diameter within three generations, so the rounds number about 3 log2(longest edge / edge_length).
// The result counts all rounds (marks: tets marked over the rounds), its maps relate the mesh after
// to the mesh before the first round. Throws InvalidArgumentError for no points, a non-finite point,
// a radius or edge length that is not positive and finite, and as refine_tets.
RefineResult refine_near_points(TetMesh& mesh, std::span<const Eigen::Vector3d> points, double radius,
                                double edge_length, const RefineOptions& options = {}, Progress* progress = nullptr);

}  // namespace waxwork
