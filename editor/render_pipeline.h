// From a volume to a picture: the steps `waxwork render` and `waxwork demo` take, as free functions so
// the interactive editor and scripted sessions can run the same pipeline (and keep the pieces they
// need between frames: a solved scene, the GL renderer).
//
//   materials   per tet: an override, else the volume's stored ones, else marble
//   lighting    q at the boundary with shadows (solver/lighting.h)
//   diffusion   phi at every vertex (solver/diffusion_solve.h)
//   shading     the boundary split at its creases, q per copy (solver/shading_surface.h)
//   radiance    E per shading vertex, L_o = F_t(theta_o) E (solver/radiance.h)
//   image       SurfaceRenderer on the world-space boundary (editor/surface_renderer.h), exposed
//               automatically unless an exposure is given
#pragma once

#include "editor/surface_renderer.h"
#include "io/image_io.h"
#include "solver/diffusion_solve.h"
#include "solver/lighting.h"
#include "solver/shading_surface.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

namespace waxwork {

// The light `waxwork render` uses when none is given: a white key light from the upper front-left of
// a y-up model facing +z (travelling along (1, -1, -1)), so the default 3/4 camera (front right) sees
// lit faces next to faces in shade, and translucency shows in the gradient between them.
Light default_key_light();
// The ambient irradiance per channel where none is given (`render --ambient`, the editor, sessions).
inline constexpr double kDefaultAmbient = 0.02;
// The lighting of a scene that names none: default_key_light, kDefaultAmbient, shadows.
Lighting default_lighting();

// Parses "dir:X,Y,Z[:R,G,B]" (direction of travel) or "point:X,Y,Z[:R,G,B]" (position in model units);
// the intensity defaults to 1,1,1. Throws InvalidArgumentError("bad light spec 'SPEC': WHY") for
// anything else: unknown kind, wrong component count, trailing text, non-finite numbers, a zero
// direction or a negative intensity.
Light parse_light_spec(std::string_view spec);

// One material per tet: `override` everywhere when given, else the volume's stored materials, else
// the marble preset. Every material is validated (validate_material); a stored one that fails names
// its tet.
std::vector<TetMaterial> resolve_materials(const TetMesh& mesh, const std::optional<TetMaterial>& override);
// What resolve_materials(mesh, override) fills the tets with, by name: the override's preset name
// ("custom" for other coefficients; material_label), "stored" for the volume's own, else "marble".
std::string resolved_materials_name(const TetMesh& mesh, const std::optional<TetMaterial>& override);

// True when `point` (world space) lies inside or on a tet of the volume (piece transforms applied).
bool point_inside_volume(const TetMesh& mesh, const Eigen::Vector3d& point);

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
};

// Runs lighting, diffusion and radiance. Throws AlgorithmError when phi or E is not finite (never a
// NaN image), InvalidArgumentError for bad materials, lights, options or crease angle.
SolvedScene solve_scene(const TetMesh& mesh, const TetConnectivity& connectivity,
                        const std::vector<TetMaterial>& materials, const Lighting& lighting,
                        const DiffusionOptions& options, double crease_angle_degrees = kDefaultCreaseAngleDegrees);

// How the image is framed and exposed.
struct ImageSettings {
    int width = 800;
    int height = 600;
    CameraSettings camera;
    std::optional<float> exposure;  // nullopt: automatic_exposure
};

// The largest width or height accepted (and the check render/demo apply to their options).
inline constexpr int kMaxImageSide = 16384;

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

// Writes the per-vertex fields, atomically: header
//   x,y,z,boundary,q_r,q_g,q_b,phi_r,phi_g,phi_b,lo_r,lo_g,lo_b
// one row per volume vertex in the volume's order; x,y,z in world space; lo = F_t(1, eta) E, the
// exitant radiance seen along the normal (0 with q at interior vertices).
void write_fields_csv(const std::filesystem::path& path, const TetMesh& mesh, const TetConnectivity& connectivity,
                      const SolvedScene& scene);

}  // namespace waxwork
