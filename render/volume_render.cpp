#include "render/volume_render.h"

#include "base/error.h"
#include "base/timing.h"
#include "gl/gl_context.h"
#include "render/surface_renderer.h"
#include "solver/material.h"
#include "tetops/point_location.h"

#include <chrono>

namespace waxwork {

VolumeRender render_volume(const TetMesh& mesh, const std::string& volume_name, const VolumeRenderSettings& settings) {
    if (mesh.tet_count() == 0) throw InvalidArgumentError(volume_name + ": the volume has no tets to render");
    VolumeRender result;
    result.connectivity = build_connectivity(mesh);
    // A stored material no solve can use is the file's problem.
    result.materials = naming_context(volume_name, [&] { return resolve_materials(mesh, settings.material); });

    // One OpenGL context for the GPU solve and the renderer (the same device).
    HeadlessGlContext context;
    DiffusionOptions diffusion = settings.diffusion;
    if (diffusion.backend == SolverBackend::Gpu) diffusion.gl = &context.gl();
    result.scene = solve_scene(mesh, result.connectivity, result.materials, settings.lighting, diffusion,
                               settings.crease_angle_degrees);

    const auto render_start = std::chrono::steady_clock::now();
    SurfaceRenderInput input = make_render_input(mesh, result.scene, settings.lighting, settings.image);
    result.view = build_view_geometry(mesh, result.connectivity, result.materials, result.scene, settings.view);
    apply_view(result.view, input);
    SurfaceRenderer renderer(context.gl());
    result.image = render_scene(renderer, input);
    result.exposure = input.exposure;
    result.render_ms = milliseconds_since(render_start);

    for (const Light& light : settings.lighting.lights)
        result.lights_inside += light.type == LightType::Point && point_inside_volume(mesh, light.vector);
    return result;
}

}  // namespace waxwork
