#include "editor/render_pipeline.h"

#include "io/atomic_file.h"
#include "solver/material.h"
#include "solver/radiance.h"
#include "tetops/cut.h"
#include "tetops/error.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <string>

namespace waxwork {

namespace {

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Comma-separated doubles, all of the text consumed. std::from_chars rather than stod: it is
// locale-independent and reports trailing garbage ("1,2,3x") instead of ignoring it.
bool parse_numbers(std::string_view text, std::vector<double>& values) {
    values.clear();
    while (true) {
        const size_t comma = text.find(',');
        const std::string_view item = text.substr(0, comma);
        double value = 0;
        const char* begin = item.data();
        const char* end = item.data() + item.size();
        if (!item.empty() && *begin == '+') ++begin;  // from_chars refuses a leading '+'
        const auto [ptr, ec] = std::from_chars(begin, end, value);
        if (ec != std::errc() || ptr != end || begin == end) return false;
        values.push_back(value);
        if (comma == std::string_view::npos) return true;
        text.remove_prefix(comma + 1);
    }
}

}  // namespace

Light default_key_light() {
    Light light;
    light.type = LightType::Directional;
    light.vector = Eigen::Vector3d(1, -1, -1).normalized();
    light.intensity = {1, 1, 1};
    return light;
}

Lighting default_lighting() {
    Lighting lighting;
    lighting.lights = {default_key_light()};
    lighting.ambient = {kDefaultAmbient, kDefaultAmbient, kDefaultAmbient};
    lighting.shadows = true;
    return lighting;
}

Light parse_light_spec(std::string_view spec) {
    const auto fail = [&](const std::string& why) {
        throw InvalidArgumentError("bad light spec '" + std::string(spec) + "': " + why);
    };
    const size_t colon = spec.find(':');
    if (colon == std::string_view::npos) fail("expected dir:X,Y,Z[:R,G,B] or point:X,Y,Z[:R,G,B]");
    const std::string_view kind = spec.substr(0, colon);
    Light light;
    if (kind == "dir") {
        light.type = LightType::Directional;
    } else if (kind == "point") {
        light.type = LightType::Point;
    } else {
        fail("unknown kind '" + std::string(kind) + "' (dir or point)");
    }
    std::string_view rest = spec.substr(colon + 1);
    const size_t second = rest.find(':');
    const std::string_view vector_text = rest.substr(0, second);
    std::vector<double> v;
    if (!parse_numbers(vector_text, v) || v.size() != 3) fail("expected three numbers X,Y,Z");
    light.vector = Eigen::Vector3d(v[0], v[1], v[2]);
    if (!light.vector.allFinite()) fail("non-finite coordinate");
    if (light.type == LightType::Directional && light.vector.norm() == 0) fail("zero direction");
    if (second != std::string_view::npos) {
        std::vector<double> c;
        if (!parse_numbers(rest.substr(second + 1), c) || c.size() != 3) fail("expected an intensity R,G,B");
        for (int k = 0; k < 3; ++k) {
            if (!std::isfinite(c[k]) || c[k] < 0) fail("intensity must be finite and non-negative");
            light.intensity[k] = c[k];
        }
    }
    return light;
}

std::string resolved_materials_name(const TetMesh& mesh, const std::optional<TetMaterial>& override) {
    if (override) return material_label(*override);
    return mesh.has_materials() ? "stored" : "marble";
}

std::vector<TetMaterial> resolve_materials(const TetMesh& mesh, const std::optional<TetMaterial>& override) {
    if (override) {
        validate_material(*override);
        return std::vector<TetMaterial>(mesh.tet_count(), *override);
    }
    if (!mesh.has_materials()) return std::vector<TetMaterial>(mesh.tet_count(), material_preset("marble"));
    if (mesh.materials.size() != mesh.tet_count()) {
        throw InvalidArgumentError("the volume stores " + std::to_string(mesh.materials.size()) + " materials for " +
                                   std::to_string(mesh.tet_count()) + " tets");
    }
    // Painted volumes hold few distinct materials in long runs: validate each run once.
    for (size_t t = 0; t < mesh.materials.size(); ++t) {
        if (t == 0 || !(mesh.materials[t] == mesh.materials[t - 1]))
            validate_material(mesh.materials[t], "stored material of tet " + std::to_string(t));
    }
    return mesh.materials;
}

bool point_inside_volume(const TetMesh& mesh, const Eigen::Vector3d& point) {
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    for (const Tet& tet : mesh.tets) {
        const Eigen::Vector3d &a = world[tet[0]], &b = world[tet[1]], &c = world[tet[2]], &d = world[tet[3]];
        // The tet's box first: far from the tet the sub-volumes below are differences of huge
        // products, whose rounding exceeds any tolerance relative to the tet (a light at 1e8 passed
        // the signs of a unit cube's tets).
        const Eigen::Vector3d lo = a.cwiseMin(b).cwiseMin(c).cwiseMin(d), hi = a.cwiseMax(b).cwiseMax(c).cwiseMax(d);
        const double margin = 1e-9 * (hi - lo).maxCoeff();
        if ((point.array() < lo.array() - margin).any() || (point.array() > hi.array() + margin).any()) continue;
        const double volume = signed_volume(a, b, c, d);
        // Barycentric signs with a relative tolerance, so a point on a shared face counts.
        const double tolerance = -1e-12 * std::abs(volume);
        if (signed_volume(point, b, c, d) >= tolerance && signed_volume(a, point, c, d) >= tolerance &&
            signed_volume(a, b, point, d) >= tolerance && signed_volume(a, b, c, point) >= tolerance)
            return true;
    }
    return false;
}

SolvedScene solve_scene(const TetMesh& mesh, const TetConnectivity& connectivity,
                        const std::vector<TetMaterial>& materials, const Lighting& lighting,
                        const DiffusionOptions& options, double crease_angle_degrees) {
    SolvedScene scene;
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
    const std::vector<CornerLight> corners =
        corner_light(scene.surface, scene.shading, scene.shading_light.q, surface_source_q);
    scene.q = to_volume_vertices(scene.surface, surface_source_q, mesh.vertex_count());
    scene.lighting_ms = milliseconds_since(lighting_start);

    scene.diffusion = solve_diffusion(mesh, connectivity, materials, scene.q, options, corners);
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
    return scene;
}

float automatic_exposure(const SurfaceRenderInput& input) {
    if (input.positions.empty()) return 1.0f;
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3f& p : input.positions) box.extend(p.cast<double>());
    const CameraFrame frame = frame_camera(box, input.camera, static_cast<double>(input.width) / input.height);
    std::vector<double> luminance;
    luminance.reserve(input.positions.size());
    for (size_t i = 0; i < input.positions.size(); ++i) {
        const Eigen::Vector3d to_eye = frame.eye - input.positions[i].cast<double>();
        const double cos_view = input.normals[i].cast<double>().dot(to_eye.normalized());
        if (!(cos_view > 0)) continue;  // facing away: the camera cannot see it
        const double eta = input.eta.empty() ? input.uniform_eta : input.eta[i];
        const double transmittance = fresnel_transmittance(cos_view, eta);
        const auto& e = input.radiance_factor[i];
        luminance.push_back(transmittance * (0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2]));
    }
    if (luminance.empty()) return 1.0f;
    const auto nth = luminance.begin() + static_cast<std::ptrdiff_t>(kExposurePercentile * (luminance.size() - 1));
    std::nth_element(luminance.begin(), nth, luminance.end());
    const double reference = *nth;
    if (!(reference > 0) || !std::isfinite(reference)) return 1.0f;
    const double exposure = kExposureTarget / reference;
    return std::isfinite(exposure) ? static_cast<float>(std::min(exposure, 1e30)) : 1.0f;
}

