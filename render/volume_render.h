// One picture of a volume: its materials resolved, the light solved (on the CPU, or on the GPU in the
// picture's own OpenGL context, one device for both), the view applied and the image drawn. What
// `waxwork render` does between reading its options and writing its files.
#pragma once

#include "io/image_io.h"
#include "render/image_background.h"
#include "render/render_input.h"
#include "render/view_modes.h"
#include "solver/diffusion_solve.h"
#include "solver/lighting.h"
#include "solver/shading_surface.h"
#include "solver/solved_scene.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <optional>
#include <string>
#include <vector>

namespace waxwork {

struct VolumeRenderSettings {
    std::optional<TetMaterial> material;  // every tet's, when given (resolve_materials)
    Lighting lighting;
    // backend Gpu: solved in the picture's context; `gl` is then set here and must be left null.
    DiffusionOptions diffusion;
    // When set, one of the seeds' alternative methods solves instead of TransCut (solve_scene).
    std::optional<AlternativeMethodSettings> alternative;
    double crease_angle_degrees = kDefaultCreaseAngleDegrees;
    ImageSettings image;
    ViewOptions view;
    ImageBackground background;
    bool linear = false;
    bool ground = false;  // a ground plane with the model's shadows (SurfaceRenderInput::ground)  // also draw VolumeRender::linear (SurfaceRenderer::render_linear)
};

struct VolumeRender {
    TetConnectivity connectivity;
    std::vector<TetMaterial> materials;
    SolvedScene scene;
    ViewGeometry view;  // the view's colours, overlays and legend (empty for the radiance view)
    Image image;
    LinearImage linear;    // when settings.linear: the image before tone mapping
    float exposure = 1;    // the one the image was drawn with
    double render_ms = 0;  // the renderer's input, the view and the drawing
    size_t lights_inside = 0;  // point lights and sphere lights centred inside the volume (they light nothing)
};

// The light of a volume exactly as render_volume solves it, without drawing: the connectivity, the
// resolved materials and the solved scene (`waxwork export --radiance` bakes it). With backend Gpu the
// solve runs in a headless context of its own. Throws as render_volume.
struct VolumeLight {
    TetConnectivity connectivity;
    std::vector<TetMaterial> materials;
    SolvedScene scene;
};
VolumeLight solve_volume_light(const TetMesh& mesh, const std::string& volume_name, const VolumeRenderSettings& settings);

// Throws InvalidArgumentError for an empty volume or bad settings; errors about the volume's own
// data (stored materials no solve can use) name `volume_name`.
VolumeRender render_volume(const TetMesh& mesh, const std::string& volume_name, const VolumeRenderSettings& settings);

// Draws a light solved by solve_volume_light, possibly changed since (a fluence from elsewhere, with
// its radiance factors recomputed: `render --method mc`), as render_volume draws its own.
VolumeRender render_volume_light(const TetMesh& mesh, VolumeLight light, const VolumeRenderSettings& settings);

}  // namespace waxwork
