// From a solved scene to a picture: the renderer's input (world-space boundary, E, eta, the lights'
// highlights), its exposure, and the draw. `waxwork render`, sessions and the editor share these.
#pragma once

#include "io/image_io.h"
#include "render/surface_renderer.h"
#include "solver/lighting.h"
#include "solver/solved_scene.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <optional>
#include <vector>

namespace waxwork {

// How the image is framed and exposed.
struct ImageSettings {
    int width = 800;
    int height = 600;
    CameraSettings camera;
    std::optional<float> exposure;  // nullopt: automatic_exposure
};

// The largest width or height accepted (and the check render/demo apply to their options). The
// renderer draws into a 4x multisampled framebuffer: llvmpipe cannot allocate one of 16384 x 16384
// (4 GiB of colour and depth), and renders 8192 x 8192 in about 14 s with 2.7 GB resident.
inline constexpr int kMaxImageSide = 8192;

// Automatic exposure. The statistic is the luminance (Rec. 709 weights) of the radiance the camera
// sees from the subsurface term, L_o = F_t(theta_o) E, at the boundary vertices that face the camera;
// its 95th percentile is mapped to kExposureTarget before tone mapping (ACES maps 0.6 to 0.67, about
// sRGB 215), so the brightest few percent and the highlights keep headroom instead of clipping to
// white, and a dark material (ketchup) or a large scale (less light comes back) is exposed as well as
// marble: images differ in colour and in light distribution, not in overall brightness. Vertices, not
// pixels, are counted (cheap, before drawing; occlusion ignored). Returns 1 when nothing visible is lit.
inline constexpr double kExposurePercentile = 0.95;
inline constexpr double kExposureTarget = 0.6;
float automatic_exposure(const SurfaceRenderInput& input);

// The renderer's input for a solved scene, one vertex per shading vertex: world-space positions, the
// shading normals, E, eta and the lights for the highlights (point lights inside the volume dropped:
// they light nothing). The exposure is settings.exposure or automatic_exposure. E comes from
// scene.radiance_factor, or from `shading_radiance` (e.g. read back from the device) when given; both
// are per shading vertex. Throws InvalidArgumentError when the one used does not match the shading.
SurfaceRenderInput make_render_input(const TetMesh& mesh, const SolvedScene& scene, const Lighting& lighting,
                                     const ImageSettings& settings,
                                     const std::vector<std::array<float, 3>>* shading_radiance = nullptr);

// Draws with an existing renderer (keep one per context when rendering many frames).
Image render_scene(SurfaceRenderer& renderer, const SurfaceRenderInput& input);

}  // namespace waxwork
