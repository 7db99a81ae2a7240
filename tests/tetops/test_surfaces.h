// Small hand-made triangle surfaces for tests.
#pragma once

#include "tetops/triangle_surface.h"

namespace waxwork::testing {

// The cube [0,1]^3 + offset, 8 points and 12 outward triangles.
inline TriangleSurface make_cube_surface(const Eigen::Vector3d& offset = Eigen::Vector3d::Zero()) {
    TriangleSurface s;
    for (int k = 0; k < 8; ++k) s.points.push_back(offset + Eigen::Vector3d(k & 1, (k >> 1) & 1, (k >> 2) & 1));
    s.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    return s;
}

// Appends b to a with shifted indices.
inline TriangleSurface combine(TriangleSurface a, const TriangleSurface& b) {
    const auto shift = static_cast<int32_t>(a.points.size());
    a.points.insert(a.points.end(), b.points.begin(), b.points.end());
    for (auto t : b.triangles) a.triangles.push_back({t[0] + shift, t[1] + shift, t[2] + shift});
    return a;
}

}  // namespace waxwork::testing
