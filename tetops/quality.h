// Element quality: dihedral angles and radius-edge ratios, per tet and summarised.
#pragma once

#include "tetops/tet_mesh.h"

#include <array>
#include <vector>

namespace waxwork {

// The six dihedral angles of a tet, in degrees, in the order of kTetEdges (angle at that edge).
std::array<double, 6> dihedral_angles_deg(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                          const Eigen::Vector3d& p2, const Eigen::Vector3d& p3);
double min_dihedral_angle_deg(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                              const Eigen::Vector3d& p2, const Eigen::Vector3d& p3);
// The same for a tet of `mesh` (its vertex indices need not be one of mesh.tets: a candidate tet).
double min_dihedral_angle_deg(const TetMesh& mesh, const Tet& tet);
// The cosine of the smallest dihedral angle (the largest over the six edges; 1 for a degenerate
// face): the smallest angle is 180 degrees minus acos(-cosine), and comparing cosines compares angles
// without the arc cosine.
double max_dihedral_cosine(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                           const Eigen::Vector3d& p3);

// Circumradius divided by the shortest edge (sqrt(6)/4 ~ 0.612 for the regular tet; infinite for
// degenerate tets).
double radius_edge_ratio(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                         const Eigen::Vector3d& p3);

struct QualityReport {
    double min_dihedral_deg = 0;
    double max_dihedral_deg = 0;
    double max_radius_edge_ratio = 0;
    double mean_radius_edge_ratio = 0;
    size_t tets_below_5_deg = 0;  // tets whose smallest dihedral angle is under 5 degrees
    double min_edge_length = 0;
    double max_edge_length = 0;
    double mean_edge_length = 0;
};

// Per-tet minimum dihedral angle in degrees (parallel).
std::vector<double> min_dihedral_angles_deg(const TetMesh& mesh);

// Smallest dihedral angle over all tets, in degrees (parallel; 0 for an empty mesh).
double mesh_min_dihedral_deg(const TetMesh& mesh);

// Summary over all tets (parallel). An empty mesh gives a zero report.
QualityReport measure_quality(const TetMesh& mesh);

}  // namespace waxwork
