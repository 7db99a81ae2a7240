#include "solver/owned_rows.h"

#include "base/error.h"
#include "tetops/connectivity.h"

#include <algorithm>
#include <string>

namespace waxwork {

RowRange balanced_row_range(size_t rows, int ranks, int rank) {
    if (ranks <= 0 || rank < 0 || rank >= ranks)
        throw InvalidArgumentError("row partition: rank " + std::to_string(rank) + " of " + std::to_string(ranks));
    if (rows < static_cast<size_t>(ranks))
        throw InvalidArgumentError(std::to_string(ranks) + " processes for " + std::to_string(rows) +
                                   " vertices: every process must own at least one vertex (run at most " +
                                   std::to_string(rows) + ")");
    const size_t base = rows / ranks, extra = rows % ranks, r = static_cast<size_t>(rank);
    const size_t begin = r * base + std::min(r, extra);
    return {static_cast<int32_t>(begin), static_cast<int32_t>(begin + base + (r < extra ? 1 : 0))};
}

OwnedRows assemble_owned_rows(const TetMesh& mesh, const std::vector<TetMaterial>& materials,
                              const std::vector<std::array<double, 3>>& q,
                              std::span<const PortableCornerLight> corners, RowRange range,
                              const AssemblyOptions& options) {
    const size_t n = mesh.vertex_count();
    if (materials.size() != mesh.tet_count() || q.size() != n)
        throw InvalidArgumentError("owned rows: " + std::to_string(materials.size()) + " materials and " +
                                   std::to_string(q.size()) + " light values for " + std::to_string(mesh.tet_count()) +
                                   " tets and " + std::to_string(n) + " vertices");
    if (range.begin < 0 || range.end < range.begin || static_cast<size_t>(range.end) > n)
        throw InvalidArgumentError("owned rows: vertices [" + std::to_string(range.begin) + ", " +
                                   std::to_string(range.end) + ") are not in a mesh of " + std::to_string(n));

    // The tets touching the range and their vertices; the range itself is kept whole, so that a vertex
    // of no tet gets its identity row as in the whole assembly.
    std::vector<int32_t> global_tet;
    std::vector<uint8_t> used(n, 0);
    std::fill(used.begin() + range.begin, used.begin() + range.end, uint8_t{1});
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const Tet& tet = mesh.tets[t];
        if (std::none_of(tet.begin(), tet.end(), [&](int32_t v) { return range.contains(v); })) continue;
        global_tet.push_back(static_cast<int32_t>(t));
        for (const int32_t v : tet) used[v] = 1;
    }
    std::vector<int32_t> local_of(n, -1), global_vertex;
    for (size_t v = 0; v < n; ++v)
        if (used[v]) {
            local_of[v] = static_cast<int32_t>(global_vertex.size());
            global_vertex.push_back(static_cast<int32_t>(v));
        }
    std::vector<uint8_t>().swap(used);

    TetMesh local;
    local.positions.reserve(global_vertex.size());
    for (const int32_t v : global_vertex) local.positions.push_back(mesh.positions[v]);
    local.tets.reserve(global_tet.size());
    std::vector<TetMaterial> local_materials;
    local_materials.reserve(global_tet.size());
    for (const int32_t t : global_tet) {
        Tet tet = mesh.tets[t];
        for (int32_t& v : tet) v = local_of[v];
        local.tets.push_back(tet);
        local_materials.push_back(materials[t]);
    }
    const TetConnectivity connectivity = build_connectivity(local);
    const DiffusionMatrix matrix = assemble_diffusion_matrix(local, connectivity, local_materials, options);

    std::vector<std::array<double, 3>> local_q(global_vertex.size());
    for (size_t l = 0; l < global_vertex.size(); ++l) local_q[l] = q[global_vertex[l]];
    // The corners on faces of local tets, renamed into the local volume (boundary faces are ordered by
    // tet and local face there too).
    std::vector<CornerLight> local_corners;
    for (const PortableCornerLight& corner : corners) {
        const auto tet = std::lower_bound(global_tet.begin(), global_tet.end(), corner.tet);
        if (tet == global_tet.end() || *tet != corner.tet) continue;
        CornerLight c;
        c.tet = static_cast<int32_t>(tet - global_tet.begin());
        const auto face = std::lower_bound(
            connectivity.boundary_faces.begin(), connectivity.boundary_faces.end(), std::pair(c.tet, corner.local_face),
            [](const BoundaryFace& f, const std::pair<int32_t, int32_t>& key) {
                return std::pair(f.tet, f.local_face) < key;
            });
        if (face == connectivity.boundary_faces.end() || face->tet != c.tet || face->local_face != corner.local_face)
            throw InvalidArgumentError("owned rows: corner light on face " + std::to_string(corner.local_face) +
                                       " of tet " + std::to_string(corner.tet) + ", which is not a boundary face");
        c.face = static_cast<int32_t>(face - connectivity.boundary_faces.begin());
        for (int k = 0; k < 3; ++k) c.vertices[k] = local_of[corner.vertices[k]];
        c.delta = corner.delta;
        local_corners.push_back(c);
    }

    OwnedRows rows;
    rows.range = range;
    rows.local_tets = global_tet.size();
    rows.local_vertices = global_vertex.size();
    const int32_t first = local_of[range.begin];  // owned rows are contiguous locally too
    const auto owned = static_cast<size_t>(range.size());
    rows.inside_count.resize(owned);
    rows.outside_count.resize(owned);
    for (size_t i = 0; i < owned; ++i) {
        const size_t l = static_cast<size_t>(first) + i;
        for (int32_t k = matrix.offsets[l]; k < matrix.offsets[l + 1]; ++k) {
            const int32_t column = global_vertex[matrix.columns[k]];
            rows.columns.push_back(column);
            ++(range.contains(column) ? rows.inside_count[i] : rows.outside_count[i]);
            for (int c = 0; c < 3; ++c) rows.values[c].push_back(matrix.values[c][k]);
        }
        rows.offsets.push_back(static_cast<int32_t>(rows.columns.size()));
    }
    std::vector<double> b(global_vertex.size());
    for (int c = 0; c < 3; ++c) {
        diffusion_right_hand_side(matrix, local_q, c, b);
        add_corner_light(matrix, local_corners, c, b);
        rows.rhs[c].assign(b.begin() + first, b.begin() + first + static_cast<std::ptrdiff_t>(owned));
    }
    return rows;
}

EdgeCount owned_edge_count(const OwnedRows& rows) {
    EdgeCount count;
    for (size_t i = 0; i + 1 < rows.offsets.size(); ++i) {
        const int32_t vertex = rows.range.begin + static_cast<int32_t>(i);
        for (int32_t k = rows.offsets[i]; k < rows.offsets[i + 1]; ++k) {
            const int32_t other = rows.columns[k];
            if (other <= vertex) continue;
            ++count.edges;
            count.cut += !rows.range.contains(other);
        }
    }
    return count;
}

}  // namespace waxwork
