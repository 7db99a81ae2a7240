// Breaking a volume into pieces and putting pieces back together.
//
// A piece is a set of tets with its own rigid transform (TetMesh::piece_ids, piece_transforms). Pieces
// share no vertices: fracturing duplicates every vertex on a crack so each piece can move on its own;
// welding merges coincident vertices of pieces whose crack faces meet again.
//
// CONTRACT HEADER: written by the lead so editor/ can be built against it while tetops/fracture.cpp
// is implemented. Signatures may gain options but not lose them.
#pragma once

#include "tetops/cut.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

struct FractureOptions {
    // Split tets crossed by a cell wall so crack faces are flat (exact_cut.h); false: cracks follow
    // existing tet faces (each tet goes to the cell of its centroid).
    bool exact = true;
    // Pieces with fewer tets than this are merged into the neighbouring piece they share most faces
    // with (no dust).
    int min_piece_tets = 8;
    // Pieces under this fraction of the mean cell's volume (the volume over the cells) are merged the
    // same way: an exact wall can leave a part of a cell that meets a concave volume in a corner
    // which has enough tets but almost no volume (spot, 10 seeds: 17 tets of 3e-9 of the volume).
    double min_piece_volume = 1e-3;
    // Exact mode: vertices this close to a wall (as a fraction of a crossed edge) move onto it instead
    // of being cut off in a sliver (SplitOptions::snap_fraction); 0 splits every crossed edge, which
    // keeps every unsplit tet's shape but leaves thinner tets.
    double snap_fraction = 0.2;
    // Exact mode: boundary vertices slide onto a wall where the surface bends by at most this angle
    // (SplitOptions::boundary_bend_deg; 0 keeps the outer surface exactly).
    double boundary_bend_deg = 20;
    // Exact mode: after each wall is split in, vertices around new or moved tets under this angle
    // (degrees) are optimised within the walls and the boundary, guarded (SplitOptions::
    // smooth_below_deg, split_quality.h); 0 leaves the split as the case table made it.
    double smooth_below_deg = 5;
    // Exact mode: vertices that walls of earlier cells left inside a later cell (no crack) are
    // collapsed into a neighbour where no tet ends up under min(5 degrees, the worst around the vertex
    // before) (split_coarsening.h); false keeps every split, so that no vertex moves and the
    // children of each tet add up to it when snapping and smoothing are off too.
    bool collapse_swallowed_walls = true;
};

struct FractureResult {
    int pieces_before = 0;
    int pieces_after = 0;
    size_t vertices_duplicated = 0;  // vertices added on crack faces
    size_t tets_split = 0;           // tets split along cell walls (exact mode)
    size_t vertices_collapsed = 0;   // made on walls later cells swallowed, collapsed again (split_coarsening.h)
    double min_dihedral_deg = 0;     // of the whole mesh afterwards
    // Exact mode: tets whose minimum dihedral angle is under min(0.5 degrees, that of the tet before
    // the fracture they come from), counted from the result; all others meet that bound.
    size_t tets_under_guard = 0;
    // Per vertex after: where it comes from. Vertices before keep their index and have
    // VertexOrigin::vertex(v); every vertex the fracture appends names vertices with lower indices
    // after: edge ab (a != b) and the parameter along it when a wall made it there, vertex a when it is
    // a crack copy of a. Read in index order it carries per-vertex data across the fracture (the
    // editor's warm start).
    std::vector<VertexOrigin> vertex_origins;
};

// More cells than this is not a fracture but a re-meshing (the exact split's passes cost O(pieces x
// tets)): the command line and sessions refuse it (the editor's slider stops at 12).
inline constexpr int kMaxFracturePieces = 1000;

// `count` seed points scattered inside the volume (world space), deterministic for `seed`: a tet drawn
// with probability proportional to its volume, then a uniform point in it (std::mt19937).
// Throws InvalidArgumentError for count < 1, count > tet count or an empty mesh.
std::vector<Eigen::Vector3d> scatter_fracture_seeds(const TetMesh& mesh, int count, uint32_t seed);

// Breaks every existing piece along the Voronoi cells of `seeds` (world space): each cell's part of
// each piece becomes a piece (new pieces take their parent's transform). Original ids and materials
// follow their tets (split tets keep their parent's original id and material).
// Implementation notes (fracture.cpp): pieces are renumbered by their lowest tet and piece_transforms
// holds exactly the pieces after (empty pieces are dropped). A cell can give fewer pieces than seeds
// (a seed whose cell holds fewer than min_piece_tets tets is merged as dust) or more (a cell that meets
// a concave volume in several parts gives one piece per part). Exact mode builds the diagram one seed
// at a time; the vertices that walls of earlier seeds left inside a later cell are collapsed again
// where that keeps the angles (FractureOptions::collapse_swallowed_walls), the rest stay as extra
// splits inside that piece.
// Throws InvalidArgumentError for more seeds than the tets allow pieces of min_piece_tets, and when the
// exact split grows the mesh past 32 times its tets and 100,000 more (many pieces of a coarse volume); the mesh is
// then partly split, so callers that keep theirs fracture a copy.
FractureResult fracture_voronoi(TetMesh& mesh, std::span<const Eigen::Vector3d> seeds,
                                const FractureOptions& options = {});

// Breaks along planes n.x = d (world space): each planar side region becomes a piece.
FractureResult fracture_planes(TetMesh& mesh, std::span<const Eigen::Vector4d> planes,
                               const FractureOptions& options = {});

// Sets the transform of one piece. Throws InvalidArgumentError for a bad piece index or a
// non-rigid / non-finite transform.
void set_piece_transform(TetMesh& mesh, int piece, const RigidTransform& transform);

struct WeldResult {
    int pieces_before = 0;
    int pieces_after = 0;
    size_t vertices_merged = 0;
    // Per vertex before: its index after, or -1 when it was merged into another vertex (which keeps
    // its own entry). The vertices left keep their order.
    std::vector<int32_t> old_to_new_vertex;
};

// Merges pieces whose boundary faces coincide in world space (within `tolerance`, world units, >= 0):
// coincident vertices become one, the pieces become one piece (the lowest index's transform; the
// others' rest positions are re-expressed in it). Pieces that do not touch stay apart. Vertices of
// different pieces are coincident when they lie within the tolerance and within half of either one's
// shortest edge; they merge nearest pairs first, and never two vertices of one piece into one.
// Implementation notes (fracture.cpp): pieces join only when a whole boundary face matches (touching at
// a point or an edge joins nothing); absorbed pieces are removed and the rest renumbered in order;
// throws AlgorithmError (mesh unchanged) if merging would flatten a tet (tolerance too large).
WeldResult weld_touching_pieces(TetMesh& mesh, double tolerance);

}  // namespace waxwork
