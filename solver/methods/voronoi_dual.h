// The circumcentric (Voronoi) dual of a tetrahedral volume: the geometry finite volumes on Voronoi cells
// need (Kang & Kim 2013, Sec. 4.1: cell volumes V_i, neighbour-face areas S_ij, surface-face areas S_is).
//
// Each vertex owns the cell of points nearer to it than to its neighbours, clipped to the volume. On a
// Delaunay tet mesh that cell is the union, over the vertex's tets, of the circumcentric pieces below,
// so the dual is computed tet by tet from circumcentres rather than by a separate Voronoi diagram:
// a Voronoi diagram of the vertices (CGAL's Delaunay_triangulation_3) knows nothing of the volume's
// boundary (it would need clipping, Yan et al. 2010, the paper's [21]), its Delaunay edges differ from
// the mesh's wherever the mesh is not Delaunay, and the finite-volume matrix must live on the mesh's
// edges to be compared with TransCut's. What CGAL decides exactly, whether the mesh is Delaunay, is
// tetops/delaunay_check.h.
//
// Per tet t and edge e = (a, b) with other vertices k, l, the dual piece of e in t is the quadrilateral
// (m_e, c_abk, c_t, c_abl) in the bisector plane of e: m_e the edge midpoint, c_abk and c_abl the
// circumcentres of the two faces at e, c_t the circumcentre of t. Its two right triangles get signed
// areas (Hirani 2003, "signed elementary duals"): a triangle counts negative when c_t lies beyond the
// face from the tet's fourth vertex, or the face circumcentre lies beyond e from the face's third vertex.
// Summed over the tets around an interior edge these signed pieces are exactly the area of the Voronoi
// face of e when the mesh is Delaunay; otherwise the sum can be negative. Unlike in 2D, (signed area) /
// |e| is not TransCut's cotangent weight (1/6) |kl| cot(theta_kl) (Eq. 10 of Li et al.), even on
// well-centred tets; both satisfy sum_e w_e |e|^2 = 3 V per tet (tests/solver/fvm_method_test.cpp).
//
// The cell volume piece of vertex a in t is the signed sum over a's three edges of the pyramids with apex
// a over the edge's dual piece (height |e| / 2); the four pieces of a tet add up to its volume.
// On the boundary a vertex's share of a boundary triangle is the mixed Voronoi area of Meyer et al.
// (2003): the circumcentric (Voronoi) region of the vertex in a non-obtuse triangle, and half or a
// quarter of the area in an obtuse one, where the circumcentre leaves the triangle and the circumcentric
// shares would go negative. The boundary term of the paper (Eq. 15) needs a positive surface-face area.
#pragma once

#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <vector>

namespace waxwork {

struct VoronoiDual {
    // Per tet, per edge in kTetEdges order: signed dual-piece area over edge length, in mm.
    std::vector<std::array<double, 6>> edge_coefficient;
    // Per tet, per local vertex: signed circumcentric cell-volume piece, in mm^3.
    std::vector<std::array<double, 4>> cell_volume;
    // Per boundary face (TetConnectivity::boundary_faces order), per corner: mixed Voronoi area, mm^2.
    std::vector<std::array<double, 3>> boundary_area;
};

// Dual pieces of every tet and boundary face (in parallel), lengths converted to mm. Throws
// InvalidArgumentError for a tet of non-positive volume (no circumcentre) or mismatched sizes.
VoronoiDual build_voronoi_dual(const TetMesh& mesh, const TetConnectivity& connectivity, double mm_per_unit);

// One tet's dual pieces (positions in mm, positively oriented): edge coefficients and volume pieces.
struct TetDual {
    std::array<double, 6> edge_coefficient;
    std::array<double, 4> cell_volume;
};
TetDual tet_voronoi_dual(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                         const Eigen::Vector3d& p3);

// Circumcentre of a triangle and of a tet (mm in, mm out).
Eigen::Vector3d triangle_circumcentre(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);
Eigen::Vector3d tet_circumcentre(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                                 const Eigen::Vector3d& p3);

}  // namespace waxwork
