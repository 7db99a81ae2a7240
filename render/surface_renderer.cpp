#include "render/surface_renderer.h"

#include "base/error.h"
#include "render/environment_prefilter.h"
#include "render/ground_plane.h"
#include "solver/environment_light.h"
#include "solver/material.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <utility>
#include <string>

namespace waxwork {

namespace {

// F_t is tabulated from solver/material.h's fresnel_transmittance rather than re-derived in GLSL, so
// the shader and the solver can never disagree about it. 128 x 41 samples with bilinear filtering:
// the table error is far below one 8-bit output step.
constexpr int kLutCosSamples = 128;
constexpr int kLutEtaSamples = 41;
constexpr float kLutEtaMin = 1.0f;  // the range validate_material accepts
constexpr float kLutEtaMax = 3.0f;

// The background's texture is the map reduced to at most this width: 2048 texels over 360 degrees
// leave about 340 across a 60-degree view, sharp enough behind a model, and 24 MB of float texels.
constexpr int kBackgroundWidth = 2048;

constexpr const char* kVertexShader = R"glsl(
#version 430 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 radiance_factor;
layout(location = 3) in float eta;
layout(location = 4) in vec4 visibility_a;  // lights 0-3
layout(location = 5) in vec4 visibility_b;  // lights 4-7
uniform mat4 view_projection;
out vec3 v_position;
out vec3 v_normal;
out vec3 v_factor;
out float v_eta;
out vec4 v_visibility_a;
out vec4 v_visibility_b;
void main() {
    v_position = position;
    v_normal = normal;
    v_factor = radiance_factor;
    v_eta = eta;
    v_visibility_a = visibility_a;
    v_visibility_b = visibility_b;
    gl_Position = view_projection * vec4(position, 1.0);
}
)glsl";

// Shared by the surface's and the background's fragment shaders: exposure and tone mapping, the sRGB
// encoding, and where a world direction falls in the environment's textures.
constexpr const char* kCommonGlsl = R"glsl(
#version 430 core
const float kPi = 3.14159265358979;
uniform float exposure;
uniform int tone_map;                      // 0 ACES, 1 Reinhard, 2 clamp, 3 none (linear output)
uniform vec2 environment_turn;             // cos and sin of the environment's rotation about +y
uniform float environment_intensity;

vec3 aces(vec3 x) {  // Narkowicz's fit of the ACES filmic curve
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

vec3 srgb_encode(vec3 c) {
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

vec4 exposed_pixel(vec3 radiance) {
    vec3 c = max(radiance * exposure, vec3(0.0));
    if (tone_map == 3) return vec4(c, 1.0);
    if (tone_map == 0) c = aces(c);
    else if (tone_map == 1) c = c / (1.0 + c);
    else c = clamp(c, 0.0, 1.0);
    return vec4(srgb_encode(c), 1.0);
}

// The texture coordinates of world direction w in the map (environment_map.h's convention), after
// undoing the environment's rotation: R^-1 w.
vec2 environment_uv(vec3 w) {
    vec3 m = vec3(environment_turn.x * w.x - environment_turn.y * w.z, w.y,
                  environment_turn.y * w.x + environment_turn.x * w.z);
    float theta = acos(clamp(m.y / max(length(m), 1e-30), -1.0, 1.0));
    float phi = atan(m.x, -m.z);
    return vec2((phi + kPi) / (2.0 * kPi), theta / kPi);
}
)glsl";

constexpr const char* kFragmentShader = R"glsl(
const int kMaxLights = 8;
in vec3 v_position;
in vec3 v_normal;
in vec3 v_factor;
in float v_eta;
in vec4 v_visibility_a;
in vec4 v_visibility_b;
out vec4 color;
layout(std430, binding = 0) readonly buffer TriangleColours { float triangle_colour[]; };
uniform int shading;                       // 0 radiance, 1 vertex colour, 2 triangle colour
uniform int clip_enabled;
uniform vec4 clip_plane;
uniform vec3 eye;
uniform sampler2D transmittance_lut;  // x: cos(theta) in [0, 1], y: eta over lut_eta_range
uniform vec2 lut_eta_range;
uniform vec2 lut_size;
uniform int light_count;
uniform vec4 light_vector[kMaxLights];     // w = 0: direction of travel; w = 1: position
uniform vec3 light_intensity[kMaxLights];
uniform float roughness;
uniform float specular_scale;
uniform int environment_enabled;
uniform sampler2D environment_specular;    // the environment prefiltered for `roughness`

float transmittance(float cos_theta, float eta) {
    vec2 t = vec2(clamp(cos_theta, 0.0, 1.0),
                  clamp((eta - lut_eta_range.x) / (lut_eta_range.y - lut_eta_range.x), 0.0, 1.0));
    // Samples sit at texel centres: map [0, 1] onto [0.5, size - 0.5] texels.
    return texture(transmittance_lut, (t * (lut_size - 1.0) + 0.5) / lut_size).r;
}

// The integral of the BRDF against a white environment, split into a scale and a bias of the
// normal-incidence reflectance F0 (the second sum of Karis 2013, Eq. 5), from Lazarov's analytic fit
// ("Getting More Physical in Call of Duty: Black Ops II", 2013) instead of a second lookup table.
vec2 environment_brdf(float roughness, float nv) {
    const vec4 c0 = vec4(-1.0, -0.0275, -0.572, 0.022);
    const vec4 c1 = vec4(1.0, 0.0425, 1.04, -0.04);
    vec4 r = roughness * c0 + c1;
    float a004 = min(r.x * r.x, exp2(-9.28 * nv)) * r.x + r.y;
    return vec2(-1.04, 1.04) * a004 + r.zw;
}

void main() {
    if (clip_enabled != 0 && dot(clip_plane.xyz, v_position) + clip_plane.w < 0.0) discard;
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;  // inside of an open cut: shade the side we see
    vec3 v = normalize(eye - v_position);
    float nv = max(dot(n, v), 1e-4);
    if (shading != 0) {
        // A headlight keeps the shape readable without changing the hue the view encodes.
        vec3 albedo = v_factor;
        if (shading == 2) {
            int t = 3 * gl_PrimitiveID;
            albedo = vec3(triangle_colour[t], triangle_colour[t + 1], triangle_colour[t + 2]);
        }
        color = vec4(srgb_encode(clamp(albedo * (0.35 + 0.65 * nv), 0.0, 1.0)), 1.0);
        return;
    }
    // Subsurface part: L_o = F_t(theta_o) E (Li et al. 2013, Eq. 3).
    vec3 radiance = transmittance(nv, v_eta) * max(v_factor, vec3(0.0));

    // Cook-Torrance: GGX distribution, Smith-Schlick geometry (k = alpha / 2), Fresnel reflectance
    // 1 - F_t at the half vector.
    float alpha = roughness * roughness;
    float alpha2 = alpha * alpha;
    float k = alpha * 0.5;
    for (int i = 0; i < light_count; ++i) {
        vec3 l;
        vec3 irradiance = light_intensity[i];
        if (light_vector[i].w == 0.0) {
            l = -normalize(light_vector[i].xyz);
        } else {
            vec3 d = light_vector[i].xyz - v_position;
            float d2 = max(dot(d, d), 1e-12);
            l = d * inversesqrt(d2);
            irradiance /= d2;
        }
        float nl = dot(n, l);
        if (nl <= 0.0) continue;
        // The shadow rays' visibility of this light, interpolated over the triangle.
        float visible = i < 4 ? v_visibility_a[i] : v_visibility_b[i - 4];
        if (visible <= 0.0) continue;
        irradiance *= visible;
        vec3 h = normalize(l + v);
        float nh = max(dot(n, h), 0.0);
        float vh = max(dot(v, h), 0.0);
        float denom = nh * nh * (alpha2 - 1.0) + 1.0;
        float D = alpha2 / (kPi * denom * denom);
        float G = (nl / (nl * (1.0 - k) + k)) * (nv / (nv * (1.0 - k) + k));
        float F = 1.0 - transmittance(vh, v_eta);
        radiance += specular_scale * irradiance * nl * D * G * F / (4.0 * nl * nv);
    }
    // The environment's reflection by the split sum (environment_prefilter.h), unshadowed.
    if (environment_enabled != 0) {
        vec3 prefiltered = texture(environment_specular, environment_uv(reflect(-v, n))).rgb;
        float f0 = 1.0 - transmittance(1.0, v_eta);
        vec2 ab = environment_brdf(roughness, nv);
        radiance += specular_scale * environment_intensity * prefiltered * (f0 * ab.x + ab.y);
    }
    color = exposed_pixel(radiance);
}
)glsl";

// The environment behind the model: one triangle covering the viewport, each pixel the radiance
// arriving along its view ray, exposed and tone-mapped as the surface is.
constexpr const char* kBackgroundVertexShader = R"glsl(
#version 430 core
void main() {
    vec2 corner = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    gl_Position = vec4(corner * 2.0 - 1.0, 1.0, 1.0);
}
)glsl";

