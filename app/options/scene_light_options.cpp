#include "app/options/scene_light_options.h"

#include "base/error.h"
#include "scene/environment_loading.h"
#include "solver/conjugate_gradient.h"
#include "solver/light_spec.h"
#include "solver/material.h"
#include "solver/methods/alternative_method.h"

#include <CLI/CLI.hpp>

#include <iostream>

namespace waxwork {

namespace {
// A voxel of a kilometre lights nothing; the grid methods cap their voxel count themselves.
constexpr double kMaxCellMm = 1e6;
}  // namespace

void add_scene_light_options(CLI::App& command, SceneLightOptions& options, bool monte_carlo) {
    add_material_options(command, options.material);
    command
        .add_option("--light", options.lights,
                    "dir:X,Y,Z[:R,G,B] (direction of travel), point:X,Y,Z[:R,G,B] (position, model units), or an "
                    "area light with soft shadows: rect:CX,CY,CZ:NX,NY,NZ:W,H[:R,G,B] (centre, emitting normal, "
                    "width along +x projected onto it, height), disk:CX,CY,CZ:NX,NY,NZ:RADIUS[:R,G,B] or "
                    "sphere:CX,CY,CZ:RADIUS[:R,G,B] (intensity: radiant intensity along the normal, as a point "
                    "light's); repeatable; intensity 1,1,1 by default")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    command.add_option("--env", options.environment,
                       "Environment light: FILE.hdr[:ROT_DEG[:INTENSITY]] (equirectangular Radiance image, rotated "
                       "about +y) or sky:SUN_ELEV_DEG,SUN_AZIM_DEG[,TURBIDITY][:ROT_DEG[:INTENSITY]] (a clear sky "
                       "with its sun; azimuth from +z towards +x); replaces the default key light and ambient");
    command.add_flag("--no-env-background", options.hide_environment,
                     "Draw the background colour behind the model instead of the environment (it still lights and "
                     "is reflected)");
    std::vector<std::string> methods = {"transcut", "fem"};
    for (AlternativeMethod method : all_alternative_methods()) methods.push_back(alternative_method_name(method));
    if (monte_carlo) methods.push_back("mc");
    command
        .add_option("--method", options.method,
                    std::string("Discretisation: transcut (lumped, Li et al.) or fem (consistent mass); or one of the "
                                "seeds' methods for the same light (docs/methods.md): fd, fd-cg (finite differences "
                                "on a voxel grid, Jacobi or CG), fvm, fvm-cg (finite volumes on Voronoi cells, "
                                "relaxation or CG), lbm (lattice Boltzmann on voxels), dipole (surface-only dipole "
                                "profiles)") +
                        (monte_carlo ? "; or mc: a Monte Carlo path tracer through the volume (the physical "
                                       "reference; see --mc-seconds)"
                                     : ""))
        ->check(CLI::IsMember(methods))
        ->capture_default_str();
    command.add_option("--tol", options.tolerance,
                       "Relative tolerance of the diffusion solve (default 1e-2 for transcut and fem, 1e-4 for the "
                       "seeds' methods)");
    command.add_option("--cell", options.cell_mm,
                       "--method fd, fd-cg, lbm: the voxel size in mm (default: as many voxels as the volume has "
                       "vertices)");
    command
        .add_option("--backend", options.backend,
                    "Diffusion solver: cpu, or gpu (float CG on OpenGL 4.3 compute shaders in the render context; "
                    "falls back to the CPU with a warning when the driver cannot run it, and finishes in double on "
                    "the CPU when float cannot reach --tol)")
        ->check(CLI::IsMember({"cpu", "gpu"}))
        ->capture_default_str();
    command.add_option("--scale", options.scale,
                       "Millimetres per model unit (coefficients are per mm; default: the scale stored in the volume, "
                       "else the bounding-box diagonal about 75 mm)");
    command.add_option("--ambient", options.ambient,
                       "Ambient irradiance added to every boundary vertex (default 0.02, 0 under --env)");
    command
        .add_option("--crease-angle", options.crease_angle,
                    "Shade and light the surface as folded where neighbouring triangles turn by more than "
                    "this many degrees (box edges, cut rims); 180 uses one averaged normal per vertex")
        ->capture_default_str();
}

void check_scene_light_options(const SceneLightOptions& o) {
    auto fail = [](const std::string& what) { throw InvalidArgumentError(what); };
    if (o.scale) validate_mm_per_unit(*o.scale, "--scale");
    if (o.tolerance && !(*o.tolerance >= kMinRelativeTolerance && *o.tolerance < 1))
        fail("--tol must be a relative tolerance in [1e-15, 1)");
    const std::optional<AlternativeMethod> alternative = parse_alternative_method(o.method);
    if (o.cell_mm && !(alternative && uses_voxel_grid(*alternative)))
        fail("--cell applies only to the grid methods (--method fd, fd-cg or lbm)");
    if (o.cell_mm && !(*o.cell_mm > 0 && *o.cell_mm <= kMaxCellMm))
        fail("--cell must be a voxel size in mm in (0, 1e6]");
    if (alternative && o.backend == "gpu")
        fail(std::string("--backend gpu applies to transcut and fem; --method ") + o.method + " runs on the CPU");
    if (o.ambient && !(*o.ambient >= 0 && *o.ambient <= kMaxLightIntensity))
        fail("--ambient must be non-negative and at most 1e15");
    if (!o.environment.empty()) parse_environment_spec(o.environment);
    if (o.hide_environment && o.environment.empty()) fail("--no-env-background needs --env");
    if (!is_crease_angle(o.crease_angle)) fail("--crease-angle must be between 0 and 180 degrees");
}

Lighting chosen_lighting(const SceneLightOptions& o) {
    Lighting lighting;
    for (const std::string& spec : o.lights) lighting.lights.push_back(parse_light_spec(spec));
    if (!o.environment.empty()) {
        lighting.environment = load_environment(parse_environment_spec(o.environment));
        lighting.environment->background = !o.hide_environment;
    }
    if (lighting.lights.empty() && !lighting.environment) lighting.lights.push_back(default_key_light());
    const double ambient = o.ambient.value_or(lighting.environment ? 0.0 : kDefaultAmbient);
    lighting.ambient = {ambient, ambient, ambient};
    return lighting;
}

VolumeRenderSettings scene_light_settings(const SceneLightOptions& o, const ModelScale& scale) {
    VolumeRenderSettings settings;
    settings.lighting = chosen_lighting(o);
    settings.material = chosen_material(o.material);
    settings.diffusion.discretization = o.method == "fem" ? Discretization::Fem : Discretization::TransCut;
    settings.diffusion.mm_per_unit = scale.mm_per_unit;
    settings.diffusion.relative_tolerance = o.tolerance.value_or(kTransCutTolerance);
    if (const std::optional<AlternativeMethod> method = parse_alternative_method(o.method)) {
        AlternativeMethodSettings alternative;
        alternative.method = *method;
        alternative.cell_mm = o.cell_mm.value_or(0.0);
        alternative.relative_tolerance = o.tolerance.value_or(kAlternativeTolerance);
        settings.alternative = alternative;
    }
    if (o.backend == "gpu") settings.diffusion.backend = SolverBackend::Gpu;
    settings.crease_angle_degrees = o.crease_angle;
    return settings;
}

ModelScale chosen_scale(const SceneLightOptions& o, const VolumeFile& file) {
    return choose_model_scale(o.scale, file.metadata.mm_per_unit, bounding_extent(file.mesh.positions));
}

void report_chosen_scale(const std::string& file, const ModelScale& scale, const TetMesh& mesh) {
    if (scale.source == ScaleSource::ModelSize)
        std::cerr << "waxwork: " << file << ": scale: " << describe_model_scale(scale, bounding_extent(mesh.positions))
                  << "\n";
}

void report_solve_warnings(const std::string& file, const SolvedScene& scene) {
    if (!scene.diffusion.gpu_fallback_reason.empty())
        std::cerr << "warning: " << file << ": solving on the CPU instead: " << scene.diffusion.gpu_fallback_reason << "\n";
    if (scene.alternative)
        for (const std::string& warning : scene.alternative->warnings) std::cerr << "warning: " << file << ": " << warning << "\n";
}

void add_solve_summary(nlohmann::ordered_json& summary, const SolvedScene& scene) {
    summary["iterations"] = scene.diffusion.iterations;
    if (!scene.alternative) {
        summary["estimated_error"] = scene.diffusion.estimated_relative_error;
        return;
    }
    const MethodSolution& m = *scene.alternative;
    summary["alternative"] = {{"unknowns", m.unknowns},
                              {"setup_ms", m.setup_ms},
                              {"solve_ms", m.solve_ms},
                              {"warnings", m.warnings}};
}

}  // namespace waxwork
