// Tips where sharp edges meet at a small angle: the one surface shape CGAL Mesh_3 cannot mesh in
// bounded time. Its protection of sharp edges (Mesh_3's 1D features) puts balls along each sharp edge
// that may not overlap the balls of another; where two sharp edges meet at an angle theta the balls
// near the tip must shrink like theta times the distance to it, and CGAL 5.5 has no floor under them.
// Measured with CGAL on a cube whose corner is pulled out to a needle (tip angles 0.97, 0.58, 0.38
// degrees): 6 s, 24 s, 72 s, and no mesh after 5 minutes at 0.06 degrees, while TetGen, which keeps the
// input triangles, meshes each in under a second.
#pragma once

#include "tetops/triangle_surface.h"

#include <cstdint>
#include <vector>

namespace waxwork {

// The feature angle CGAL's Polyhedral_mesh_domain_with_features_3::detect_features uses by default:
// an edge is sharp when its two faces' normals differ by more than this.
inline constexpr double kSharpEdgeAngleDeg = 60.0;

struct SharpTip {
    int32_t vertex = -1;
    double angle_deg = 180.0;  // the smallest angle between two sharp edges at `vertex`
    double shorter_edge = 0;   // the length of the shorter of those two edges
};

// For every vertex with two or more sharp edges, the pair meeting at the smallest angle. `surface`
// must be closed (each edge shared by exactly two triangles).
std::vector<SharpTip> sharp_tips(const TriangleSurface& surface, double sharp_edge_angle_deg = kSharpEdgeAngleDeg);

// How much work a tip makes for the protection of sharp edges when the surface is meshed at edge
// length `edge`: balls of radius about (distance to the tip) x (angle) cover the tip's edges until
// they reach `edge`, about log(1 + shorter_edge / edge) / angle of them (angle in radians). The same
// needles as above: 145, 294, 495, 746 for tips of 1.97, 0.97, 0.58, 0.38 degrees at the default size
// (3.8, 6, 24, 72 s); the skull's narrowest tip (0.45 degrees, between edges far shorter than its
// mesh size) scores under 50 and meshes in seconds.
double sharp_tip_work(const SharpTip& tip, double edge);

}  // namespace waxwork
