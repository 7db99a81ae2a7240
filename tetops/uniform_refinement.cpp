#include "tetops/uniform_refinement.h"

#include "base/error.h"
#include "tetops/connectivity.h"

#include <algorithm>
#include <limits>
#include <string>

namespace waxwork {
namespace {

// The index of edge {a, b} in the sorted, unique edge list.
int32_t edge_index(const std::vector<std::array<int32_t, 2>>& edges, int32_t a, int32_t b) {
    const std::array<int32_t, 2> key = a < b ? std::array<int32_t, 2>{a, b} : std::array<int32_t, 2>{b, a};
    const auto it = std::lower_bound(edges.begin(), edges.end(), key);
    return static_cast<int32_t>(it - edges.begin());
}

}  // namespace

TetMesh refine_uniformly(const TetMesh& mesh,
                         const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& project_boundary) {
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<std::array<int32_t, 2>>& edges = connectivity.edges;
    const auto vertex_count = static_cast<int32_t>(mesh.vertex_count());

    TetMesh out;
    out.positions = mesh.positions;
    out.positions.reserve(mesh.vertex_count() + edges.size());
    for (const auto& [a, b] : edges) out.positions.push_back(0.5 * (mesh.positions[a] + mesh.positions[b]));

    // Children, oriented on the exact midpoints (each is a parent scaled by 1/2 or an eighth of its volume,
    // so the signs are never in doubt); projection comes after and is checked.
    out.tets.reserve(8 * mesh.tet_count());
    for (const Tet& tet : mesh.tets) {
        // m[i][j]: the vertex at the midpoint of local edge ij, or the corner i itself on the diagonal.
        std::array<std::array<int32_t, 4>, 4> m{};
        for (int i = 0; i < 4; ++i) m[i][i] = tet[i];
        for (const auto& [i, j] : kTetEdges)
            m[i][j] = m[j][i] = vertex_count + edge_index(edges, tet[i], tet[j]);

        // Corner k: the parent scaled by 1/2 about vertex k, orientation kept.
        for (int k = 0; k < 4; ++k) out.tets.push_back({m[k][0], m[k][1], m[k][2], m[k][3]});

        // The octahedron of the six midpoints has three diagonals, each joining the midpoints of two
        // opposite edges (01-23, 02-13, 03-12), and any one splits it into four tets. Splitting along the
        // shortest keeps the tets from degenerating over repeated refinement: the children's shapes stay
        // in finitely many similarity classes, so their angles are bounded below independently of the
        // level (Zhang 1995, "Successive subdivisions of tetrahedra and multigrid methods on tetrahedral
        // meshes", Houston J. Math. 21; Bey 1995 for a fixed ordered choice), whereas a careless choice
        // can flatten the inner tets further at every level.
        const std::array<std::array<int32_t, 2>, 3> diagonals = {
            {{m[0][1], m[2][3]}, {m[0][2], m[1][3]}, {m[0][3], m[1][2]}}};
        // The four midpoints around each diagonal, in cyclic order (consecutive ones share a parent face).
        const std::array<std::array<int32_t, 4>, 3> rings = {{{m[0][2], m[0][3], m[1][3], m[1][2]},
                                                              {m[0][1], m[0][3], m[2][3], m[1][2]},
                                                              {m[0][1], m[0][2], m[2][3], m[1][3]}}};
        int shortest = 0;
        double shortest_length = std::numeric_limits<double>::infinity();
        for (int d = 0; d < 3; ++d) {
            const double length = (out.positions[diagonals[d][0]] - out.positions[diagonals[d][1]]).squaredNorm();
            if (length < shortest_length) shortest = d, shortest_length = length;
        }
        const auto [a, b] = diagonals[shortest];
        for (int i = 0; i < 4; ++i) {
            Tet child{a, b, rings[shortest][i], rings[shortest][(i + 1) % 4]};
            if (signed_volume(out.positions[child[0]], out.positions[child[1]], out.positions[child[2]],
                              out.positions[child[3]]) < 0)
                std::swap(child[2], child[3]);
            out.tets.push_back(child);
        }
    }

    if (project_boundary) {
        std::vector<uint8_t> on_boundary(edges.size(), 0);
        for (const BoundaryFace& face : connectivity.boundary_faces)
            for (int i = 0; i < 3; ++i)
                on_boundary[edge_index(edges, face.vertices[i], face.vertices[(i + 1) % 3])] = 1;
        for (size_t e = 0; e < edges.size(); ++e)
            if (on_boundary[e]) out.positions[vertex_count + e] = project_boundary(out.positions[vertex_count + e]);
        for (size_t t = 0; t < out.tets.size(); ++t)
            if (!(signed_volume(out, t) > 0))
                throw AlgorithmError("uniform refinement: projecting the boundary midpoints inverts or flattens child " +
                                     std::to_string(t % 8) + " of tet " + std::to_string(t / 8) +
                                     " (signed volume " + number_text(signed_volume(out, t)) + ")");
    }

    auto inherit = [](const auto& parents, auto& children) {
        children.clear();
        children.reserve(8 * parents.size());
        for (const auto& value : parents) children.insert(children.end(), 8, value);
    };
    inherit(mesh.materials, out.materials);
    inherit(mesh.original_ids, out.original_ids);
    inherit(mesh.piece_ids, out.piece_ids);
    out.piece_transforms = mesh.piece_transforms;
    return out;
}

}  // namespace waxwork
