#include "bench/studies/resolution_study.h"

#include "base/error.h"
#include "io/surface_reader.h"
#include "render/render_input.h"
#include "render/surface_renderer.h"
#include "solver/light_spec.h"
#include "solver/material.h"
#include "solver/mesh_resolution.h"
#include "solver/solved_scene.h"
#include "tetops/connectivity.h"
#include "tetops/tetrahedralize.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace waxwork {
namespace {

double srgb_to_linear(uint8_t value) {
    const double c = value / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

struct Scene {
    TetMesh mesh;
    TetConnectivity connectivity;
    std::vector<TetMaterial> materials;
    double meshing_ms = 0;
};

Scene mesh_scene(const TriangleSurface& surface, const TetMaterial& material, double mm_per_unit, double factor) {
    MeshingOptions meshing;
    meshing.sizing = default_mesh_sizing(surface, material, mm_per_unit, {.size_factor = factor});
    MeshingResult result = tetrahedralize(surface, meshing);
    Scene scene;
    scene.mesh = std::move(result.mesh);
    scene.meshing_ms = result.milliseconds;
    scene.connectivity = build_connectivity(scene.mesh);
    scene.materials.assign(scene.mesh.tet_count(), material);
    return scene;
}

}  // namespace

double relative_image_error(const Image& image, const Image& reference, const std::array<uint8_t, 3>& background) {
    if (image.width != reference.width || image.height != reference.height)
        throw InvalidArgumentError("image comparison: the images differ in size");
    double difference = 0, total = 0;
    for (int y = 0; y < reference.height; ++y)
        for (int x = 0; x < reference.width; ++x) {
            const uint8_t* r = reference.pixel(x, y);
            if (r[0] == background[0] && r[1] == background[1] && r[2] == background[2]) continue;
            const uint8_t* p = image.pixel(x, y);
            for (int c = 0; c < 3; ++c) {
                const double expected = srgb_to_linear(r[c]);
                difference += std::abs(srgb_to_linear(p[c]) - expected);
                total += expected;
            }
        }
    return total > 0 ? difference / total : 0.0;
}

nlohmann::ordered_json ResolutionStudy::to_json() const {
    nlohmann::ordered_json out;
    out["reference_tets"] = reference_tets;
    out["recommended"] = recommended;
    out["shipped_default"] = shipped_default;
    auto& rows = out["samples"] = nlohmann::ordered_json::array();
    for (const ResolutionSample& s : samples)
        rows.push_back({{"size_factor", s.size_factor},
                        {"tolerance", s.tolerance},
                        {"tets", s.tets},
                        {"meshing_ms", s.meshing_ms},
                        {"solve_ms", s.solve_ms},
                        {"iterations", s.iterations},
                        {"image_error", s.image_error}});
    return out;
}

ResolutionStudy run_resolution_study(const ResolutionStudyOptions& options) {
    if (options.size_factors.empty() || options.tolerances.empty())
        throw InvalidArgumentError("resolution study: needs at least one size factor and one tolerance");
    for (double f : options.size_factors)
        if (!(f > 0) || !std::isfinite(f)) throw InvalidArgumentError("resolution study: size factors must be positive");
    for (double t : options.tolerances)
        if (!(t > 0 && t < 1)) throw InvalidArgumentError("resolution study: tolerances must be in (0, 1)");
    if (!(options.reference_size_factor > 0) || !(options.reference_tolerance > 0 && options.reference_tolerance < 1))
        throw InvalidArgumentError("resolution study: bad reference size factor or tolerance");

    const TetMaterial material = material_preset(options.material);
    const TriangleSurface surface = load_closed_surface(options.surface).surface;
    Lighting lighting;
    lighting.lights.push_back(default_key_light());

    HeadlessGlContext context;
    SurfaceRenderer renderer(context.gl());
    ImageSettings image_settings;
    image_settings.width = options.width;
    image_settings.height = options.height;

    auto solve = [&](const Scene& scene, double tolerance, ResolutionSample* sample) {
        DiffusionOptions diffusion;
        diffusion.mm_per_unit = options.mm_per_unit;
        diffusion.relative_tolerance = tolerance;
        const SolvedScene solved = solve_scene(scene.mesh, scene.connectivity, scene.materials, lighting, diffusion);
        if (sample) {
            sample->solve_ms = solved.diffusion.assembly_ms + solved.diffusion.solve_ms;
            sample->iterations = *std::max_element(solved.diffusion.iterations.begin(), solved.diffusion.iterations.end());
        }
        return make_render_input(scene.mesh, solved, lighting, image_settings);
    };

    ResolutionStudy study;
    const Scene reference_scene = mesh_scene(surface, material, options.mm_per_unit, options.reference_size_factor);
    study.reference_tets = reference_scene.mesh.tet_count();
    const SurfaceRenderInput reference_input = solve(reference_scene, options.reference_tolerance, nullptr);
    // Every image uses the reference's exposure: automatic exposure would hide brightness errors.
    image_settings.exposure = reference_input.exposure;
    const Image reference = render_scene(renderer, reference_input);

    for (double factor : options.size_factors) {
        const Scene scene = mesh_scene(surface, material, options.mm_per_unit, factor);
        for (double tolerance : options.tolerances) {
            ResolutionSample sample;
            sample.size_factor = factor;
            sample.tolerance = tolerance;
            sample.tets = scene.mesh.tet_count();
            sample.meshing_ms = scene.meshing_ms;
            const Image image = render_scene(renderer, solve(scene, tolerance, &sample));
            sample.image_error = relative_image_error(image, reference, reference_input.background);
            study.samples.push_back(sample);
        }
    }
    for (size_t i = 0; i < study.samples.size(); ++i) {
        const ResolutionSample& s = study.samples[i];
        if (s.size_factor == 1.0 && s.tolerance == 1e-3) study.shipped_default = static_cast<int>(i);
        if (s.image_error <= options.error_bound &&
            (study.recommended < 0 || s.solve_ms < study.samples[static_cast<size_t>(study.recommended)].solve_ms))
            study.recommended = static_cast<int>(i);
    }
    return study;
}

}  // namespace waxwork