constexpr const char* kBackgroundFragmentShader = R"glsl(
uniform mat4 inverse_view_projection;
uniform vec2 viewport_size;
uniform sampler2D environment_background;
out vec4 color;
void main() {
    vec2 ndc = gl_FragCoord.xy / viewport_size * 2.0 - 1.0;
    vec4 near = inverse_view_projection * vec4(ndc, -1.0, 1.0);
    vec4 far = inverse_view_projection * vec4(ndc, 1.0, 1.0);
    vec3 w = far.xyz / far.w - near.xyz / near.w;
    color = exposed_pixel(environment_intensity * texture(environment_background, environment_uv(w)).rgb);
}
)glsl";

// The ground plane (ground_plane.h): a square from gl_VertexID, its irradiance from a texture, a
// diffuse grey exposed and tone-mapped as the surface is, faded towards its edge.
constexpr const char* kGroundVertexShader = R"glsl(
#version 430 core
uniform mat4 view_projection;
uniform vec4 ground;  // centre x, centre z, half side, height
out vec3 v_position;
void main() {
    vec2 corner = vec2(gl_VertexID & 1, gl_VertexID >> 1) * 2.0 - 1.0;
    v_position = vec3(ground.x + corner.x * ground.z, ground.w, ground.y + corner.y * ground.z);
    gl_Position = view_projection * vec4(v_position, 1.0);
}
)glsl";

constexpr const char* kGroundFragmentShader = R"glsl(
in vec3 v_position;
out vec4 color;
uniform vec4 ground;
uniform float texture_extent;
uniform float albedo;
uniform sampler2D ground_irradiance;
uniform int fade;           // 0 none, 1 into `background`, 2 into transparency
uniform vec3 background;    // as the clear colour holds it
void main() {
    vec2 offset = v_position.xz - ground.xy;
    vec3 irradiance = texture(ground_irradiance, offset / (2.0 * texture_extent) + 0.5).rgb;
    vec4 c = exposed_pixel(albedo / kPi * irradiance);
    float a = 1.0 - smoothstep(0.3, 0.95, length(offset) / ground.z);
    if (fade == 1) color = vec4(mix(background, c.rgb, a), 1.0);
    else if (fade == 2) color = vec4(c.rgb * a, a);  // premultiplied, as the resolve of the clear
    else color = c;
}
)glsl";

// The overlay: unlit, coloured lines, triangles and points.
constexpr const char* kOverlayVertexShader = R"glsl(
#version 430 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 colour;
uniform mat4 view_projection;
uniform float depth_pull;  // fraction of w subtracted from the clip-space depth
uniform float point_size;
out vec3 v_colour;
void main() {
    v_colour = colour;
    gl_Position = view_projection * vec4(position, 1.0);
    gl_Position.z -= depth_pull * gl_Position.w;
    gl_PointSize = point_size;
}
)glsl";

constexpr const char* kOverlayFragmentShader = R"glsl(
#version 430 core
in vec3 v_colour;
out vec4 color;
vec3 srgb_encode(vec3 c) {
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
void main() { color = vec4(srgb_encode(clamp(v_colour, 0.0, 1.0)), 1.0); }
)glsl";

