// Draws the boundary surface of a volume with its subsurface radiance: per-vertex exitant radiance
// factor E (solver/radiance.h) times the view-dependent Fresnel transmittance F_t(theta_o) per
// fragment, plus a Cook-Torrance highlight for each light and the environment's reflection, over the
// environment as background when there is one, tone-mapped to sRGB. Cross-sections need no
// special case: after a cut they are boundary faces like any other.
#pragma once

#include "gl/gl_context.h"
#include "gl/gpu_compute.h"
#include "io/image_io.h"
#include "render/camera.h"
#include "render/ground_plane.h"
#include "render/srgb.h"
#include "solver/lighting.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <optional>
#include <memory>
#include <vector>

namespace waxwork {

enum class ToneMap { Aces, Reinhard, Clamp };

// What colours the surface (the optional views of render/view_modes.h use the colour modes).
enum class SurfaceShading {
    Radiance,        // F_t E plus the highlights, exposed and tone-mapped (the physical image)
    VertexColour,    // `colours` per vertex, interpolated
    TriangleColour,  // `colours` per triangle (flat)
};

// Unlit geometry drawn after the surface into the same depth buffer (so the surface hides what lies
// behind it): tet edges, slice polygons, marker points. Colours are linear rgb in [0, 1], shown as
// they are (no exposure, no tone mapping); lines and points are pulled slightly towards the camera
// so that edges lying on the surface are not lost to depth fighting.
struct RenderOverlay {
    std::vector<Eigen::Vector3f> line_vertices;          // two per segment
    std::vector<std::array<float, 3>> line_colours;      // per line vertex
    std::vector<Eigen::Vector3f> triangle_vertices;      // three per triangle
    std::vector<std::array<float, 3>> triangle_colours;  // per triangle vertex
    std::vector<Eigen::Vector3f> points;
    std::vector<std::array<float, 3>> point_colours;     // per point
    float point_size = 4.0f;                             // pixels
    bool empty() const { return line_vertices.empty() && triangle_vertices.empty() && points.empty(); }
};

struct SurfaceRenderInput {
    std::vector<Eigen::Vector3f> positions;            // world space
    std::vector<std::array<int32_t, 3>> triangles;     // counter-clockwise seen from outside
    std::vector<Eigen::Vector3f> normals;              // per vertex, outward
    std::vector<std::array<float, 3>> radiance_factor; // per vertex: E, rgb, HDR (L_o = F_t(theta_o) E)
    std::vector<float> eta;                            // per vertex; empty: uniform_eta everywhere
    float uniform_eta = 1.3f;
    // For the specular highlights (at most kMaxRenderLights lights); its environment, if any, is also
    // reflected (environment_prefilter.h) and, when its `background` is set, drawn behind the model.
    Lighting lighting;
    float roughness = 0.35f;                           // GGX roughness of the surface, (0, 1]
    float specular_scale = 1.0f;                       // 0 turns the highlight off
    int width = 800;
    int height = 600;
    int samples = 4;                                   // MSAA, clamped to what the driver supports
    CameraSettings camera;
    float exposure = 1.0f;
    ToneMap tone_map = ToneMap::Aces;
    std::array<uint8_t, 3> background = kViewBackground; // sRGB
    // Clear to transparent instead of `background`: render() then returns the object's coverage (the
    // multisample resolve's average) as alpha, with the colours un-premultiplied (straight alpha, as
    // PNG stores it). An environment drawn behind the model covers every pixel.
    bool transparent_background = false;
    // A ground plane under the model with its shadows and a soft contact shadow (ground_plane.h), for
    // the radiance shading. It fades into the background towards its edge (into transparency with
    // transparent_background; not at all in front of an environment, which it then hides below).
    bool ground = false;
    // Per vertex and light (lighting.lights.size() per vertex, vertex-major), multiplies that light's
    // highlight: the shadow rays' visibility (SolvedScene::light_visibility). Empty: all visible.
    std::vector<float> light_visibility;
    SurfaceShading shading = SurfaceShading::Radiance;
    // Linear rgb in [0, 1]: per vertex (VertexColour) or per triangle (TriangleColour), lit by a
    // headlight so the shape stays readable; unused for Radiance.
    std::vector<std::array<float, 3>> colours;
    RenderOverlay overlay;
    // (n, d): surface fragments at points p with n.p + d < 0 are not drawn (the slice view's cut-away
    // half). The overlay is never clipped.
    std::optional<Eigen::Vector4f> clip_plane;
    // Optional: E per vertex already on the device (3 floats per vertex, in the order of `positions`),
    // in a buffer of the drawing context's share group, complete (the editor's GPU solver writes it in
    // its own context and finishes, live_solver.h). Drawn instead of radiance_factor, which still sets
    // the automatic exposure.
    std::shared_ptr<const GpuBuffer> device_radiance;
};

inline constexpr int kMaxRenderLights = 8;

// Compiles the program and builds the F_t lookup table once; render() may then be called many times.
// Needs a current OpenGL >= 4.3 context (HeadlessGlContext or a window's) for its whole lifetime.
class SurfaceRenderer {
public:
    // Throws waxwork::Error with the driver's info log when a shader fails to compile or link.
    explicit SurfaceRenderer(const GlApi& gl);
    ~SurfaceRenderer();
    SurfaceRenderer(const SurfaceRenderer&) = delete;
    SurfaceRenderer& operator=(const SurfaceRenderer&) = delete;

