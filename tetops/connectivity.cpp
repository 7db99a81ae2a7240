#include "tetops/connectivity.h"

#include "tetops/error.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <numeric>

namespace waxwork {
namespace {

// Exclusive prefix sum of counts into offsets (size n+1).
std::vector<int32_t> offsets_from_counts(const std::vector<int32_t>& counts) {
    std::vector<int32_t> offsets(counts.size() + 1, 0);
    std::inclusive_scan(counts.begin(), counts.end(), offsets.begin() + 1);
    return offsets;
}

// Vertex -> tets by counting sort; each row comes out sorted because tets are visited in order.
CompressedRows build_vertex_tets(const TetMesh& mesh) {
    std::vector<int32_t> counts(mesh.vertex_count(), 0);
    for (const Tet& tet : mesh.tets)
        for (int32_t v : tet) ++counts[v];
    CompressedRows rows;
    rows.offsets = offsets_from_counts(counts);
    rows.indices.resize(rows.offsets.back());
    std::vector<int32_t> cursor(rows.offsets.begin(), rows.offsets.end() - 1);
    for (size_t t = 0; t < mesh.tets.size(); ++t)
        for (int32_t v : mesh.tets[t]) rows.indices[cursor[v]++] = static_cast<int32_t>(t);
    return rows;
}

bool tet_contains(const Tet& tet, int32_t v) { return tet[0] == v || tet[1] == v || tet[2] == v || tet[3] == v; }

// Face neighbours by intersecting vertex stars: the tet across a face is the other tet that contains
// all three of its vertices, found in the shortest of the three vertex stars. Linear in the mesh size
// and free of the global sort that a face-hashing approach needs.
std::vector<std::array<int32_t, 4>> build_tet_neighbors(const TetMesh& mesh, const CompressedRows& vertex_tets) {
    std::vector<std::array<int32_t, 4>> neighbors(mesh.tets.size());
    std::atomic<int64_t> overfull_face{-1};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.tets.size()), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t t = r.begin(); t != r.end(); ++t) {
            const Tet& tet = mesh.tets[t];
            for (int f = 0; f < 4; ++f) {
                const auto& local = kTetFaces[f];
                const int32_t a = tet[local[0]], b = tet[local[1]], c = tet[local[2]];
                int32_t pivot = a;
                for (int32_t v : {b, c})
                    if (vertex_tets.row(v).size() < vertex_tets.row(pivot).size()) pivot = v;
                int32_t found = -1;
                for (int32_t other : vertex_tets.row(pivot)) {
                    if (other == static_cast<int32_t>(t)) continue;
                    const Tet& o = mesh.tets[other];
                    if (tet_contains(o, a) && tet_contains(o, b) && tet_contains(o, c)) {
                        if (found >= 0) overfull_face = static_cast<int64_t>(t);
                        found = other;
                    }
                }
                neighbors[t][f] = found;
            }
        }
    });
    if (overfull_face >= 0)
        throw InvalidMeshError("a face of tet " + std::to_string(overfull_face.load()) +
                               " is shared by more than two tets");
    return neighbors;
}

// Vertex one-rings: the union of the vertices of each vertex's tets, sorted and deduplicated in
// place in a scratch buffer whose rows are sized 3x the star (an upper bound), then compacted.
CompressedRows build_vertex_vertices(const TetMesh& mesh, const CompressedRows& vertex_tets) {
    const size_t n = mesh.vertex_count();
    std::vector<int32_t> scratch(3 * vertex_tets.indices.size());
    std::vector<int32_t> counts(n, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
            int32_t* begin = scratch.data() + 3 * static_cast<size_t>(vertex_tets.offsets[v]);
            int32_t* out = begin;
            for (int32_t t : vertex_tets.row(v))
                for (int32_t u : mesh.tets[t])
                    if (u != static_cast<int32_t>(v)) *out++ = u;
            std::sort(begin, out);
            counts[v] = static_cast<int32_t>(std::unique(begin, out) - begin);
        }
    });
    CompressedRows rows;
    rows.offsets = offsets_from_counts(counts);
    rows.indices.resize(rows.offsets.back());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v)
            std::copy_n(scratch.data() + 3 * static_cast<size_t>(vertex_tets.offsets[v]), counts[v],
                        rows.indices.data() + rows.offsets[v]);
    });
    return rows;
}

