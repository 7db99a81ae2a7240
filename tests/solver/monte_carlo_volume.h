// A uniform volume with what the Monte Carlo tracers take, shared by their tests.
#pragma once

#include "solver/lighting.h"
#include "solver/material.h"
#include "solver/reference/first_hit_grid.h"
#include "solver/reference/camera_rays.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <utility>
#include <vector>

namespace waxwork::test {

inline TetMaterial uniform_material(double mua, double musp, double eta) {
    return TetMaterial{{mua, mua, mua}, {musp, musp, musp}, eta};
}

struct MonteCarloVolume {
    TetMesh mesh;
    TetConnectivity connectivity;
    std::vector<TetMaterial> materials;
    BoundarySurface surface;
    TriangleBvh bvh;    // shadow rays
    FirstHitGrid grid;  // camera rays
    MonteCarloVolume(TetMesh m, const TetMaterial& material) : mesh(std::move(m)) {
        connectivity = build_connectivity(mesh);
        materials.assign(mesh.tet_count(), material);
        surface = extract_boundary_surface(mesh, connectivity, materials);
        bvh = build_shadow_bvh(surface);
        grid = surface_hit_grid(surface);
    }
};

}  // namespace waxwork::test