GLuint compile_shader(const GlApi& gl, GLenum type, const std::string& source, const char* name) {
    const GLuint shader = gl.CreateShader(type);
    const char* text = source.c_str();
    gl.ShaderSource(shader, 1, &text, nullptr);
    gl.CompileShader(shader);
    GLint ok = GL_FALSE;
    gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (ok != GL_TRUE) {
        const std::string log = shader_info_log(gl, shader);
        gl.DeleteShader(shader);
        throw Error(std::string("surface renderer: the ") + name + " shader failed to compile: " + log);
    }
    return shader;
}

GLuint link_program(const GlApi& gl, const std::string& vertex_source, const std::string& fragment_source) {
    const GLuint vertex = compile_shader(gl, GL_VERTEX_SHADER, vertex_source, "vertex");
    GLuint fragment = 0;
    try {
        fragment = compile_shader(gl, GL_FRAGMENT_SHADER, fragment_source, "fragment");
    } catch (...) {
        gl.DeleteShader(vertex);
        throw;
    }
    const GLuint program = gl.CreateProgram();
    gl.AttachShader(program, vertex);
    gl.AttachShader(program, fragment);
    gl.LinkProgram(program);
    gl.DeleteShader(vertex);
    gl.DeleteShader(fragment);
    GLint ok = GL_FALSE;
    gl.GetProgramiv(program, GL_LINK_STATUS, &ok);
    if (ok != GL_TRUE) {
        const std::string log = program_info_log(gl, program);
        gl.DeleteProgram(program);
        throw Error(std::string("surface renderer: the shader program failed to link: ") + log);
    }
    return program;
}

// Every GL object of one render(), released on every path including exceptions.
struct FrameResources {
    const GlApi& gl;
    GLuint framebuffers[2] = {0, 0};   // multisampled, resolved
    GLuint renderbuffers[3] = {0, 0, 0};  // msaa colour, msaa depth, resolved colour
    GLuint vertex_array = 0;
    GLuint overlay_array = 0;
    GLuint background_array = 0;  // empty: the background's triangle comes from gl_VertexID
    // positions, normals, factors, eta, indices, visibility, triangle colours, overlay positions,
    // overlay colours, overlay indices
    static constexpr int kBuffers = 10;
    GLuint buffers[kBuffers] = {};

    explicit FrameResources(const GlApi& g) : gl(g) {}
    ~FrameResources() {
        gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
        gl.BindVertexArray(0);
        gl.DeleteFramebuffers(2, framebuffers);
        gl.DeleteRenderbuffers(3, renderbuffers);
        gl.DeleteVertexArrays(1, &vertex_array);
        gl.DeleteVertexArrays(1, &overlay_array);
        gl.DeleteVertexArrays(1, &background_array);
        gl.DeleteBuffers(kBuffers, buffers);
    }
};

// An incomplete framebuffer at a size the driver accepts is an allocation it could not make (llvmpipe
// at 16384 x 16384 with 4x MSAA needs 4 GiB of colour and depth): said with the size and the way out.
void check_framebuffer(const GlApi& gl, const char* which, int width, int height, int samples) {
    const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        char code[16];
        std::snprintf(code, sizeof code, "0x%04X", status);
        throw Error(std::string("surface renderer: the driver could not make the ") + which + " framebuffer of " +
                    std::to_string(width) + "x" + std::to_string(height) + " pixels, " + std::to_string(samples) +
                    " samples (status " + code + ", usually out of memory); render a smaller image");
    }
}

Eigen::Matrix4f to_float(const Eigen::Matrix4d& m) { return m.cast<float>(); }

// A point light farther than this from the surface's centre is drawn as the parallel light it
// approximates: the shader's float d.d overflows beyond about 1.8e19, and at this distance the
// directions to it differ across any surface float can place by less than float's own precision.
constexpr double kFarPointLight = 1e15;

// One light as the shader takes it, computed in double so that every light validate() accepts draws:
// a direction is normalised here (its components may be 1e-30 or 1e50, beyond float's range or
// precision once squared), and a point light beyond kFarPointLight becomes a direction with the
// irradiance it gives at the centre. An area light is drawn as the point light of its intensity at its
// centre: the highlight of a small light, without the shape a large one would reflect or a rectangle's
// or disk's fall-off with the emission angle (the subsurface term integrates the whole light); its
// visibility, the visible fraction of its samples, still dims the highlight in partial shadow.
struct ShaderLight {
    std::array<float, 4> vector;     // w = 0: unit direction of travel; w = 1: position
    std::array<float, 3> intensity;  // irradiance (w = 0) or radiant intensity (w = 1)
};

ShaderLight shader_light(const Light& light, const Eigen::Vector3d& centre) {
    Eigen::Vector3d vector = light.vector;
    double scale = 1.0;
    float w = 1.0f;
    if (light.type == LightType::Directional) {
        vector.normalize();
        w = 0.0f;
    } else if (const Eigen::Vector3d travel = centre - light.vector; travel.norm() > kFarPointLight) {
        scale = 1.0 / travel.squaredNorm();
        vector = travel.normalized();
        w = 0.0f;
    }
    ShaderLight out;
    out.vector = {static_cast<float>(vector.x()), static_cast<float>(vector.y()), static_cast<float>(vector.z()), w};
    for (int c = 0; c < 3; ++c) out.intensity[c] = static_cast<float>(light.intensity[c] * scale);
    return out;
}

