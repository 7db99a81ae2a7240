// One process's share of the diffusion system when several solve it together (the distributed render,
// solver/petsc_distributed_solve.h): a contiguous range of vertices, whose rows of M and b it assembles
// from the tets around them only.
//
// Rows are split into contiguous ranges of the mesh's vertex order, balanced by vertex count. Fresh
// meshes number their vertices along a Morton curve (tetops/spatial_order.h), so a range is a compact
// region of space and few edges cross between ranges; a mesh in another order still solves correctly,
// with a larger cut (more communication per iteration).
//
// A row of M and b involves only the tets containing its vertex and the boundary faces of those tets
// (diffusion_matrix.h). The tets touching the range, with their vertices renumbered in ascending global
// order, form a small volume whose assembly gives exactly the range's rows: every face at an owned
// vertex has both of its tets in that volume, so it is a boundary face there exactly when it is one in
// the whole mesh, and the tets and faces around a vertex keep their order, so even the summation order
// of each entry is the whole assembly's.
#pragma once

#include "solver/diffusion_matrix.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

// Vertices [begin, end) of the mesh.
struct RowRange {
    int32_t begin = 0;
    int32_t end = 0;
    int32_t size() const { return end - begin; }
    bool contains(int32_t v) const { return v >= begin && v < end; }
};

// Rank `rank` of `ranks`' range of `rows` rows: contiguous, sizes differing by at most one, the larger
// ones first. Throws InvalidArgumentError when there are fewer rows than ranks (a rank would own none)
// or rank is outside [0, ranks).
RowRange balanced_row_range(size_t rows, int ranks, int rank);

// A corner's light (diffusion_matrix.h: CornerLight) with its face named by its tet and the tet's local
// face instead of an index into one connectivity's boundary faces, so that it means the same face in
// any volume holding that tet.
struct PortableCornerLight {
    int32_t tet;                      // in the whole mesh
    int32_t local_face;               // 0..3, BoundaryFace::local_face
    std::array<int32_t, 3> vertices;  // in the whole mesh, this corner first
    std::array<double, 3> delta;
};

// The range's rows of M (three channels, global column indices, ascending per row) and of b, from
// per-vertex q (the whole mesh's, as solve_diffusion takes it) and the crease corners.
struct OwnedRows {
    RowRange range;
    std::vector<int32_t> offsets{0};  // per owned row
    std::vector<int32_t> columns;     // global vertex indices
    std::array<std::vector<double>, 3> values;
    std::array<std::vector<double>, 3> rhs;  // per owned row
    // Per owned row, the entries whose column lies inside and outside the range: PETSc's d_nnz and
    // o_nnz (the diagonal and off-diagonal blocks of a row-distributed matrix).
    std::vector<int32_t> inside_count, outside_count;
    size_t local_tets = 0;      // tets assembled (those touching the range)
    size_t local_vertices = 0;  // their vertices (the range and its halo)
};

// Assembles the rows of `range`. materials: one per tet of `mesh`; q: one per vertex. Throws
// InvalidArgumentError for sizes that do not match the mesh or a range outside it, and what
// assemble_diffusion_matrix throws.
OwnedRows assemble_owned_rows(const TetMesh& mesh, const std::vector<TetMaterial>& materials,
                              const std::vector<std::array<double, 3>>& q,
                              std::span<const PortableCornerLight> corners, RowRange range,
                              const AssemblyOptions& options);

// Edges of the mesh counted from one range's rows: those from an owned vertex to a higher vertex, and
// those of them whose other end lies outside the range. Summed over the ranges of a partition, each
// edge of the mesh is counted once, and `cut` is the partition's edge cut.
struct EdgeCount {
    int64_t edges = 0;
    int64_t cut = 0;
};
EdgeCount owned_edge_count(const OwnedRows& rows);

}  // namespace waxwork
