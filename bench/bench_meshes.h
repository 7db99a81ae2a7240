// Volumes shared by the benchmarks: the embedded spot model meshed to a given size, cached per run.
#pragma once

#include "io/surface_reader.h"
#include "tetops/tetrahedralize.h"

#include <map>
#include <string>

namespace waxwork::bench {

inline const TetMesh& spot_volume(size_t target_tets) {
    static std::map<size_t, TetMesh> cache;
    auto it = cache.find(target_tets);
    if (it == cache.end()) {
        const LoadedSurface surface = load_closed_surface(std::string(WAXWORK_ASSET_DIR) + "/meshes/spot.obj");
        MeshingOptions options;
        options.sizing.target_tets = target_tets;
        it = cache.emplace(target_tets, tetrahedralize(surface.surface, options).mesh).first;
    }
    return it->second;
}

}  // namespace waxwork::bench