void validate_input(const SurfaceRenderInput& input) {
    const size_t n = input.positions.size();
    auto fail = [](const std::string& what) { throw InvalidArgumentError("render_surface: " + what); };
    if (input.normals.size() != n) fail(std::to_string(input.normals.size()) + " normals for " + std::to_string(n) + " vertices");
    if (input.radiance_factor.size() != n) {
        fail(std::to_string(input.radiance_factor.size()) + " radiance factors for " + std::to_string(n) + " vertices");
    }
    if (input.device_radiance && input.device_radiance->bytes() < n * 3 * sizeof(float))
        fail("the device radiance buffer holds fewer than " + std::to_string(n) + " vertices");
    if (!input.eta.empty() && input.eta.size() != n) fail(std::to_string(input.eta.size()) + " eta values for " + std::to_string(n) + " vertices");
    for (size_t t = 0; t < input.triangles.size(); ++t) {
        for (int32_t v : input.triangles[t]) {
            if (v < 0 || static_cast<size_t>(v) >= n) fail("triangle " + std::to_string(t) + " has vertex index " + std::to_string(v) + " out of range");
        }
    }
    for (size_t i = 0; i < n; ++i) {
        if (!input.positions[i].allFinite() || !input.normals[i].allFinite()) fail("non-finite position or normal at vertex " + std::to_string(i));
    }
    if (input.width <= 0 || input.height <= 0) fail("image size must be positive");
    if (!(input.roughness > 0.0f && input.roughness <= 1.0f)) fail("roughness must be in (0, 1]");
    if (!std::isfinite(input.exposure) || input.exposure < 0) fail("exposure must be finite and non-negative");
    if (!std::isfinite(input.specular_scale) || input.specular_scale < 0) fail("specular_scale must be finite and non-negative");
    if (input.lighting.environment) validate(*input.lighting.environment);
    if (input.lighting.lights.size() > static_cast<size_t>(kMaxRenderLights)) {
        fail(std::to_string(input.lighting.lights.size()) + " lights; at most " + std::to_string(kMaxRenderLights) + " are drawn");
    }
    if (!input.light_visibility.empty() && input.light_visibility.size() != n * input.lighting.lights.size())
        fail(std::to_string(input.light_visibility.size()) + " visibility values for " + std::to_string(n) +
             " vertices and " + std::to_string(input.lighting.lights.size()) + " lights");
    if (input.shading == SurfaceShading::VertexColour && input.colours.size() != n)
        fail(std::to_string(input.colours.size()) + " vertex colours for " + std::to_string(n) + " vertices");
    if (input.shading == SurfaceShading::TriangleColour && input.colours.size() != input.triangles.size())
        fail(std::to_string(input.colours.size()) + " triangle colours for " + std::to_string(input.triangles.size()) +
             " triangles");
    const RenderOverlay& o = input.overlay;
    if (o.line_vertices.size() % 2 != 0 || o.line_colours.size() != o.line_vertices.size())
        fail("overlay lines need two vertices per segment and one colour per vertex");
    if (o.triangle_vertices.size() % 3 != 0 || o.triangle_colours.size() != o.triangle_vertices.size())
        fail("overlay triangles need three vertices each and one colour per vertex");
    if (o.point_colours.size() != o.points.size()) fail("overlay points need one colour each");
    if (!std::isfinite(o.point_size) || o.point_size <= 0) fail("overlay point size must be positive");
    for (const auto* list : {&o.line_vertices, &o.triangle_vertices, &o.points})
        for (const Eigen::Vector3f& p : *list)
            if (!p.allFinite()) fail("non-finite overlay vertex");
    if (input.clip_plane && (!input.clip_plane->allFinite() || input.clip_plane->head<3>().norm() == 0))
        fail("the clip plane needs a finite, non-zero normal");
    validate(input.lighting);
}

}  // namespace

SurfaceRenderer::SurfaceRenderer(const GlApi& gl) : gl_(gl) {
    program_ = link_program(gl_, kVertexShader, std::string(kCommonGlsl) + kFragmentShader);
    try {
        overlay_program_ = link_program(gl_, kOverlayVertexShader, kOverlayFragmentShader);
        background_program_ = link_program(gl_, kBackgroundVertexShader, std::string(kCommonGlsl) + kBackgroundFragmentShader);
        ground_program_ = link_program(gl_, kGroundVertexShader, std::string(kCommonGlsl) + kGroundFragmentShader);
    } catch (...) {
        gl_.DeleteProgram(background_program_);
        gl_.DeleteProgram(overlay_program_);
        gl_.DeleteProgram(program_);
        throw;
    }

    std::vector<float> table(kLutCosSamples * kLutEtaSamples);
    for (int j = 0; j < kLutEtaSamples; ++j) {
        const double eta = kLutEtaMin + (kLutEtaMax - kLutEtaMin) * j / (kLutEtaSamples - 1);
        for (int i = 0; i < kLutCosSamples; ++i) {
            table[j * kLutCosSamples + i] =
                static_cast<float>(fresnel_transmittance(static_cast<double>(i) / (kLutCosSamples - 1), eta));
        }
    }
    gl_.GenTextures(1, &transmittance_lut_);
    gl_.BindTexture(GL_TEXTURE_2D, transmittance_lut_);
    gl_.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl_.TexImage2D(GL_TEXTURE_2D, 0, GL_R32F, kLutCosSamples, kLutEtaSamples, 0, GL_RED, GL_FLOAT, table.data());
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl_.BindTexture(GL_TEXTURE_2D, 0);
    check_gl_error(gl_, "surface renderer: creating the transmittance table");
}

SurfaceRenderer::~SurfaceRenderer() {
    gl_.DeleteTextures(1, &transmittance_lut_);
    gl_.DeleteTextures(1, &ground_texture_);
    gl_.DeleteProgram(ground_program_);
    gl_.DeleteTextures(2, environment_textures_);
    gl_.DeleteProgram(background_program_);
    gl_.DeleteProgram(overlay_program_);
    gl_.DeleteProgram(program_);
}

Image read_framebuffer(const GlApi& gl, int width, int height) {
    Image image;
    image.width = width;
    image.height = height;
    image.rgba.resize(4 * static_cast<size_t>(width) * static_cast<size_t>(height));
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
    check_gl_error(gl, "reading back the framebuffer");

    // OpenGL's first row is the bottom one; Image's is the top one.
    const size_t row = 4 * static_cast<size_t>(width);
    std::vector<uint8_t> swap(row);
    for (int y = 0; y < height / 2; ++y) {
        uint8_t* a = image.rgba.data() + y * row;
        uint8_t* b = image.rgba.data() + (height - 1 - y) * row;
        std::memcpy(swap.data(), a, row);
        std::memcpy(a, b, row);
        std::memcpy(b, swap.data(), row);
    }
    return image;
}

