// Meshes and analytic solutions shared by the solver tests.
#pragma once

#include "solver/material.h"
#include "tetops/connectivity.h"
#include "tetops/icosphere.h"
#include "tetops/quality.h"
#include "tetops/test_meshes.h"
#include "tetops/tet_mesh.h"
#include "tetops/tetrahedralize.h"
#include "tetops/triangle_surface.h"

#include <cmath>
#include <vector>

namespace waxwork::test {

// n x n x n cubes of side h, each split into the six Kuhn tets (a conforming, all-good mesh:
// dihedral angles 45-90 degrees).
inline TetMesh make_cube_mesh(int n, double h = 1.0) {
    return testing::make_box_mesh(n, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(n * h));
}

inline TetMesh make_ball_mesh(int surface_level, size_t target_tets, double r = 10.0) {
    MeshingOptions options;
    options.sizing.target_tets = target_tets;
    return tetrahedralize(make_icosphere(surface_level, r), options).mesh;
}

}  // namespace waxwork::test
