// The solved fields of a volume as a table, for analysis outside Waxwork (`render --fields`, sessions).
#pragma once

#include "solver/solved_scene.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <filesystem>

namespace waxwork {

// Writes the per-vertex fields, atomically: header
//   x,y,z,boundary,q_r,q_g,q_b,phi_r,phi_g,phi_b,lo_r,lo_g,lo_b
// one row per volume vertex in the volume's order; x,y,z in world space; lo = F_t(1, eta) E, the
// exitant radiance seen along the normal (0 with q at interior vertices). With `phi_error` (one per
// vertex: the standard error of a Monte Carlo phi, solver/reference/monte_carlo.h) the header gains
// phi_err_r,phi_err_g,phi_err_b at the end.
void write_fields_csv(const std::filesystem::path& path, const TetMesh& mesh, const TetConnectivity& connectivity,
                      const SolvedScene& scene, const std::vector<std::array<double, 3>>* phi_error = nullptr);

}  // namespace waxwork
