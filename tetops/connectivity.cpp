#include "tetops/connectivity.h"

#include "base/error.h"
#include "tetops/disjoint_sets.h"

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

// Face neighbours, each face matched exactly once at its smallest vertex: the faces of that vertex's
// star for which it is the minimum are keyed by their other two vertices and sorted, so equal
// neighbouring keys are the two sides of one interior face. The work per vertex is a sort of a few
// dozen keys read from contiguous star arrays, linear overall and free of the global face sort that a
// hashing approach needs; every (tet, face) slot is written by exactly one task, so no locks.
std::vector<std::array<int32_t, 4>> build_tet_neighbors(const TetMesh& mesh, const CompressedRows& vertex_tets) {
    std::vector<std::array<int32_t, 4>> neighbors(mesh.tets.size());
    std::atomic<int64_t> overfull_face{-1};
    struct FaceEntry {
        uint64_t key;  // the face's two larger vertices
        int32_t tet;
        int32_t face;
        bool operator<(const FaceEntry& o) const { return key < o.key; }
    };
    tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.vertex_count()), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<FaceEntry> entries;
        for (size_t v = r.begin(); v != r.end(); ++v) {
            entries.clear();
            for (int32_t t : vertex_tets.row(v)) {
                const Tet& tet = mesh.tets[t];
                for (int f = 0; f < 4; ++f) {
                    if (tet[f] == static_cast<int32_t>(v)) continue;  // face f is opposite vertex f
                    int32_t others[2], n = 0;
                    bool v_is_min = true;
                    for (int k : kTetFaces[f]) {
                        if (tet[k] == static_cast<int32_t>(v)) continue;
                        if (tet[k] < static_cast<int32_t>(v)) v_is_min = false;
                        others[n++] = tet[k];
                    }
                    if (!v_is_min) continue;
                    const auto lo = static_cast<uint32_t>(std::min(others[0], others[1]));
                    const auto hi = static_cast<uint32_t>(std::max(others[0], others[1]));
                    entries.push_back({(uint64_t{lo} << 32) | hi, t, f});
                }
            }
            std::sort(entries.begin(), entries.end());
            for (size_t i = 0; i < entries.size();) {
                size_t j = i + 1;
                while (j < entries.size() && entries[j].key == entries[i].key) ++j;
                if (j - i == 1) {
                    neighbors[entries[i].tet][entries[i].face] = -1;
                } else {
                    if (j - i > 2) overfull_face = entries[i].tet;
                    neighbors[entries[i].tet][entries[i].face] = entries[i + 1].tet;
                    neighbors[entries[i + 1].tet][entries[i + 1].face] = entries[i].tet;
                }
                i = j;
            }
        }
    });
    if (overfull_face >= 0)
        throw InvalidMeshError("a face of tet " + std::to_string(overfull_face.load()) +
                               " is shared by more than two tets");
    return neighbors;
}

