// Checks shared by the exact-cut and fracture tests: conformity, closed boundaries, world-space
// boundary area and per-piece structure.
#pragma once

#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/quality.h"
#include "tetops/tet_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

namespace waxwork::testing {

// Tets of `mesh` whose minimum dihedral angle is under min(guard, that of their parent in `before`),
// parent_of(t) giving the parent's index: the guarantee of exact cuts and fractures, recounted here
// independently of tetops/split_quality.h (an untouched tet equals its parent and never counts).
template <class ParentOf>
size_t tets_under_parent_guard(const TetMesh& mesh, const TetMesh& before, ParentOf parent_of, double guard = 0.5) {
    const std::vector<double> after_deg = min_dihedral_angles_deg(mesh), before_deg = min_dihedral_angles_deg(before);
    size_t count = 0;
    for (size_t t = 0; t < mesh.tet_count(); ++t)
        if (after_deg[t] < std::min(guard, before_deg[parent_of(t)])) ++count;
    return count;
}

// On a face of the unit cube [0, 1]^3 (to rounding).
inline bool on_unit_cube_boundary(const Eigen::Vector3d& p) {
    for (int i = 0; i < 3; ++i)
        if (std::abs(p[i]) < 1e-12 || std::abs(p[i] - 1) < 1e-12) return true;
    return false;
}

// Valid, every tet positively oriented (validate), no face shared by more than two tets
// (build_connectivity throws otherwise) and the boundary closed: every edge of a boundary face is
// shared by exactly two boundary faces (by an even number when `manifold` is false: pieces made of
// whole tets may touch themselves along an edge). Returns the connectivity for further checks.
inline TetConnectivity expect_valid_conforming(const TetMesh& mesh, bool manifold = true) {
    EXPECT_NO_THROW(validate(mesh));
    TetConnectivity c = build_connectivity(mesh);
    std::map<std::pair<int32_t, int32_t>, int> edge_use;
    for (const BoundaryFace& f : c.boundary_faces)
        for (int k = 0; k < 3; ++k) {
            const int32_t a = f.vertices[k], b = f.vertices[(k + 1) % 3];
            ++edge_use[{std::min(a, b), std::max(a, b)}];
        }
    size_t open_edges = 0;
    for (const auto& [edge, uses] : edge_use) open_edges += manifold ? uses != 2 : uses % 2 != 0;
    EXPECT_EQ(open_edges, 0u) << "boundary edges not shared by exactly two boundary faces";
    return c;
}

// Area of the boundary in world space.
inline double boundary_area(const TetMesh& mesh, const TetConnectivity& c) {
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    double area = 0;
    for (const BoundaryFace& f : c.boundary_faces)
        area += 0.5 * (world[f.vertices[1]] - world[f.vertices[0]]).cross(world[f.vertices[2]] - world[f.vertices[0]]).norm();
    return area;
}

// Volume per original id, to check that split tets' children add up to their parent.
inline std::map<int32_t, double> volume_by_original_id(const TetMesh& mesh) {
    std::map<int32_t, double> volume;
    for (size_t t = 0; t < mesh.tet_count(); ++t) volume[mesh.original_ids[t]] += signed_volume(mesh, t);
    return volume;
}

// Every tet's vertices belong to its piece only, and every piece is one face-connected component.
inline void expect_pieces_separate_and_connected(const TetMesh& mesh, const TetConnectivity& c) {
    std::vector<int32_t> vertex_piece(mesh.vertex_count(), -1);
    size_t shared = 0;
    for (size_t t = 0; t < mesh.tet_count(); ++t)
        for (int32_t v : mesh.tets[t]) {
            if (vertex_piece[v] >= 0 && vertex_piece[v] != mesh.piece_ids[t]) ++shared;
            vertex_piece[v] = mesh.piece_ids[t];
        }
    EXPECT_EQ(shared, 0u) << "vertices shared between pieces";
    std::map<int32_t, std::set<int32_t>> components_of_piece;
    for (size_t t = 0; t < mesh.tet_count(); ++t) components_of_piece[mesh.piece_ids[t]].insert(c.tet_component[t]);
    for (const auto& [piece, components] : components_of_piece)
        EXPECT_EQ(components.size(), 1u) << "piece " << piece << " has " << components.size() << " components";
}

}  // namespace waxwork::testing
