#include "solver/solved_scene.h"

#include "base/error.h"
#include "base/timing.h"
#include "solver/radiance.h"

#include <chrono>
#include <cmath>
#include <string>
#include <utility>

namespace waxwork {

LitScene light_scene(const TetMesh& mesh, const TetConnectivity& connectivity,
                     const std::vector<TetMaterial>& materials, const Lighting& lighting,
                     double crease_angle_degrees) {
    LitScene lit;
    SolvedScene& scene = lit.scene;
    const auto lighting_start = std::chrono::steady_clock::now();
    // The surface and its shadow BVH are built once and shared by the lighting of the solve, the
    // shading's copies and the renderer.
    scene.surface = extract_boundary_surface(mesh, connectivity, materials);
    const TriangleBvh bvh = lighting.shadows ? build_shadow_bvh(scene.surface) : TriangleBvh();
    std::vector<float> visibility;
    const std::vector<Rgb> surface_q = incident_light(scene.surface, bvh, lighting, &visibility);
    scene.shading = split_at_creases(scene.surface, crease_angle_degrees);
    scene.shading_light = shading_light(scene.surface, scene.shading, bvh, lighting, surface_q, visibility);
    const std::vector<Rgb> surface_source_q = source_light(scene.surface, scene.shading, scene.shading_light.q);
    lit.corners = corner_light(scene.surface, scene.shading, scene.shading_light.q, surface_source_q);
    scene.q = to_volume_vertices(scene.surface, surface_source_q, mesh.vertex_count());
    scene.lighting_ms = milliseconds_since(lighting_start);
    return lit;
}

void shade_scene(SolvedScene& scene) {
    for (size_t v = 0; v < scene.diffusion.phi.size(); ++v) {
        for (int c = 0; c < 3; ++c) {
            if (!std::isfinite(scene.diffusion.phi[v][c]))
                throw AlgorithmError("the diffusion solve gave a non-finite fluence at vertex " + std::to_string(v));
        }
    }
    scene.radiance_factor =
        shading_radiance_factors(scene.surface, scene.shading, scene.diffusion.phi, scene.shading_light.q);
    for (size_t d = 0; d < scene.radiance_factor.size(); ++d) {
        for (int c = 0; c < 3; ++c) {
            if (!std::isfinite(scene.radiance_factor[d][c]))
                throw AlgorithmError("non-finite exitant radiance at vertex " +
                                     std::to_string(scene.surface.vertices[scene.shading.surface_vertex[d]]) +
                                     " (float overflow: are the light intensities absurd?)");
        }
    }
}

SolvedScene solve_scene(const TetMesh& mesh, const TetConnectivity& connectivity,
                        const std::vector<TetMaterial>& materials, const Lighting& lighting,
                        const DiffusionOptions& options, double crease_angle_degrees,
                        const AlternativeMethodSettings* alternative) {
    LitScene lit = light_scene(mesh, connectivity, materials, lighting, crease_angle_degrees);
    SolvedScene scene = std::move(lit.scene);
    if (alternative) {
        const MethodProblem problem{mesh, connectivity, materials, scene.q, options.mm_per_unit};
        scene.alternative = solve_alternative(problem, *alternative);
        scene.diffusion.phi = std::move(scene.alternative->phi);
        scene.alternative->phi.clear();
        scene.diffusion.iterations = scene.alternative->iterations;
        scene.diffusion.assembly_ms = scene.alternative->setup_ms;
        scene.diffusion.solve_ms = scene.alternative->solve_ms;
    } else {
        scene.diffusion = solve_diffusion(mesh, connectivity, materials, scene.q, options, lit.corners);
    }
    shade_scene(scene);
    return scene;
}

}  // namespace waxwork
