// What `waxwork export` and the editor's File > Export write: the boundary of a volume as shells
// (tetops/boundary_shells.h) and, for a solved scene, its exitant radiance baked as vertex colours.
#pragma once

#include "solver/solved_scene.h"
#include "tetops/boundary_shells.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <cstdint>
#include <vector>

namespace waxwork {

struct SurfaceExport {
    BoundaryShells shells;
    // One sRGB colour per shell vertex, that of its volume vertex (vertex_radiance_colours: equal to
    // `render --fields` lo after sRGB encoding); empty without a scene.
    std::vector<std::array<uint8_t, 3>> colours;
};

// `scene`, when given, must have been solved on `mesh` and `connectivity`.
SurfaceExport surface_export(const TetMesh& mesh, const TetConnectivity& connectivity, ShellGrouping grouping,
                             const SolvedScene* scene = nullptr);

}  // namespace waxwork