// Edges and vertex one-rings. Each vertex collects its larger neighbours from its star (sorted and
// deduplicated in place in a scratch buffer sized 3x the star, an upper bound): these rows, in vertex
// order, are exactly the sorted unique edge list. The one-rings are then the edge list read in both
// directions; scattering the smaller neighbours in edge order keeps every row sorted. Sorting only the
// larger half of each neighbourhood halves the dominant cost.
void build_edges_and_one_rings(const TetMesh& mesh, TetConnectivity& c) {
    const size_t n = mesh.vertex_count();
    const CompressedRows& vertex_tets = c.vertex_tets;
    std::vector<int32_t> scratch(3 * vertex_tets.indices.size());
    std::vector<int32_t> upper_counts(n, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
            int32_t* begin = scratch.data() + 3 * static_cast<size_t>(vertex_tets.offsets[v]);
            int32_t* out = begin;
            for (int32_t t : vertex_tets.row(v))
                for (int32_t u : mesh.tets[t])
                    if (u > static_cast<int32_t>(v)) *out++ = u;
            std::sort(begin, out);
            upper_counts[v] = static_cast<int32_t>(std::unique(begin, out) - begin);
        }
    });
    const std::vector<int32_t> edge_offsets = offsets_from_counts(upper_counts);
    c.edges.resize(edge_offsets.back());
    tbb::parallel_for(size_t{0}, n, [&](size_t v) {
        const int32_t* upper = scratch.data() + 3 * static_cast<size_t>(vertex_tets.offsets[v]);
        for (int32_t k = 0; k < upper_counts[v]; ++k)
            c.edges[edge_offsets[v] + k] = {static_cast<int32_t>(v), upper[k]};
    });

    std::vector<int32_t> counts = upper_counts;
    for (const auto& e : c.edges) ++counts[e[1]];
    CompressedRows& rows = c.vertex_vertices;
    rows.offsets = offsets_from_counts(counts);
    rows.indices.resize(rows.offsets.back());
    std::vector<int32_t> cursor(rows.offsets.begin(), rows.offsets.end() - 1);
    for (const auto& e : c.edges) rows.indices[cursor[e[1]]++] = e[0];  // smaller neighbours, ascending
    tbb::parallel_for(size_t{0}, n, [&](size_t v) {
        std::copy_n(scratch.data() + 3 * static_cast<size_t>(vertex_tets.offsets[v]), upper_counts[v],
                    rows.indices.data() + cursor[v]);
    });
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

void label_components(const std::vector<std::array<int32_t, 4>>& neighbors, TetConnectivity& out) {
    const auto n = static_cast<int32_t>(neighbors.size());
    DisjointSets components(n);
    for (int32_t t = 0; t < n; ++t)
        for (int32_t o : neighbors[t])
            if (o > t) components.unite(t, o);
    out.tet_component.assign(n, -1);
    out.component_count = components.label_classes(out.tet_component);  // numbered by lowest tet
}

void check_vertex_indices(const TetMesh& mesh) {
    const auto n_vertices = static_cast<int64_t>(mesh.vertex_count());
    for (size_t t = 0; t < mesh.tets.size(); ++t)
        for (int32_t v : mesh.tets[t])
            if (v < 0 || v >= n_vertices)
                throw InvalidMeshError("tet " + std::to_string(t) + " references vertex " + std::to_string(v) +
                                       " out of range");
}

}  // namespace

// Counting sort; each row comes out sorted because the elements are visited in order.
template <size_t N>
CompressedRows vertex_elements(const std::vector<std::array<int32_t, N>>& elements, size_t vertex_count) {
    std::vector<int32_t> counts(vertex_count, 0);
    for (const auto& element : elements)
        for (int32_t v : element) ++counts[v];
    CompressedRows rows;
    rows.offsets = offsets_from_counts(counts);
    rows.indices.resize(rows.offsets.back());
    std::vector<int32_t> cursor(rows.offsets.begin(), rows.offsets.end() - 1);
    for (size_t e = 0; e < elements.size(); ++e)
        for (int32_t v : elements[e]) rows.indices[cursor[v]++] = static_cast<int32_t>(e);
    return rows;
}
template CompressedRows vertex_elements(const std::vector<std::array<int32_t, 3>>&, size_t);
template CompressedRows vertex_elements(const std::vector<std::array<int32_t, 4>>&, size_t);

std::vector<std::array<int32_t, 4>> build_face_neighbors(const TetMesh& mesh) {
    check_vertex_indices(mesh);
    return build_tet_neighbors(mesh, vertex_elements(mesh.tets, mesh.vertex_count()));
}

TetConnectivity build_connectivity(const TetMesh& mesh) {
    check_vertex_indices(mesh);
    TetConnectivity c;
    c.vertex_tets = vertex_elements(mesh.tets, mesh.vertex_count());
    c.tet_neighbors = build_tet_neighbors(mesh, c.vertex_tets);
    build_edges_and_one_rings(mesh, c);
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
