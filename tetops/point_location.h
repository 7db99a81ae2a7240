// Which points lie inside a volume.
#pragma once

#include "tetops/tet_mesh.h"

#include <Eigen/Core>

namespace waxwork {

// True when `point` (world space) lies inside or on a tet of the volume (piece transforms applied).
bool point_inside_volume(const TetMesh& mesh, const Eigen::Vector3d& point);

}  // namespace waxwork