namespace {

// Lines, then triangles, then points from one vertex buffer, each with its own index range.
void draw_overlay(const GlApi& gl, GLuint program, const RenderOverlay& o, const CameraFrame& frame, FrameResources& r) {
    std::vector<Eigen::Vector3f> positions;
    std::vector<std::array<float, 3>> colours;
    positions.reserve(o.line_vertices.size() + o.triangle_vertices.size() + o.points.size());
    colours.reserve(positions.capacity());
    for (const auto& [p, c] : {std::pair{&o.line_vertices, &o.line_colours}, std::pair{&o.triangle_vertices, &o.triangle_colours},
                               std::pair{&o.points, &o.point_colours}}) {
        positions.insert(positions.end(), p->begin(), p->end());
        colours.insert(colours.end(), c->begin(), c->end());
    }
    std::vector<uint32_t> indices(positions.size());
    for (size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<uint32_t>(i);

    gl.GenVertexArrays(1, &r.overlay_array);
    gl.BindVertexArray(r.overlay_array);
    gl.BindBuffer(GL_ARRAY_BUFFER, r.buffers[7]);
    gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(positions.size() * sizeof(Eigen::Vector3f)), positions.data(),
                  GL_STATIC_DRAW);
    gl.EnableVertexAttribArray(0);
    gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    gl.BindBuffer(GL_ARRAY_BUFFER, r.buffers[8]);
    gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(colours.size() * sizeof(std::array<float, 3>)), colours.data(),
                  GL_STATIC_DRAW);
    gl.EnableVertexAttribArray(1);
    gl.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, r.buffers[9]);
    gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(uint32_t)), indices.data(),
                  GL_STATIC_DRAW);

    gl.UseProgram(program);
    const Eigen::Matrix4f view_projection = to_float(frame.projection * frame.view);
    gl.UniformMatrix4fv(gl.GetUniformLocation(program, "view_projection"), 1, GL_FALSE, view_projection.data());
    gl.Uniform1f(gl.GetUniformLocation(program, "point_size"), o.point_size);
    const GLint pull = gl.GetUniformLocation(program, "depth_pull");
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LEQUAL);
    gl.Enable(GL_PROGRAM_POINT_SIZE);
    auto draw = [&](GLenum mode, size_t first, size_t count, float depth_pull) {
        if (count == 0) return;
        gl.Uniform1f(pull, depth_pull);
        gl.DrawElements(mode, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                        reinterpret_cast<const void*>(static_cast<uintptr_t>(first * sizeof(uint32_t))));
    };
    // Lines and points on the surface would fight its depth: pull them a little towards the eye.
    // Triangles (slice polygons) lie where the clipped surface ends and need no pull.
    const size_t lines = o.line_vertices.size(), triangles = o.triangle_vertices.size();
    draw(GL_TRIANGLES, lines, triangles, 0.0f);
    draw(GL_LINES, 0, lines, 2e-4f);
    draw(GL_POINTS, lines + triangles, o.points.size(), 2e-3f);
    gl.Disable(GL_PROGRAM_POINT_SIZE);
    gl.DepthFunc(GL_LESS);
    gl.UseProgram(0);
}

// An equirectangular texture: linear filtering, wrapping across the seam in longitude, clamped at the
// poles. Float texels: an HDR file's brightest pixels exceed half float's range.
void upload_environment_texture(const GlApi& gl, GLuint texture, const EnvironmentTexture& t) {
    gl.BindTexture(GL_TEXTURE_2D, texture);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, t.width, t.height, 0, GL_RGB, GL_FLOAT, t.texels.data());
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl.BindTexture(GL_TEXTURE_2D, 0);
}

// The uniforms kCommonGlsl declares, for the program in use.
void set_common_uniforms(const GlApi& gl, GLuint program, const SurfaceRenderInput& input, bool linear) {
    auto location = [&](const char* name) { return gl.GetUniformLocation(program, name); };
    gl.Uniform1f(location("exposure"), input.exposure);
    gl.Uniform1i(location("tone_map"), linear ? 3 : static_cast<int>(input.tone_map));
    const auto& environment = input.lighting.environment;
    const double radians = environment ? environment->rotation_degrees * std::numbers::pi / 180 : 0.0;
    gl.Uniform2f(location("environment_turn"), static_cast<float>(std::cos(radians)), static_cast<float>(std::sin(radians)));
    gl.Uniform1f(location("environment_intensity"), environment ? static_cast<float>(environment->intensity) : 0.0f);
}

}  // namespace

struct SurfaceRenderer::Frame : FrameResources {
    using FrameResources::FrameResources;
};

void SurfaceRenderer::prepare_environment(const std::shared_ptr<const EnvironmentMap>& map, float roughness) {
    if (environment_textures_[0] == 0) gl_.GenTextures(2, environment_textures_);
    if (map != environment_map_) {
        // One reduction of the full map serves both textures.
        const EnvironmentTexture background = reduce_environment(*map, kBackgroundWidth);
        upload_environment_texture(gl_, environment_textures_[0], background);
        upload_environment_texture(gl_, environment_textures_[1], prefilter_environment(background, roughness));
        environment_map_ = map;
        environment_roughness_ = roughness;
    }
    if (roughness != environment_roughness_) {
        upload_environment_texture(gl_, environment_textures_[1], prefilter_environment(*map, roughness));
        environment_roughness_ = roughness;
    }
    check_gl_error(gl_, "surface renderer: uploading the environment");
}

