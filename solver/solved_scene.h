// From a volume, its materials and its lights to the light it shows: lighting (q at the boundary,
// with shadows; solver/lighting.h), diffusion (phi at every vertex; solver/diffusion_solve.h),
// shading (the boundary split at its creases; solver/shading_surface.h) and radiance (E per shading
// vertex, L_o = F_t(theta_o) E; solver/radiance.h). `waxwork render`, sessions, the live scene's
// first frame and the studies all solve a scene through solve_scene.
#pragma once

#include "solver/diffusion_solve.h"
#include "solver/lighting.h"
#include "solver/methods/alternative_method.h"
#include "solver/shading_surface.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <optional>
#include <vector>

namespace waxwork {

// Everything the solve produced for one scene.
struct SolvedScene {
    BoundarySurface surface;                           // world space, with per-vertex eta
    // The surface split at its creases (solver/shading_surface.h): what the image shades, with q and
    // the shadow rays' visibility per shading vertex (the renderer shadows each light's highlight by it).
    ShadingSurface shading;
    ShadingLight shading_light;
    std::vector<Rgb> q;                                // the solve's light per volume vertex (0 inside): source_light
    DiffusionSolution diffusion;                       // phi per volume vertex and solver statistics
    std::vector<std::array<float, 3>> radiance_factor; // E per shading vertex (shading_radiance_factors)
    double lighting_ms = 0;                            // surface extraction, shadow BVH, q and the shading's light
    // When an alternative method solved (solve_scene's `alternative`): its statistics and warnings; its
    // phi is diffusion.phi, its setup and solve times diffusion.assembly_ms and solve_ms.
    std::optional<MethodSolution> alternative;
};

// Runs lighting, diffusion and radiance. With `alternative`, phi comes from that method
// (solver/methods/alternative_method.h) instead of solve_diffusion, from the same q and materials;
// the light a crease corner receives apart from its vertex (corner_light) reaches only TransCut's
// solve, since the alternatives read one q per vertex. Throws AlgorithmError when phi or E is not
// finite (never a NaN image), InvalidArgumentError for bad materials, lights, options or crease angle,
// and what the alternative method throws.
SolvedScene solve_scene(const TetMesh& mesh, const TetConnectivity& connectivity,
                        const std::vector<TetMaterial>& materials, const Lighting& lighting,
                        const DiffusionOptions& options, double crease_angle_degrees = kDefaultCreaseAngleDegrees,
                        const AlternativeMethodSettings* alternative = nullptr);

// solve_scene in its two halves, for a solve that happens elsewhere (the distributed render): the
// lighting (surface, shading, q and lighting_ms; diffusion and radiance_factor left empty) with the
// crease corners' light for the right-hand side, and then, once scene.diffusion.phi is set, the
// radiance. They throw as solve_scene does.
struct LitScene {
    SolvedScene scene;
    std::vector<CornerLight> corners;
};
LitScene light_scene(const TetMesh& mesh, const TetConnectivity& connectivity,
                     const std::vector<TetMaterial>& materials, const Lighting& lighting,
                     double crease_angle_degrees = kDefaultCreaseAngleDegrees);
void shade_scene(SolvedScene& scene);

}  // namespace waxwork
