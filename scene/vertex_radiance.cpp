#include "scene/vertex_radiance.h"

#include "render/srgb.h"
#include "solver/radiance.h"

namespace waxwork {

std::vector<std::array<double, 3>> vertex_exitant_radiance(const TetMesh& mesh, const TetConnectivity& connectivity,
                                                           const SolvedScene& scene) {
    // eta per volume vertex, from the surface (the value q and E were computed with).
    std::vector<double> eta(mesh.vertex_count(), 1.0);
    for (size_t s = 0; s < scene.surface.vertices.size(); ++s) eta[scene.surface.vertices[s]] = scene.surface.eta[s];
    std::vector<std::array<double, 3>> lo(mesh.vertex_count(), {0, 0, 0});
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        if (connectivity.is_boundary_vertex[v] == 0) continue;
        for (int c = 0; c < 3; ++c) lo[v][c] = exitant_radiance(scene.diffusion.phi[v][c], scene.q[v][c], eta[v], 1.0);
    }
    return lo;
}

std::vector<std::array<uint8_t, 3>> vertex_radiance_colours(const TetMesh& mesh, const TetConnectivity& connectivity,
                                                            const SolvedScene& scene) {
    const std::vector<std::array<double, 3>> lo = vertex_exitant_radiance(mesh, connectivity, scene);
    std::vector<std::array<uint8_t, 3>> colours(lo.size());
    for (size_t v = 0; v < lo.size(); ++v) colours[v] = srgb_bytes(lo[v]);
    return colours;
}

}  // namespace waxwork
