// A regular grid of cubic cells over a tetrahedral volume: the unknowns of the grid methods (finite
// differences after QuadGraph, lattice Boltzmann) and the way their result goes back to the volume.
//
// A cell is inside when its centre lies in a tet. Two inside cells that share a face are linked
// (an interior link) only when the segment between their centres crosses no boundary face of the
// volume, so the two sides of a cut or of a fracture's crack, whose faces coincide in the rest frame,
// are separated even where both sides have cells. Every other axis link of an inside cell is a
// boundary link: it records where the boundary is crossed (as a fraction of the cell size, so a method
// can place its boundary condition there rather than on the staircase of cell faces), the tet whose
// face is crossed (its material gives the boundary coefficients) and the incident light there.
//
// Everything is in the rest frame of the pieces: pieces of a fracture then lie where they were cut
// from, side by side with their crack faces between them.
#pragma once

#include "solver/methods/method_problem.h"
#include "solver/ray_caster.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace waxwork {

// The most voxels (inside or not) a grid may have: 2^24 (a 256^3 box). The voxel table is then 64 MB
// (twice that while cells are located), and a box filled with cells needs about 1 GB of links.
inline constexpr size_t kMaxVoxelGridVoxels = size_t{1} << 24;

// Unit steps of the six link directions: +x, -x, +y, -y, +z, -z.
inline constexpr std::array<std::array<int, 3>, 6> kVoxelDirections = {
    {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}};

// An axis link from an inside cell that crosses the volume's boundary.
struct VoxelLink {
    int32_t cell = -1;            // inside cell index
    int8_t direction = 0;         // 0..5: +x, -x, +y, -y, +z, -z (kVoxelDirections)
    double fraction = 1;          // where the boundary is crossed, in (0, 1] of the cell size from the cell centre
    int32_t tet = -1;             // the tet whose boundary face is crossed (its material gives A, F_dr, eta)
    std::array<double, 3> q{};    // incident light at the crossing (interpolated on the face from vertex q)
    // Outward unit normal of the crossed face (rest frame). A boundary condition on dphi/dn applied
    // along an axis link needs n . axis: the axis faces of the cells cover the surface with
    // |n_x| + |n_y| + |n_z| times its area (1.5 times on average over a sphere).
    std::array<double, 3> normal{};
};

struct VoxelGrid {
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // model units, rest frame; cell (i,j,k) centre =
                                                       // origin + (i+.5, j+.5, k+.5) * cell_size
    double cell_size = 0;                              // model units
    std::array<int, 3> dims{};
    std::vector<int32_t> cell_of_voxel;               // per voxel (i + dims[0]*(j + dims[1]*k)): inside cell index or -1
    std::vector<std::array<int32_t, 3>> cell_coords;  // per inside cell
    std::vector<int32_t> cell_tet;                    // per inside cell: the tet containing its centre
    // Per direction, per inside cell: the inside neighbour across that face, or -1 when the link is a
    // boundary link (then exactly one entry of boundary_links has this cell and direction).
    std::array<std::vector<int32_t>, 6> neighbor;
    std::vector<VoxelLink> boundary_links;  // ordered by (cell, direction)
    // The boundary faces (rest frame), kept for sample_at_vertices' visibility tests.
    std::shared_ptr<const TriangleBvh> boundary_bvh;

    size_t cell_count() const { return cell_tet.size(); }
    size_t voxel_count() const { return cell_of_voxel.size(); }
    Eigen::Vector3d cell_centre(int32_t cell) const {
        const auto& c = cell_coords[cell];
        return origin + (Eigen::Vector3d(c[0], c[1], c[2]) + Eigen::Vector3d::Constant(0.5)) * cell_size;
    }
    // The inside cell at voxel (i, j, k), or -1 when the voxel is outside the volume or the grid.
    int32_t cell_at(int i, int j, int k) const {
        if (i < 0 || j < 0 || k < 0 || i >= dims[0] || j >= dims[1] || k >= dims[2]) return -1;
        return cell_of_voxel[static_cast<size_t>(i) + static_cast<size_t>(dims[0]) * (j + static_cast<size_t>(dims[1]) * k)];
    }
};