SurfaceRenderInput make_render_input(const TetMesh& mesh, const SolvedScene& scene, const Lighting& lighting,
                                     const ImageSettings& settings,
                                     const std::vector<std::array<float, 3>>* shading_radiance) {
    const BoundarySurface& surface = scene.surface;
    const ShadingSurface& shading = scene.shading;
    SurfaceRenderInput input;
    const size_t n = shading.size();
    const std::vector<std::array<float, 3>>& radiance = shading_radiance ? *shading_radiance : scene.radiance_factor;
    if (radiance.size() != n || shading.normals.size() != n)
        throw InvalidArgumentError("render input: " + std::to_string(radiance.size()) + " radiance values for " +
                                   std::to_string(n) + " shading vertices");
    input.positions.resize(n);
    input.normals.resize(n);
    input.radiance_factor = radiance;
    input.eta.resize(n);
    for (size_t d = 0; d < n; ++d) {
        const int32_t s = shading.surface_vertex[d];
        input.positions[d] = surface.positions[s].cast<float>();
        input.normals[d] = shading.normals[d].cast<float>();
        input.eta[d] = static_cast<float>(surface.eta[s]);
    }
    input.triangles = shading.triangles;
    // Highlights: the same lights as the subsurface term, minus point lights inside the volume (they
    // reach no surface from outside), each shadowed by the visibility its shadow rays found.
    input.lighting.ambient = lighting.ambient;
    input.lighting.shadows = lighting.shadows;
    std::vector<size_t> kept;  // index into lighting.lights of each drawn light
    for (size_t l = 0; l < lighting.lights.size(); ++l) {
        const Light& light = lighting.lights[l];
        if (input.lighting.lights.size() == static_cast<size_t>(kMaxRenderLights)) break;
        if (light.type == LightType::Point && point_inside_volume(mesh, light.vector)) continue;
        input.lighting.lights.push_back(light);
        kept.push_back(l);
    }
    const size_t solved_lights = lighting.lights.size();
    const std::vector<float>& visibility = scene.shading_light.visibility;
    if (!kept.empty() && visibility.size() == n * solved_lights) {
        input.light_visibility.resize(n * kept.size());
        for (size_t d = 0; d < n; ++d)
            for (size_t k = 0; k < kept.size(); ++k)
                input.light_visibility[d * kept.size() + k] = visibility[d * solved_lights + kept[k]];
    }
    input.width = settings.width;
    input.height = settings.height;
    input.camera = settings.camera;
    input.exposure = settings.exposure ? *settings.exposure : automatic_exposure(input);
    return input;
}