void SurfaceRenderer::draw_resolved(const SurfaceRenderInput& input, const CameraFrame& frame, Frame& r, bool linear) {
    validate_input(input);
    const GlApi& gl = gl_;
    GLint max_size = 0, max_samples = 0;
    gl.GetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
    gl.GetIntegerv(GL_MAX_SAMPLES, &max_samples);
    if (input.width > max_size || input.height > max_size) {
        throw InvalidArgumentError("render_surface: " + std::to_string(input.width) + "x" + std::to_string(input.height) +
                                   " exceeds the driver's maximum of " + std::to_string(max_size) + " pixels per side");
    }
    const int samples = std::clamp(input.samples, 1, std::max(max_samples, 1));

    gl.GenFramebuffers(2, r.framebuffers);
    gl.GenRenderbuffers(3, r.renderbuffers);
    gl.BindRenderbuffer(GL_RENDERBUFFER, r.renderbuffers[0]);
    const GLenum colour_format = linear ? GL_RGBA32F : GL_RGBA8;
    gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, colour_format, input.width, input.height);
    gl.BindRenderbuffer(GL_RENDERBUFFER, r.renderbuffers[1]);
    gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, input.width, input.height);
    gl.BindRenderbuffer(GL_RENDERBUFFER, r.renderbuffers[2]);
    gl.RenderbufferStorage(GL_RENDERBUFFER, colour_format, input.width, input.height);
    gl.BindFramebuffer(GL_FRAMEBUFFER, r.framebuffers[1]);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, r.renderbuffers[2]);
    check_framebuffer(gl, "resolve", input.width, input.height, 1);
    gl.BindFramebuffer(GL_FRAMEBUFFER, r.framebuffers[0]);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, r.renderbuffers[0]);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, r.renderbuffers[1]);
    check_framebuffer(gl, "multisampled", input.width, input.height, samples);

    gl.Viewport(0, 0, input.width, input.height);
    if (input.transparent_background) {
        gl.ClearColor(0.0f, 0.0f, 0.0f, 0.0f);
    } else if (linear) {
        // The background colour is sRGB-encoded; the linear image holds it decoded.
        gl.ClearColor(static_cast<float>(srgb_decode(input.background[0] / 255.0)),
                      static_cast<float>(srgb_decode(input.background[1] / 255.0)),
                      static_cast<float>(srgb_decode(input.background[2] / 255.0)), 1.0f);
    } else {
        gl.ClearColor(input.background[0] / 255.0f, input.background[1] / 255.0f, input.background[2] / 255.0f, 1.0f);
    }
    gl.ClearDepth(1.0);
    gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

    // The environment appears in the physical image only, not in the inspection views.
    const bool environment = input.lighting.environment && input.shading == SurfaceShading::Radiance;
    if (environment) prepare_environment(input.lighting.environment->map, input.roughness);
    if (environment && input.lighting.environment->background) {
        gl.UseProgram(background_program_);
        set_common_uniforms(gl, background_program_, input, linear);
        const Eigen::Matrix4f inverse = (frame.projection * frame.view).inverse().cast<float>();
        gl.UniformMatrix4fv(gl.GetUniformLocation(background_program_, "inverse_view_projection"), 1, GL_FALSE,
                            inverse.data());
        gl.Uniform2f(gl.GetUniformLocation(background_program_, "viewport_size"), static_cast<float>(input.width),
                     static_cast<float>(input.height));
        gl.ActiveTexture(GL_TEXTURE0);
        gl.BindTexture(GL_TEXTURE_2D, environment_textures_[0]);
        gl.Uniform1i(gl.GetUniformLocation(background_program_, "environment_background"), 0);
        gl.GenVertexArrays(1, &r.background_array);
        gl.BindVertexArray(r.background_array);
        gl.Disable(GL_DEPTH_TEST);  // behind everything, and the surface's depth test starts from the clear
        gl.DrawArrays(GL_TRIANGLES, 0, 3);
        gl.BindVertexArray(0);
        gl.BindTexture(GL_TEXTURE_2D, 0);
        gl.UseProgram(0);
    }

    if (input.ground && input.shading == SurfaceShading::Radiance && !input.triangles.empty())
        draw_ground(input, frame, r, linear, environment && input.lighting.environment->background);

    if (!input.triangles.empty()) {
        const size_t n = input.positions.size();
        std::vector<float> eta = input.eta.empty() ? std::vector<float>(n, input.uniform_eta) : input.eta;
        gl.GenVertexArrays(1, &r.vertex_array);
        gl.BindVertexArray(r.vertex_array);
        gl.GenBuffers(FrameResources::kBuffers, r.buffers);
        auto attribute = [&](GLuint index, GLuint buffer, const void* data, size_t bytes, GLint components) {
            gl.BindBuffer(GL_ARRAY_BUFFER, buffer);
            gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(bytes), data, GL_STATIC_DRAW);
            gl.EnableVertexAttribArray(index);
            gl.VertexAttribPointer(index, components, GL_FLOAT, GL_FALSE, 0, nullptr);
        };
        // Eigen::Vector3f and std::array<float, 3> are three packed floats.
        static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float) && sizeof(std::array<float, 3>) == 3 * sizeof(float));
        attribute(0, r.buffers[0], input.positions.data(), n * sizeof(Eigen::Vector3f), 3);
        attribute(1, r.buffers[1], input.normals.data(), n * sizeof(Eigen::Vector3f), 3);
        if (input.device_radiance && input.shading == SurfaceShading::Radiance) {
            // E straight from the solver's buffer (same layout as the uploaded attribute).
            gl.BindBuffer(GL_ARRAY_BUFFER, input.device_radiance->id());
            gl.EnableVertexAttribArray(2);
            gl.VertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
        } else {
            // The colour modes pass their per-vertex colours where the radiance factors go.
            const auto& factors =
                input.shading == SurfaceShading::VertexColour ? input.colours : input.radiance_factor;
            attribute(2, r.buffers[2], factors.data(), n * sizeof(std::array<float, 3>), 3);
        }
        attribute(3, r.buffers[3], eta.data(), n * sizeof(float), 1);
        // Visibility as two vec4 attributes of eight lights each (1 where not given).
        const size_t light_count_in = input.lighting.lights.size();
        std::vector<float> visibility(8 * n, 1.0f);
        if (!input.light_visibility.empty())
            for (size_t v = 0; v < n; ++v)
                for (size_t l = 0; l < light_count_in; ++l) visibility[8 * v + l] = input.light_visibility[v * light_count_in + l];
        gl.BindBuffer(GL_ARRAY_BUFFER, r.buffers[5]);
        gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(visibility.size() * sizeof(float)), visibility.data(),
                      GL_STATIC_DRAW);
        for (GLuint k = 0; k < 2; ++k) {
            gl.EnableVertexAttribArray(4 + k);
            gl.VertexAttribPointer(4 + k, 4, GL_FLOAT, GL_FALSE, 8 * sizeof(float),
                                   reinterpret_cast<const void*>(static_cast<uintptr_t>(4 * k * sizeof(float))));
        }
        // Per-triangle colours as a storage buffer read with gl_PrimitiveID (one entry when unused:
        // the binding must exist).
        std::vector<float> triangle_colours(3, 0.0f);
        if (input.shading == SurfaceShading::TriangleColour && !input.colours.empty()) {
            triangle_colours.resize(3 * input.colours.size());
            std::memcpy(triangle_colours.data(), input.colours.data(), triangle_colours.size() * sizeof(float));
        }
        gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, r.buffers[6]);
        gl.BufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(triangle_colours.size() * sizeof(float)),
                      triangle_colours.data(), GL_STATIC_DRAW);
        gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, r.buffers[6]);
        gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, r.buffers[4]);
        gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(input.triangles.size() * sizeof(input.triangles[0])),
                      input.triangles.data(), GL_STATIC_DRAW);

        const Eigen::Matrix4f view_projection = to_float(frame.projection * frame.view);

        gl.UseProgram(program_);
        auto location = [&](const char* name) { return gl.GetUniformLocation(program_, name); };
        gl.UniformMatrix4fv(location("view_projection"), 1, GL_FALSE, view_projection.data());  // column-major
        const Eigen::Vector3f eye = frame.eye.cast<float>();
        gl.Uniform3fv(location("eye"), 1, eye.data());
        gl.Uniform2f(location("lut_eta_range"), kLutEtaMin, kLutEtaMax);
        gl.Uniform2f(location("lut_size"), kLutCosSamples, kLutEtaSamples);
        gl.Uniform1f(location("roughness"), input.roughness);
        gl.Uniform1f(location("specular_scale"), input.specular_scale);
        set_common_uniforms(gl, program_, input, linear);
        gl.Uniform1i(location("environment_enabled"), environment ? 1 : 0);
        gl.Uniform1i(location("shading"), static_cast<int>(input.shading));
        gl.Uniform1i(location("clip_enabled"), input.clip_plane ? 1 : 0);
        const Eigen::Vector4f plane = input.clip_plane.value_or(Eigen::Vector4f::Zero());
        gl.Uniform4fv(location("clip_plane"), 1, plane.data());
        const auto light_count = static_cast<int>(input.lighting.lights.size());
        gl.Uniform1i(location("light_count"), light_count);
        // The centre only matters to lights with a position (shader_light): no pass over the vertices
        // without one.
        Eigen::AlignedBox3d bounds;
        if (std::any_of(input.lighting.lights.begin(), input.lighting.lights.end(),
                        [](const Light& light) { return has_position(light.type); }))
            for (const Eigen::Vector3f& p : input.positions) bounds.extend(p.cast<double>());
        const Eigen::Vector3d centre = bounds.isEmpty() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(bounds.center());
        for (int i = 0; i < light_count; ++i) {
            const ShaderLight light = shader_light(input.lighting.lights[i], centre);
            const std::string index = "[" + std::to_string(i) + "]";
            gl.Uniform4fv(location(("light_vector" + index).c_str()), 1, light.vector.data());
            gl.Uniform3fv(location(("light_intensity" + index).c_str()), 1, light.intensity.data());
        }
        gl.ActiveTexture(GL_TEXTURE0);
        gl.BindTexture(GL_TEXTURE_2D, transmittance_lut_);
        gl.Uniform1i(location("transmittance_lut"), 0);
        // Unit 1 always holds a texture: a sampler without one is undefined even where unused.
        gl.ActiveTexture(GL_TEXTURE1);
        gl.BindTexture(GL_TEXTURE_2D, environment ? environment_textures_[1] : transmittance_lut_);
        gl.Uniform1i(location("environment_specular"), 1);
        gl.ActiveTexture(GL_TEXTURE0);

        gl.Enable(GL_DEPTH_TEST);
        gl.DepthFunc(GL_LESS);
        gl.Enable(GL_MULTISAMPLE);
        gl.Disable(GL_CULL_FACE);  // cut-open or non-closed surfaces show their inner side
        gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * input.triangles.size()), GL_UNSIGNED_INT, nullptr);
        gl.UseProgram(0);
        gl.ActiveTexture(GL_TEXTURE1);
        gl.BindTexture(GL_TEXTURE_2D, 0);
        gl.ActiveTexture(GL_TEXTURE0);
        gl.BindTexture(GL_TEXTURE_2D, 0);
        gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, 0);
    }
    if (!input.overlay.empty()) draw_overlay(gl, overlay_program_, input.overlay, frame, r);

    // Resolve the samples.
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, r.framebuffers[0]);
    gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, r.framebuffers[1]);
    gl.BlitFramebuffer(0, 0, input.width, input.height, 0, 0, input.width, input.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
}

