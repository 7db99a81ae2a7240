// `waxwork export VOLUME -o OUT.{ply,obj,stl}`: the boundary surface of a (carved, fractured) volume
// for other programs, with `--radiance` its exitant radiance, lit as `render` lights it, baked as
// sRGB vertex colours.
#include "app/commands.h"
#include "app/options/help_sections.h"
#include "app/options/scene_light_options.h"
#include "app/stderr_progress.h"
#include "base/error.h"
#include "base/timing.h"
#include "io/surface_writer.h"
#include "io/volume_file.h"
#include "render/volume_render.h"
#include "scene/surface_export.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

namespace waxwork {
namespace {

struct ExportCommandOptions {
    std::string volume;
    std::string output;
    bool radiance = false;
    std::string pieces = "merged";
    SceneLightOptions light;
};

// Everything that can be refused without reading the volume is refused before any work.
void check_options(const ExportCommandOptions& o) {
    const SurfaceFormat format = surface_format(o.output);
    if (o.radiance && !stores_vertex_colours(format))
        throw InvalidArgumentError("-o " + o.output +
                                   ": --radiance needs vertex colours, which STL has no standard for; write .ply or .obj");
    check_scene_light_options(o.light);
}

void run_export_command(const ExportCommandOptions& o) {
    const auto start = std::chrono::steady_clock::now();
    check_options(o);
    const ShellGrouping grouping = o.pieces == "separate" ? ShellGrouping::Separate : ShellGrouping::Merged;

    StderrProgress progress("waxwork: " + o.volume + ": ");
    progress.set_stage("reading");
    const VolumeFile file = read_volume_file(o.volume);
    const TetMesh& mesh = file.mesh;
    const ModelScale scale = chosen_scale(o.light, file);
    const VolumeRenderSettings settings = scene_light_settings(o.light, scale);
    if (mesh.tet_count() == 0) throw InvalidArgumentError(o.volume + ": the volume has no tets to export");

    std::optional<VolumeLight> light;
    TetConnectivity connectivity;
    if (o.radiance) {
        progress.set_stage("solving the light");
        light = solve_volume_light(mesh, o.volume, settings);
        report_solve_warnings(o.volume, light->scene);
    } else {
        connectivity = build_connectivity(mesh);
    }
    const TetConnectivity& used = light ? light->connectivity : connectivity;
    progress.set_stage("writing " + o.output);
    const SurfaceExport surface = surface_export(mesh, used, grouping, light ? &light->scene : nullptr);
    write_surface(o.output, surface.shells, surface.colours);
    progress.finish();
    if (o.radiance) report_chosen_scale(o.volume, scale, mesh);

    nlohmann::ordered_json summary = {
        {"output", o.output},
        {"tets", mesh.tet_count()},
        {"pieces", o.pieces},
        {"shells", surface.shells.shell_count()},
        {"vertices", surface.shells.positions.size()},
        {"triangles", surface.shells.triangles.size()},
        {"radiance", o.radiance},
    };
    if (light) {
        const DiffusionSolution& s = light->scene.diffusion;
        summary["materials"] = settings.material ? "option" : mesh.has_materials() ? "stored" : "marble default";
        summary["method"] = o.light.method;
        summary["backend"] = s.backend == SolverBackend::Gpu ? "gpu" : "cpu";
        summary["mm_per_unit"] = scale.mm_per_unit;
        summary["scale_source"] = scale_source_name(scale.source);
        summary["lights"] = settings.lighting.lights.size();
        add_solve_summary(summary, light->scene);
    }
    summary["milliseconds"] = milliseconds_since(start);
    std::cout << summary.dump() << "\n";
}

}  // namespace

void add_export_command(CLI::App& app) {
    auto options = std::make_shared<ExportCommandOptions>();
    CLI::App* cmd = app.add_subcommand("export", "Write the boundary surface of a volume (.ply, .obj, .stl)");
    cmd->add_option("volume", options->volume, "Volume file (.vtu, .msh, .mesh, .node/.ele)")->required();
    cmd->add_option("-o,--output", options->output, "Surface to write: .ply (binary), .obj or .stl (binary)")
        ->required();
    cmd->add_flag("--radiance", options->radiance,
                  "Solve the light as `render` does and bake the exitant radiance as sRGB vertex colours "
                  "(.ply and .obj)");
    cmd->add_option("--pieces", options->pieces,
                    "merged: one surface, vertices shared as the tets share them; separate: one closed shell "
                    "per face-connected part (OBJ: one `o` per part), sharing no vertices")
        ->check(CLI::IsMember({"merged", "separate"}))
        ->capture_default_str();
    add_scene_light_options(*cmd, options->light);
    cmd->footer(
        "Coordinates are the volume's world coordinates in model units (--scale is not applied to them).\n"
        "Faces are outward (counter-clockwise seen from outside). With --radiance each vertex gets the\n"
        "exitant radiance `render --fields` lists as lo, clamped to [0, 1] and sRGB-encoded as the\n"
        "renderer encodes (no exposure or tone mapping); the light options are render's.");
    organise_help(*cmd, "waxwork export spot.vtu -o spot.ply --radiance", {});
    cmd->callback([options] { run_export_command(*options); });
}

}  // namespace waxwork
