// A closed triangle surface as plain arrays: the mesher's input and the output of surface validation.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace waxwork {

struct TriangleSurface {
    std::vector<Eigen::Vector3d> points;
    std::vector<std::array<int32_t, 3>> triangles;  // counter-clockwise seen from outside
};

}  // namespace waxwork