// The grid of cubes of side cell_size_mm (millimetres; problem.mm_per_unit converts) covering the
// bounding box of the rest-frame positions, centred on it. Cell centres are located in tets by
// scanning each tet's box (parallel over tets; a centre on a shared face goes to the lowest tet).
// Links are classified with TriangleBvh segment queries (solver/ray_caster.h) over the boundary faces.
// The crossing of a boundary link is found by walking through the tets from the cell's tet along the
// link until a face with no neighbour (double precision; on a crack this is the cell's own piece's
// face, not the coincident face of the piece across), with the nearest boundary face along the link
// (FirstHitGrid, solver/reference/first_hit_grid.h) as the fallback when the walk stalls. q is
// interpolated on that face. Throws InvalidArgumentError ("voxel grid: ...") for a cell size or scale
// that is not a positive finite number, a mesh with no tets, q or connectivity not of this mesh, more
// than kMaxVoxelGridVoxels voxels or more than max_cells inside cells (found before the links are
// built; both messages name a cell size that fits).
VoxelGrid voxelize(const MethodProblem& problem, double cell_size_mm, size_t max_cells = kMaxVoxelGridVoxels);

// How sample_at_vertices found each vertex's value.
struct VertexSamplingStats {
    size_t trilinear = 0;     // all eight cells around the vertex inside and visible: trilinear
    size_t fitted = 0;        // some of them: a weighted linear fit over the visible cells near it
    size_t nearest = 0;       // none near: the nearest inside cell of the same piece (component)
    size_t unsampled = 0;     // its piece has no inside cell within reach: phi = 0
};

// How per-cell values (one rgb triple per inside cell) go back to the volume's vertices: per vertex,
// weights over cells, precomputed once per grid (they depend on geometry only) so that a solve only
// applies them. A cell counts for a vertex only when the segment from its centre to (a point a hair
// inside the vertex's own tets from) the vertex crosses no boundary face, the same visibility as the
// links, so values do not leak across a cut or crack (no segment is tested where no boundary face
// comes near the eight voxels around the vertex).
//  - All eight cells whose centres surround the vertex count: trilinear interpolation (O(h^2)).
//  - Some count: a linear least-squares fit with tent weights over the usable cells of the 3x3x3
//    block around the nearest voxel, or of the 4x4x4 block around the vertex where the first does not
//    determine a plane (O(h^2) where the fit is well posed; near the boundary the vertex lies up to a
//    cell beyond the last centres, and a weighted mean there would be only O(h)); with fewer than four
//    cells or a degenerate spread, their weighted mean. Sampled values are clamped at zero (phi >= 0).
//  - None: the nearest inside cell of the vertex's component within 8 cells; otherwise no weights
//    (phi = 0) and the vertex counts as unsampled (a part thinner than a cell; the method decides how
//    to report it).
// Vertices of no tet get no weights.
struct VertexSampling {
    std::vector<int32_t> offsets{0};  // per vertex: its weights are [offsets[v], offsets[v+1])
    std::vector<int32_t> cells;
    std::vector<double> weights;
    size_t cell_count = 0;
    VertexSamplingStats stats;
};
VertexSampling build_vertex_sampling(const VoxelGrid& grid, const MethodProblem& problem);

// phi per vertex from per-cell values (InvalidArgumentError when their count is not the grid's).
std::vector<std::array<double, 3>> apply_vertex_sampling(const VertexSampling& sampling,
                                                         const std::vector<std::array<double, 3>>& cell_values);

// Both at once; `stats` (optional) receives the counts per case.
std::vector<std::array<double, 3>> sample_at_vertices(const VoxelGrid& grid, const MethodProblem& problem,
                                                      const std::vector<std::array<double, 3>>& cell_values,
                                                      VertexSamplingStats* stats = nullptr);

}  // namespace waxwork
