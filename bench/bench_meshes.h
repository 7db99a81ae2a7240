// Volumes shared by the benchmarks: the embedded spot model meshed to a given size, and that volume
// lit and assembled for the solver benchmarks, each cached per run.
#pragma once

#include "io/surface_reader.h"
#include "solver/diffusion_matrix.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "tetops/connectivity.h"
#include "tetops/tetrahedralize.h"

#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

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

// spot_volume(target_tets) in marble, 100 mm along its longest side, assembled, and lit by one white
// directional light travelling along -z without shadows: q = n.z F_t(n.z) on the boundary (a solve's
// cost does not depend on the light, only its right-hand side does).
struct LitSpot {
    const TetMesh& mesh;
    TetConnectivity conn;
    std::vector<TetMaterial> materials;
    double mm_per_unit = 1;
    DiffusionMatrix matrix;
    std::vector<std::array<double, 3>> q;
};

// The benches' marble, assembly and light from +z on `mesh` (spot or an edited copy of it, which must
// outlive the result); mm_per_unit: 100 mm over the longest side of the unedited model.
inline std::unique_ptr<LitSpot> light_spot_volume(const TetMesh& mesh, double mm_per_unit) {
    auto s = std::make_unique<LitSpot>(LitSpot{mesh, build_connectivity(mesh), {}, mm_per_unit, {}, {}});
    s->materials.assign(mesh.tet_count(), material_preset("marble"));
    AssemblyOptions assembly;
    assembly.mm_per_unit = mm_per_unit;
    s->matrix = assemble_diffusion_matrix(mesh, s->conn, s->materials, assembly);
    Lighting lighting;
    lighting.lights.push_back(Light{LightType::Directional, Eigen::Vector3d(0, 0, -1), {1, 1, 1}});
    lighting.shadows = false;
    s->q = incident_light(mesh, s->conn, s->materials, lighting);
    return s;
}

inline const LitSpot& lit_spot(size_t target_tets) {
    static std::map<size_t, std::unique_ptr<LitSpot>> cache;
    std::unique_ptr<LitSpot>& slot = cache[target_tets];
    if (!slot) {
        const TetMesh& mesh = spot_volume(target_tets);
        const auto box = bounding_box(mesh);
        slot = light_spot_volume(mesh, 100.0 / (box[1] - box[0]).maxCoeff());
    }
    return *slot;
}

}  // namespace waxwork::bench
