// The exitant radiance per volume vertex of a solved scene: what `render --fields` lists as lo and
// `waxwork export --radiance` bakes into vertex colours, from one computation so the two agree.
#pragma once

#include "solver/solved_scene.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <cstdint>
#include <vector>

namespace waxwork {

// lo = F_t(1, eta) E per volume vertex and channel: the exitant radiance seen along the vertex's
// (averaged) normal, from the q the solve used (at a crease, its sides' light weighed by their areas;
// the image shades each side with its own) and the eta of the scene's surface; 0 at interior vertices.
std::vector<std::array<double, 3>> vertex_exitant_radiance(const TetMesh& mesh, const TetConnectivity& connectivity,
                                                           const SolvedScene& scene);

// vertex_exitant_radiance as 8-bit sRGB (render/srgb.h: clamped to [0, 1], encoded as the renderer
// encodes, rounded); no exposure or tone mapping: a radiance of 1 is white.
std::vector<std::array<uint8_t, 3>> vertex_radiance_colours(const TetMesh& mesh, const TetConnectivity& connectivity,
                                                            const SolvedScene& scene);

}  // namespace waxwork