void SurfaceRenderer::draw_ground(const SurfaceRenderInput& input, const CameraFrame& frame, Frame& r, bool linear,
                                  bool over_environment) {
    const GlApi& gl = gl_;
    std::vector<double> lights = {static_cast<double>(input.lighting.shadows), input.lighting.ambient[0],
                                  input.lighting.ambient[1], input.lighting.ambient[2]};
    for (const Light& light : input.lighting.lights) {
        lights.insert(lights.end(), {static_cast<double>(light.type), light.vector.x(), light.vector.y(), light.vector.z()});
        lights.insert(lights.end(), light.intensity.begin(), light.intensity.end());
    }
    if (const auto& environment = input.lighting.environment)
        lights.insert(lights.end(), {static_cast<double>(reinterpret_cast<uintptr_t>(environment->map.get())),
                                     environment->rotation_degrees, environment->intensity});
    if (ground_texture_ == 0) gl.GenTextures(1, &ground_texture_);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_2D, ground_texture_);
    if (input.positions != ground_positions_ || lights != ground_lights_ ||
        ground_plane_.irradiance.empty()) {
        ground_plane_ = ground_plane(input);
        ground_positions_ = input.positions;
        ground_lights_ = std::move(lights);
        gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
        gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, ground_plane_.resolution, ground_plane_.resolution, 0, GL_RGB,
                      GL_FLOAT, ground_plane_.irradiance.data());
    }
    const GroundPlane& plane = ground_plane_;
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);

    gl.UseProgram(ground_program_);
    set_common_uniforms(gl, ground_program_, input, linear);
    auto location = [&](const char* name) { return gl.GetUniformLocation(ground_program_, name); };
    const Eigen::Matrix4f view_projection = to_float(frame.projection * frame.view);
    gl.UniformMatrix4fv(location("view_projection"), 1, GL_FALSE, view_projection.data());
    // Just below the lowest point: the model's face resting on the ground must win the depth test.
    const float below = 1e-4f * plane.extent;
    const std::array<float, 4> ground{plane.centre.x(), plane.centre.y(), plane.extent, plane.height - below};
    gl.Uniform4fv(location("ground"), 1, ground.data());
    gl.Uniform1f(location("texture_extent"), plane.texture_extent);
    gl.Uniform1f(location("albedo"), kGroundPlaneAlbedo);
    gl.Uniform1i(location("ground_irradiance"), 0);
    gl.Uniform1i(location("fade"), over_environment ? 0 : input.transparent_background ? 2 : 1);
    std::array<float, 3> background{};
    for (int c = 0; c < 3; ++c)
        background[c] = linear ? static_cast<float>(srgb_decode(input.background[c] / 255.0)) : input.background[c] / 255.0f;
    gl.Uniform3fv(location("background"), 1, background.data());
    if (r.background_array == 0) gl.GenVertexArrays(1, &r.background_array);
    gl.BindVertexArray(r.background_array);  // empty: the corners come from gl_VertexID
    // The plane reaches beyond the far plane, which encloses only the model's bounding sphere: clamped
    // depth (at 1, the clear's, hence LEQUAL) keeps its far part instead of cutting a false horizon.
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LEQUAL);
    gl.Enable(GL_DEPTH_CLAMP);
    gl.DrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    gl.Disable(GL_DEPTH_CLAMP);
    gl.DepthFunc(GL_LESS);
    gl.BindVertexArray(0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.UseProgram(0);
    check_gl_error(gl, "surface renderer: drawing the ground");
}

