#include "render/render_input.h"
#include "solver/solved_scene.h"

#include "base/error.h"
#include "solver/material.h"
#include "solver/radiance.h"
#include "tetops/cut.h"
#include "tetops/point_location.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace waxwork {

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
    // Highlights: the same lights as the subsurface term, minus point lights and sphere lights centred
    // inside the volume (they reach no surface from outside, or a sphere only where it pokes out, which
    // a highlight from its centre would not show), each shadowed by the visibility its shadow rays found
    // (for an area light, the visible fraction of its samples).
    input.lighting.ambient = lighting.ambient;
    input.lighting.shadows = lighting.shadows;
    // The sky's sun is one of them (direct_lights); the environment itself is reflected by its
    // prefiltered map and drawn behind the model when its `background` is set.
    input.lighting.environment = lighting.environment;
    const std::vector<Light> lights = direct_lights(lighting);
    std::vector<size_t> kept;  // index into lights of each drawn light
    for (size_t l = 0; l < lights.size(); ++l) {
        const Light& light = lights[l];
        if (input.lighting.lights.size() == static_cast<size_t>(kMaxRenderLights)) break;
        if (radiates_from_centre(light.type) && point_inside_volume(mesh, light.vector)) continue;
        input.lighting.lights.push_back(light);
        kept.push_back(l);
    }
    const size_t solved_lights = lights.size();
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

}  // namespace waxwork
