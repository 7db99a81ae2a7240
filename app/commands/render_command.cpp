// `waxwork render VOLUME -o IMAGE.png`: a volume, its materials and lights -> diffusion -> a PNG.
#include "app/commands.h"
#include "app/options/scene_light_options.h"
#include "base/error.h"
#include "io/file_extension.h"
#include "io/volume_file.h"
#include "render/render_input.h"
#include "render/view_modes.h"
#include "render/volume_render.h"
#include "scene/fields_csv.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "solver/solved_scene.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <iostream>
#include <memory>
#include <optional>

namespace waxwork {
namespace {

struct RenderCommandOptions {
    std::string volume;
    std::string output;
    SceneLightOptions light;
    int width = 800;
    int height = 600;
    std::string fields;
    std::vector<double> view;
    std::optional<double> exposure;
    std::string show = "radiance";
    std::string slice_normal;
    double slice_offset = 0;
    bool quality_interior = false;
};

// The view --show asks for, checked before any work.
ViewOptions view_options(const RenderCommandOptions& o) {
    ViewOptions view;
    view.mode = parse_view_mode(o.show);
    if (!o.slice_normal.empty()) view.slice_normal = parse_slice_normal(o.slice_normal);
    view.slice_offset = o.slice_offset;
    view.quality_interior = o.quality_interior;
    validate(view);
    return view;
}

void check_options(const RenderCommandOptions& o) {
    auto fail = [](const std::string& what) { throw InvalidArgumentError(what); };
    if (o.width <= 0 || o.height <= 0 || o.width > kMaxImageSide || o.height > kMaxImageSide) {
        fail("--width/--height must be between 1 and " + std::to_string(kMaxImageSide) + " (got " +
             std::to_string(o.width) + "x" + std::to_string(o.height) + ")");
    }
    check_scene_light_options(o.light);
    if (lower_extension(o.output) != ".png") fail("-o " + o.output + ": the image must be a .png");
    // The renderer exposes in float: beyond 1e30 the product with the radiance leaves its range.
    if (o.exposure && !(*o.exposure > 0 && *o.exposure <= 1e30)) fail("--exposure must be positive and at most 1e30");
    if (!o.view.empty()) {
        const Eigen::Vector3d v(o.view[0], o.view[1], o.view[2]);
        if (!v.allFinite() || v.norm() == 0) fail("--view must be a finite, non-zero direction");
    }
}

// The camera's up vector is +y; a view straight along y would leave it undefined, so use -z then.
CameraSettings camera_for_view(const std::vector<double>& view) {
    CameraSettings camera;
    if (view.empty()) return camera;
    camera.eye_direction = Eigen::Vector3d(view[0], view[1], view[2]);
    // Scaled first: the norm of 1e308-sized components overflows.
    camera.eye_direction /= camera.eye_direction.cwiseAbs().maxCoeff();
    if (camera.eye_direction.normalized().cross(camera.up).norm() < 1e-3) camera.up = Eigen::Vector3d(0, 0, -1);
    return camera;
}

void run_render_command(const RenderCommandOptions& o) {
    check_options(o);
    const ViewOptions view = view_options(o);
    const VolumeFile file = read_volume_file(o.volume);
    const TetMesh& mesh = file.mesh;
    const ModelScale scale = chosen_scale(o.light, file);
    VolumeRenderSettings settings = scene_light_settings(o.light, scale);
    const Lighting& lighting = settings.lighting;
    const std::optional<TetMaterial>& chosen = settings.material;
    settings.image.width = o.width;
    settings.image.height = o.height;
    settings.image.camera = camera_for_view(o.view);
    if (o.exposure) settings.image.exposure = static_cast<float>(*o.exposure);
    settings.view = view;

    const VolumeRender render = render_volume(mesh, o.volume, settings);
    const SolvedScene& scene = render.scene;
    if (!scene.diffusion.gpu_fallback_reason.empty())
        std::cerr << "warning: solving on the CPU instead: " << scene.diffusion.gpu_fallback_reason << "\n";
    write_png(render.image, o.output);
    report_chosen_scale(o.volume, scale, mesh);
    if (!o.fields.empty()) write_fields_csv(o.fields, mesh, render.connectivity, scene);

    const DiffusionSolution& s = scene.diffusion;
    nlohmann::ordered_json summary = {
        {"output", o.output},
        {"vertices", mesh.vertex_count()},
        {"tets", mesh.tet_count()},
        {"materials", chosen ? "option" : mesh.has_materials() ? "stored" : "marble default"},
        {"method", o.light.method},
        {"backend", s.backend == SolverBackend::Gpu ? "gpu" : "cpu"},
        {"mm_per_unit", scale.mm_per_unit},
        {"scale_source", scale_source_name(scale.source)},
        {"lights", lighting.lights.size()},
        {"lights_inside", render.lights_inside},
        {"iterations", s.iterations},
        {"estimated_error", s.estimated_relative_error},
        {"exposure", render.exposure},
        {"crease_angle_deg", o.light.crease_angle},
        {"shading_copies", scene.shading.size() - scene.surface.vertices.size()},
        {"lighting_ms", scene.lighting_ms},
        {"assembly_ms", s.assembly_ms},
        {"solve_ms", s.solve_ms},
        {"render_ms", render.render_ms},
        {"view", view_mode_name(view.mode)},
    };
    if (view.mode != ViewMode::Radiance) summary["legend"] = render.view.legend.title;
    if (!o.fields.empty()) summary["fields"] = o.fields;
    std::cout << summary.dump() << "\n";
}

}  // namespace

void add_render_command(CLI::App& app) {
    auto options = std::make_shared<RenderCommandOptions>();
    CLI::App* cmd = app.add_subcommand("render", "Solve the light diffusion in a volume and render a PNG");
    cmd->add_option("volume", options->volume, "Volume file (.vtu, .msh, .mesh, .node/.ele)")->required();
    cmd->add_option("-o,--output", options->output, "PNG image to write")->required();
    add_scene_light_options(*cmd, options->light);
    cmd->add_option("--width", options->width, "Image width in pixels")->capture_default_str();
    cmd->add_option("--height", options->height, "Image height in pixels")->capture_default_str();
    cmd->add_option("--fields", options->fields, "Also write q, phi and exitant radiance per vertex to this CSV");
    cmd->add_option("--view", options->view, "Direction from the object towards the camera, X,Y,Z")
        ->delimiter(',')
        ->expected(3);
    cmd->add_option("--exposure", options->exposure, "Fixed exposure (default: automatic)");
    cmd->add_option("--show", options->show,
                    "What to draw: radiance (the image), materials, quality (min dihedral angle), wireframe (tet "
                    "edges), slice (fluence on a plane), levels (multires hierarchy)")
        ->capture_default_str();
    cmd->add_option("--slice-normal", options->slice_normal,
                    "--show slice: X,Y,Z, the plane's normal, pointing at the half cut away (default 0,0,1)");
    cmd->add_option("--slice-offset", options->slice_offset,
                    "--show slice: the plane's offset from the centre, in [-1, 1] half extents along the normal")
        ->capture_default_str();
    cmd->add_flag("--quality-interior", options->quality_interior,
                  "--show quality: also cut at the slice plane and colour the cross-section's tets");
    cmd->footer(
        "Without --light a white key light shines from the upper front-left: dir:1,-1,-1 (y up, front +z).\n"
        "Without a material option the volume's stored per-tet materials are used, else marble.\n"
        "Shadows are cast by the whole volume; a point light, or a sphere light centred, inside the object\n"
        "lights nothing (counted in the summary's lights_inside); area lights cast soft shadows. Exposure is automatic: the 95th percentile of the luminance of the\n"
        "subsurface radiance at camera-facing boundary vertices maps to 0.6 before ACES tone mapping;\n"
        "--exposure sets the multiplier instead. The summary (one JSON line) reports it.");
    cmd->callback([options] { run_render_command(*options); });
}

}  // namespace waxwork