std::vector<std::array<int32_t, 2>> build_edges(const CompressedRows& vertex_vertices) {
    const size_t n = vertex_vertices.row_count();
    std::vector<int32_t> counts(n, 0);
    tbb::parallel_for(size_t{0}, n, [&](size_t v) {
        const auto row = vertex_vertices.row(v);
        counts[v] = static_cast<int32_t>(row.end() - std::upper_bound(row.begin(), row.end(), static_cast<int32_t>(v)));
    });
    const std::vector<int32_t> offsets = offsets_from_counts(counts);
    std::vector<std::array<int32_t, 2>> edges(offsets.back());
    tbb::parallel_for(size_t{0}, n, [&](size_t v) {
        const auto row = vertex_vertices.row(v);
        auto first = std::upper_bound(row.begin(), row.end(), static_cast<int32_t>(v));
        int32_t out = offsets[v];
        for (auto it = first; it != row.end(); ++it) edges[out++] = {static_cast<int32_t>(v), *it};
    });
    return edges;
}

std::vector<BoundaryFace> build_boundary_faces(const TetMesh& mesh,
                                               const std::vector<std::array<int32_t, 4>>& neighbors) {
    std::vector<int32_t> counts(mesh.tets.size());
    tbb::parallel_for(size_t{0}, mesh.tets.size(), [&](size_t t) {
        counts[t] = static_cast<int32_t>(std::count(neighbors[t].begin(), neighbors[t].end(), -1));
    });
    const std::vector<int32_t> offsets = offsets_from_counts(counts);
    std::vector<BoundaryFace> faces(offsets.back());
    tbb::parallel_for(size_t{0}, mesh.tets.size(), [&](size_t t) {
        int32_t out = offsets[t];
        for (int f = 0; f < 4; ++f)
            if (neighbors[t][f] < 0) {
                const Tet& tet = mesh.tets[t];
                faces[out++] = {{tet[kTetFaces[f][0]], tet[kTetFaces[f][1]], tet[kTetFaces[f][2]]},
                                static_cast<int32_t>(t), f};
            }
    });
    return faces;
}

int32_t find_root(std::vector<int32_t>& parent, int32_t x) {
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];  // path halving
        x = parent[x];
    }
    return x;
}

void label_components(const std::vector<std::array<int32_t, 4>>& neighbors, TetConnectivity& out) {
    const auto n = static_cast<int32_t>(neighbors.size());
    std::vector<int32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    for (int32_t t = 0; t < n; ++t)
        for (int32_t o : neighbors[t])
            if (o > t) {
                const int32_t a = find_root(parent, t), b = find_root(parent, o);
                if (a != b) parent[std::max(a, b)] = std::min(a, b);  // the root stays the lowest tet
            }
    out.tet_component.assign(n, -1);
    std::vector<int32_t> label_of_root(n, -1);
    out.component_count = 0;
    for (int32_t t = 0; t < n; ++t) {
        const int32_t root = find_root(parent, t);
        if (label_of_root[root] < 0) label_of_root[root] = out.component_count++;
        out.tet_component[t] = label_of_root[root];
    }
}

}  // namespace

TetConnectivity build_connectivity(const TetMesh& mesh) {
    const auto n_vertices = static_cast<int64_t>(mesh.vertex_count());
    for (size_t t = 0; t < mesh.tets.size(); ++t)
        for (int32_t v : mesh.tets[t])
            if (v < 0 || v >= n_vertices)
                throw InvalidMeshError("tet " + std::to_string(t) + " references vertex " + std::to_string(v) +
                                       " out of range");
    TetConnectivity c;
    c.vertex_tets = build_vertex_tets(mesh);
    c.tet_neighbors = build_tet_neighbors(mesh, c.vertex_tets);
    c.vertex_vertices = build_vertex_vertices(mesh, c.vertex_tets);
    c.edges = build_edges(c.vertex_vertices);
    c.boundary_faces = build_boundary_faces(mesh, c.tet_neighbors);
    c.is_boundary_vertex.assign(mesh.vertex_count(), 0);
    for (const BoundaryFace& f : c.boundary_faces)
        for (int32_t v : f.vertices) c.is_boundary_vertex[v] = 1;
    for (size_t v = 0; v < c.is_boundary_vertex.size(); ++v)
        if (c.is_boundary_vertex[v]) c.boundary_vertices.push_back(static_cast<int32_t>(v));
    label_components(c.tet_neighbors, c);
    return c;
}

}  // namespace waxwork
