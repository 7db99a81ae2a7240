#include "scene/surface_export.h"

#include "scene/vertex_radiance.h"

namespace waxwork {

SurfaceExport surface_export(const TetMesh& mesh, const TetConnectivity& connectivity, ShellGrouping grouping,
                             const SolvedScene* scene) {
    SurfaceExport result;
    result.shells = boundary_shells(mesh, connectivity, grouping);
    if (scene) {
        const std::vector<std::array<uint8_t, 3>> colours = vertex_radiance_colours(mesh, connectivity, *scene);
        result.colours.reserve(result.shells.volume_vertices.size());
        for (int32_t v : result.shells.volume_vertices) result.colours.push_back(colours[v]);
    }
    return result;
}

}  // namespace waxwork
