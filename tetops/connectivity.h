// Derived connectivity of a TetMesh: everything the solver, the editor and the renderer ask about
// neighbourhoods. Rebuilt in parallel (TBB) after every topological edit; a 500K-tet mesh rebuilds in
// well under 150 ms on two cores (bench/connectivity_bench.cpp).
#pragma once

#include "tetops/tet_mesh.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

// Compressed rows: the entries of row i are indices[offsets[i] .. offsets[i+1]).
struct CompressedRows {
    std::vector<int32_t> offsets{0};
    std::vector<int32_t> indices;

    size_t row_count() const { return offsets.size() - 1; }
    std::span<const int32_t> row(size_t i) const {
        return {indices.data() + offsets[i], indices.data() + offsets[i + 1]};
    }
};

// The elements (triangles, N = 3; tets, N = 4) around each vertex: row v lists, ascending, the
// elements that name v. Indices must lie in [0, vertex_count).
template <size_t N>
CompressedRows vertex_elements(const std::vector<std::array<int32_t, N>>& elements, size_t vertex_count);

// A triangle on the boundary of the volume, oriented counter-clockwise seen from outside.
struct BoundaryFace {
    std::array<int32_t, 3> vertices;
    int32_t tet;         // the tet it belongs to
    int32_t local_face;  // 0..3: the face of that tet opposite to its vertex local_face
};

// Faces of a tet: face k is opposite vertex k, listed so that its normal points out of the tet.
inline constexpr std::array<std::array<int, 3>, 4> kTetFaces = {{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};
// The six edges of a tet as pairs of local vertex indices.
inline constexpr std::array<std::array<int, 2>, 6> kTetEdges = {{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
// The index in kTetEdges of the edge between local vertices a and b, in either order (a != b, both in
// [0, 4)): lo + hi - 1 in the order above, plus one past the three edges of vertex 0.
constexpr int tet_edge_index(int a, int b) {
    const int lo = a < b ? a : b, hi = a < b ? b : a;
    return lo + hi - 1 + (lo > 0 ? 1 : 0);
}
static_assert([] {
    for (int e = 0; e < 6; ++e)
        if (tet_edge_index(kTetEdges[e][0], kTetEdges[e][1]) != e || tet_edge_index(kTetEdges[e][1], kTetEdges[e][0]) != e)
            return false;
    return true;
}());

struct TetConnectivity {
    // Unique undirected edges (a < b), sorted lexicographically.
    std::vector<std::array<int32_t, 2>> edges;
    // Per vertex: the adjacent vertices (sorted ascending).
    CompressedRows vertex_vertices;
    // Per vertex: the tets that contain it (sorted ascending).
    CompressedRows vertex_tets;
    // Per tet and local face: the tet across that face, or -1 on the boundary.
    std::vector<std::array<int32_t, 4>> tet_neighbors;
    // Boundary faces, outward oriented, ordered by (tet, local_face).
    std::vector<BoundaryFace> boundary_faces;
    // Vertices on the boundary, sorted ascending.
    std::vector<int32_t> boundary_vertices;
    // Per vertex: true when it lies on the boundary.
    std::vector<uint8_t> is_boundary_vertex;
    // Per tet: the index of its face-connected component; components are numbered by their lowest tet.
    std::vector<int32_t> tet_component;
    int32_t component_count = 0;
};

// Where one build_connectivity call spent its time, in milliseconds of wall clock, by phase (the
// benchmarks' roofline in docs/performance.md reads them).
struct ConnectivityBuildTimes {
    double vertex_tets = 0;     // the index check and the counting sort of the tets by vertex
    double tet_neighbors = 0;   // faces matched around their smallest vertex
    double one_rings = 0;       // one-rings and the edge list
    double boundary = 0;        // boundary faces and vertices
    double components = 0;      // face-connected components
};

// Builds all derived data. Throws InvalidMeshError when a face is shared by more than two tets or a
// tet names a vertex out of range. `times`, when given, receives the phases' times.
TetConnectivity build_connectivity(const TetMesh& mesh, ConnectivityBuildTimes* times = nullptr);

// Only TetConnectivity::tet_neighbors (what fracture needs), at a fraction of the full build's cost.
std::vector<std::array<int32_t, 4>> build_face_neighbors(const TetMesh& mesh);

}  // namespace waxwork