void SurfaceRenderer::draw(const SurfaceRenderInput& input, const CameraFrame& camera, GLuint target_framebuffer, int x,
                           int y) {
    {
        Frame r(gl_);
        draw_resolved(input, camera, r);
        // A multisampled source may only be blitted to the same rectangle, so the offset copy starts
        // from the resolved image.
        gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, r.framebuffers[1]);
        gl_.BindFramebuffer(GL_DRAW_FRAMEBUFFER, target_framebuffer);
        gl_.BlitFramebuffer(0, 0, input.width, input.height, x, y, x + input.width, y + input.height,
                            GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }  // the frame's objects are released (which unbinds them)
    gl_.BindFramebuffer(GL_FRAMEBUFFER, target_framebuffer);
    check_gl_error(gl_, "surface renderer: drawing into the target framebuffer");
}

namespace {

// The frame render() and render_linear() draw: framed on the input's bounding box.
CameraFrame input_frame(const SurfaceRenderInput& input) {
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3f& p : input.positions) box.extend(p.cast<double>());
    return box.isEmpty() ? CameraFrame{} : frame_camera(box, input.camera, static_cast<double>(input.width) / input.height);
}

// The resolve averages premultiplied samples (the clear is transparent black, the surface opaque):
// divide the colour by the coverage for straight alpha.
void unpremultiply(Image& image) {
    for (size_t p = 0; p < image.rgba.size(); p += 4) {
        const unsigned a = image.rgba[p + 3];
        if (a == 0 || a == 255) continue;
        for (int c = 0; c < 3; ++c)
            image.rgba[p + c] = static_cast<uint8_t>(std::min(255u, (image.rgba[p + c] * 255u + a / 2) / a));
    }
}

}  // namespace

Image SurfaceRenderer::render(const SurfaceRenderInput& input) {
    validate_input(input);
    const CameraFrame frame = input_frame(input);
    const GlApi& gl = gl_;
    Frame r(gl);
    draw_resolved(input, frame, r);
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, r.framebuffers[1]);
    Image image = read_framebuffer(gl, input.width, input.height);
    check_gl_error(gl, "surface renderer: drawing");
    if (input.transparent_background) unpremultiply(image);
    return image;
}

LinearImage SurfaceRenderer::render_linear(const SurfaceRenderInput& input) {
    validate_input(input);
    const CameraFrame frame = input_frame(input);
    const GlApi& gl = gl_;
    Frame r(gl);
    draw_resolved(input, frame, r, true);
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, r.framebuffers[1]);
    LinearImage image;
    image.width = input.width;
    image.height = input.height;
    image.rgba.resize(4 * static_cast<size_t>(input.width) * static_cast<size_t>(input.height));
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.ReadPixels(0, 0, input.width, input.height, GL_RGBA, GL_FLOAT, image.rgba.data());
    check_gl_error(gl, "surface renderer: drawing the linear image");
    // Bottom row first from OpenGL, top row first in LinearImage; straight alpha as render() gives.
    const size_t row = 4 * static_cast<size_t>(input.width);
    for (int y = 0; y < input.height / 2; ++y)
        std::swap_ranges(image.rgba.begin() + static_cast<std::ptrdiff_t>(y * row),
                         image.rgba.begin() + static_cast<std::ptrdiff_t>((y + 1) * row),
                         image.rgba.begin() + static_cast<std::ptrdiff_t>((input.height - 1 - y) * row));
    if (input.transparent_background)
        for (size_t p = 0; p < image.rgba.size(); p += 4) {
            const float a = image.rgba[p + 3];
            if (a > 0 && a < 1)
                for (int c = 0; c < 3; ++c) image.rgba[p + c] /= a;
        }
    return image;
}

Image render_surface(const SurfaceRenderInput& input) {
    validate_input(input);  // before paying for a context
    HeadlessGlContext context;
    SurfaceRenderer renderer(context.gl());
    return renderer.render(input);
}

}  // namespace waxwork