Image render_scene(SurfaceRenderer& renderer, const SurfaceRenderInput& input) { return renderer.render(input); }

void write_fields_csv(const std::filesystem::path& path, const TetMesh& mesh, const TetConnectivity& connectivity,
                      const SolvedScene& scene) {
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    // eta per volume vertex, from the surface (the value q and E were computed with).
    std::vector<double> eta(mesh.vertex_count(), 1.0);
    for (size_t s = 0; s < scene.surface.vertices.size(); ++s) eta[scene.surface.vertices[s]] = scene.surface.eta[s];
    write_file_atomically(path, [&](std::ostream& out) {
        out << "x,y,z,boundary,q_r,q_g,q_b,phi_r,phi_g,phi_b,lo_r,lo_g,lo_b\n";
        out << std::setprecision(9);
        for (size_t v = 0; v < mesh.vertex_count(); ++v) {
            const bool boundary = connectivity.is_boundary_vertex[v] != 0;
            const Rgb& q = scene.q[v];
            const auto& phi = scene.diffusion.phi[v];
            // lo: exitant_radiance along the vertex's (averaged) normal, from the q the solve used (at a
            // crease, its sides' light weighed by their areas; the image shades each side with its own).
            double lo[3] = {0, 0, 0};
            if (boundary)
                for (int c = 0; c < 3; ++c) lo[c] = exitant_radiance(phi[c], q[c], eta[v], 1.0);
            out << world[v].x() << ',' << world[v].y() << ',' << world[v].z() << ',' << (boundary ? 1 : 0);
            for (int c = 0; c < 3; ++c) out << ',' << (boundary ? q[c] : 0.0);
            for (int c = 0; c < 3; ++c) out << ',' << phi[c];
            for (int c = 0; c < 3; ++c) out << ',' << lo[c];
            out << '\n';
        }
    });
}

}  // namespace waxwork