    // Throws InvalidArgumentError for inconsistent input (array sizes, indices, non-finite values,
    // sizes beyond the driver's limits, too many lights) and waxwork::Error for driver failures.
    Image render(const SurfaceRenderInput& input);

    // The same picture before tone mapping: each pixel the exposed linear radiance (radiance times
    // input.exposure, the value ACES receives), straight alpha as render() gives it. For the radiance
    // shading; the overlay, if any, is drawn in its linear colours. Throws as render().
    LinearImage render_linear(const SurfaceRenderInput& input);

    // Draws `input` seen from `frame` (input.camera is ignored) and copies the resolved image into
    // `target_framebuffer` (0: the window's) with its lower-left corner at (x, y): exactly the pixels
    // render() returns for the same frame. The editor's viewport. Leaves `target_framebuffer` bound.
    void draw(const SurfaceRenderInput& input, const CameraFrame& frame, GLuint target_framebuffer, int x, int y);

private:
    struct Frame;
    // Draws into the multisampled target of `frame` and resolves it into its single-sampled one.
    // `linear`: float colour buffers and no tone mapping (render_linear).
    void draw_resolved(const SurfaceRenderInput& input, const CameraFrame& camera, Frame& frame, bool linear = false);
    // Makes the environment textures hold `map`, and its reflection for `roughness`; keeps them while
    // neither changes (the prefilter takes tens of milliseconds, a frame should not).
    // The ground plane (input.ground) into the bound multisampled target, before the surface.
    void draw_ground(const SurfaceRenderInput& input, const CameraFrame& camera, Frame& frame, bool linear,
                     bool over_environment);
    void prepare_environment(const std::shared_ptr<const EnvironmentMap>& map, float roughness);

    const GlApi& gl_;
    GLuint program_ = 0;
    GLuint overlay_program_ = 0;
    GLuint background_program_ = 0;
    GLuint ground_program_ = 0;
    GLuint ground_texture_ = 0;
    // What ground_texture_ was computed for (its rays take tens of milliseconds: an orbiting view or a
    // turntable redraws the same scene): the positions, and the lights as numbers.
    std::vector<Eigen::Vector3f> ground_positions_;
    std::vector<double> ground_lights_;
    GroundPlane ground_plane_;
    GLuint transmittance_lut_ = 0;
    GLuint environment_textures_[2] = {0, 0};  // the background, the prefiltered reflection
    std::shared_ptr<const EnvironmentMap> environment_map_;  // what environment_textures_ hold
    float environment_roughness_ = 0;
};

// Reads the bound read framebuffer's lower-left width x height pixels as an Image (top row first).
// Throws waxwork::Error when the driver reports an error.
Image read_framebuffer(const GlApi& gl, int width, int height);

// One-shot headless render: creates an OSMesa context (gl_context.h) and a renderer, draws, returns.
Image render_surface(const SurfaceRenderInput& input);

}  // namespace waxwork
