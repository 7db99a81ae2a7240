// Uniform ("red", 1:8) refinement of a tet mesh: every tet split into eight at its edge midpoints, so
// that repeated refinement gives a nested family whose mesh size halves exactly per level, what a
// convergence study needs to measure an order (bench/studies/accuracy_study.h).
//
// Hand-written: none of the libraries in our stack offers it. CGAL's Mesh_3 and TetGen remesh to a size
// (the new mesh is not nested in the old and its size is only roughly controlled), and 1:8 subdivision
// of tets is not in CGAL's subdivision methods (surfaces only) nor in libigl-style toolkits, which
// upsample triangle meshes.
#pragma once

#include "tetops/tet_mesh.h"

#include <functional>

namespace waxwork {

// Splits every tet into eight (Bey 1995, "Tetrahedral grid refinement", Computing 55): one new vertex
// per edge midpoint, shared by the tets around the edge; the four corner tets, each the parent scaled by
// 1/2 about one of its vertices; and the inner octahedron split into four tets around its shortest
// diagonal. The result has vertex_count() + edge count vertices (the original ones first, at the same
// indices, then one per edge in the order of TetConnectivity::edges) and 8 x tet_count() tets, children
// of tet t at 8t .. 8t+7, positively oriented.
//
// project_boundary, when given, moves each new vertex on the boundary (the midpoint of an edge of a face
// used by one tet) to the point it returns, e.g. onto the sphere a ball mesh approximates, so that the
// geometric error shrinks with the mesh. Per-tet data is inherited: each child gets its parent's
// material (when the mesh has materials), original id and piece id; piece transforms are unchanged.
// Projection keeps the shapes when every tet has at most one face on the boundary (then so do all its
// children); a tet with two faces on a curved boundary has descendants with four vertices near the
// surface, which flatten as the surface looks flatter at their size (smallest dihedral angle about
// halving per level).
// Throws AlgorithmError when a projection inverts or flattens a tet, InvalidMeshError when a face is
// shared by more than two tets (build_connectivity).
TetMesh refine_uniformly(const TetMesh& mesh,
                         const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& project_boundary = {});

}  // namespace waxwork
