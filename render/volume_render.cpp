#include "render/volume_render.h"

#include "base/error.h"
#include "base/timing.h"
#include "gl/gl_context.h"
#include "render/surface_renderer.h"
#include "solver/material.h"
#include "tetops/point_location.h"

#include <chrono>
#include <optional>
#include <utility>

namespace waxwork {

namespace {

// Checked before any OpenGL context is made.
void check_not_empty(const TetMesh& mesh, const std::string& volume_name) {
    if (mesh.tet_count() == 0) throw InvalidArgumentError(volume_name + ": the volume has no tets to render");
}

// What both entry points share; `gl` serves a GPU solve.
VolumeLight solve_light(const TetMesh& mesh, const std::string& volume_name, const VolumeRenderSettings& settings,
                        const GlApi* gl) {
    VolumeLight light;
    light.connectivity = build_connectivity(mesh);
    // A stored material no solve can use is the file's problem.
    light.materials = naming_context(volume_name, [&] { return resolve_materials(mesh, settings.material); });
    DiffusionOptions diffusion = settings.diffusion;
    if (diffusion.backend == SolverBackend::Gpu) diffusion.gl = gl;
    light.scene = solve_scene(mesh, light.connectivity, light.materials, settings.lighting, diffusion,
                              settings.crease_angle_degrees,
                              settings.alternative ? &*settings.alternative : nullptr);
    return light;
}

}  // namespace

VolumeLight solve_volume_light(const TetMesh& mesh, const std::string& volume_name, const VolumeRenderSettings& settings) {
    check_not_empty(mesh, volume_name);
    // A context only for a GPU solve: the CPU's needs none.
    std::optional<HeadlessGlContext> context;
    if (settings.diffusion.backend == SolverBackend::Gpu) context.emplace();
    return solve_light(mesh, volume_name, settings, context ? &context->gl() : nullptr);
}

namespace {

// Draws a solved light in `context`: the drawing half of render_volume.
VolumeRender draw_volume_light(const TetMesh& mesh, VolumeLight solved, const VolumeRenderSettings& settings,
                               HeadlessGlContext& context) {
    VolumeRender result;
    result.connectivity = std::move(solved.connectivity);
    result.materials = std::move(solved.materials);
    result.scene = std::move(solved.scene);

    const auto render_start = std::chrono::steady_clock::now();
    SurfaceRenderInput input = make_render_input(mesh, result.scene, settings.lighting, settings.image);
    result.view = build_view_geometry(mesh, result.connectivity, result.materials, result.scene, settings.view);
    apply_view(result.view, input);
    apply_background(settings.background, input);
    input.ground = settings.ground;
    SurfaceRenderer renderer(context.gl());
    result.image = render_scene(renderer, input);
    if (settings.linear) result.linear = renderer.render_linear(input);
    result.exposure = input.exposure;
    result.render_ms = milliseconds_since(render_start);

    for (const Light& light : settings.lighting.lights)
        result.lights_inside += radiates_from_centre(light.type) && point_inside_volume(mesh, light.vector);
    return result;
}

}  // namespace

VolumeRender render_volume(const TetMesh& mesh, const std::string& volume_name, const VolumeRenderSettings& settings) {
    check_not_empty(mesh, volume_name);
    // One OpenGL context for the GPU solve and the renderer (the same device).
    HeadlessGlContext context;
    return draw_volume_light(mesh, solve_light(mesh, volume_name, settings, &context.gl()), settings, context);
}

VolumeRender render_volume_light(const TetMesh& mesh, VolumeLight light, const VolumeRenderSettings& settings) {
    HeadlessGlContext context;
    return draw_volume_light(mesh, std::move(light), settings, context);
}

}  // namespace waxwork
