// `waxwork edit [FILE]`: opens the interactive editor (editor/editor_app.h). With --screenshot it draws
// --frames frames once loading and solving have finished, saves the window (UI included unless
// --hide-ui) as a PNG and exits: for the docs and the tests, under xvfb-run on a server.
#include "app/commands.h"
#include "app/options/help_sections.h"
#include "app/options/live_solver_options.h"
#include "app/options/material_options.h"
#include "app/options/surface_meshing_options.h"
#include "base/error.h"
#include "editor/editor_app.h"
#include "solver/material.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <iostream>
#include <memory>

namespace waxwork {
namespace {

// The editor's own options are bound to `editor` directly; the rest are text parsed into it.
struct EditCommandOptions {
    EditorOptions editor;
    std::string input;
    MaterialOptions material;
    std::vector<std::string> lights;
    std::vector<double> view;
    std::string show = "radiance";
    std::string slice_normal;
    LiveSolverChoice solver;
    SurfaceMeshingOptions meshing;
};

void run_edit_command(const EditCommandOptions& o) {
    EditorOptions options = o.editor;
    if (options.width < 64 || options.height < 64 || options.width > kMaxImageSide || options.height > kMaxImageSide)
        throw InvalidArgumentError("--width/--height must be between 64 and " + std::to_string(kMaxImageSide));
    if (options.frames < 1 || options.frames > 100000)
        throw InvalidArgumentError("--frames must be between 1 and 100000");
    if (options.scale) validate_mm_per_unit(*options.scale, "--scale");
    if (!(options.autosave_seconds >= 1 && options.autosave_seconds <= 86400))
        throw InvalidArgumentError("--autosave must be between 1 and 86400 seconds");
    if (!is_crease_angle(options.crease_angle_degrees))
        throw InvalidArgumentError("--crease-angle must be between 0 and 180 degrees");
    options.view.mode = parse_view_mode(o.show);
    if (!o.slice_normal.empty()) options.view.slice_normal = parse_slice_normal(o.slice_normal);
    validate(options.view);
    const MeshingOptions meshing = meshing_options(o.meshing);
    options.mesher = meshing.mesher;
    options.min_dihedral_deg = meshing.min_dihedral_deg;
    options.max_radius_edge_ratio = meshing.max_radius_edge_ratio;
    options.repair = surface_repair_options(o.meshing);
    options.material = chosen_material(o.material);
    options.solver_backend = parse_live_backend(o.solver.backend);
    options.solver_method = parse_live_method(o.solver.method);
    options.frame_ms = o.solver.frame_ms;
    for (const std::string& spec : o.lights) options.lights.push_back(parse_light_spec(spec));
    // Read before the window opens: a bad script is a one-line error, with or without a display.
    if (!o.input.empty()) options.input = read_input_script(o.input);
    if (!o.view.empty()) {
        const Eigen::Vector3d v(o.view[0], o.view[1], o.view[2]);
        if (!v.allFinite() || v.norm() == 0) throw InvalidArgumentError("--view must be a finite, non-zero direction");
        options.camera.eye_direction = v;
        if (v.normalized().cross(options.camera.up).norm() < 1e-3) options.camera.up = Eigen::Vector3d(0, 0, -1);
    }
    const EditorRunStats stats = run_editor(options);
    if (!options.screenshot.empty()) {
        const nlohmann::ordered_json summary = {
            {"screenshot", options.screenshot.string()},  {"frames", stats.frames},
            {"frame_ms", stats.mean_frame_ms}, {"view_ms", stats.mean_view_ms},
            {"solver_ticks", stats.ticks}, {"tick_ms", stats.tick_ms}, {"tets", stats.tets},
            {"vertices", stats.vertices},  {"mm_per_unit", stats.mm_per_unit},
            {"gl_version", stats.gl_version},
            {"gl_renderer", stats.gl_renderer}, {"solver_backend", stats.solver_backend},
            {"gpu_fallback_reason", stats.gpu_fallback_reason},
            {"method_fallback_reason", stats.method_fallback_reason},
            {"view_reads_device_radiance", stats.view_reads_device_radiance},
            {"script_frames", stats.script_frames},
            {"script_frame_ms", stats.mean_script_frame_ms},
            {"max_script_frame_ms", stats.max_script_frame_ms},
            {"frames_while_tracing", stats.frames_while_tracing},
            {"frame_ms_while_tracing", stats.mean_frame_ms_while_tracing},
            {"max_frame_ms_while_tracing", stats.max_frame_ms_while_tracing},
            {"tick_ms_while_tracing", stats.tick_ms_while_tracing},
            {"modified", stats.modified}, {"title", stats.title},
        };
        std::cout << summary.dump() << "\n";
    }
}

}  // namespace

void add_edit_command(CLI::App& app) {
    auto options = std::make_shared<EditCommandOptions>();
    CLI::App* cmd = app.add_subcommand("edit", "Open the interactive editor (needs a display)");
    cmd->add_option("file", options->editor.file, "Surface (OBJ, OFF, PLY, STL) or volume (VTU, MSH, MESH, NODE) to open")
        ->check(CLI::ExistingFile);
    cmd->add_option("--session", options->editor.session,
                    "Open a session file (as `waxwork run` takes): its input, material, lights and camera, with "
                    "its edits replayed (undoable); File > Save session records yours")
        ->check(CLI::ExistingFile);
    cmd->add_option("--screenshot", options->editor.screenshot,
                    "Draw --frames frames after loading and solving, save the window to this PNG and exit");
    cmd->add_option("--input", options->input,
                    "Replay this JSON list of timed mouse and key events into the window (editor/input_script.h)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--frames", options->editor.frames, "Frames drawn before the screenshot")->capture_default_str();
    cmd->add_option("--autosave", options->editor.autosave_seconds,
                    "Seconds between recovery copies of unsaved edits (in $WAXWORK_STATE_DIR, else "
                    "$XDG_STATE_HOME/waxwork, else ~/.local/state/waxwork)")
        ->capture_default_str();
    cmd->add_flag("--hide-ui", options->editor.hide_ui, "Show the 3D view alone (Tab toggles it)");
    cmd->add_option("--width", options->editor.width, "Window width")->capture_default_str();
    cmd->add_option("--height", options->editor.height, "Window height")->capture_default_str();
    auto* tets = add_max_tets_option(*cmd, options->editor.max_tets, "Meshing a surface: about this many tets");
    cmd->add_option("--edge", options->editor.edge, "Meshing a surface: target edge length in model units")
        ->excludes(tets);
    add_surface_meshing_options(*cmd, options->meshing);
    add_material_options(*cmd, options->material);
    cmd->add_option("--light", options->lights,
                    "dir:X,Y,Z[:R,G,B], point:X,Y,Z[:R,G,B], rect:C:N:W,H[:R,G,B], disk:C:N:RADIUS[:R,G,B] or "
                    "sphere:C:RADIUS[:R,G,B], as for render")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    cmd->add_option("--scale", options->editor.scale,
                    "Millimetres per model unit (default: the volume's stored scale, else the bounding-box "
                    "diagonal about 75 mm)");
    cmd->add_option("--crease-angle", options->editor.crease_angle_degrees,
                    "Shade and light the surface as folded where neighbouring triangles turn by more than "
                    "this many degrees, as for render (a session's own value wins)")
        ->capture_default_str();
    cmd->add_option("--view", options->view, "Direction from the object towards the camera, X,Y,Z")
        ->delimiter(',')
        ->expected(3);
    cmd->add_option("--show", options->show,
                    "What the view shows, as for render: radiance, materials, quality, wireframe, slice, levels")
        ->capture_default_str();
    cmd->add_option("--slice-normal", options->slice_normal, "--show slice: X,Y,Z, pointing at the half cut away");
    cmd->add_option("--slice-offset", options->editor.view.slice_offset, "--show slice: offset in [-1, 1] half extents")
        ->capture_default_str();
    cmd->add_flag("--quality-interior", options->editor.view.quality_interior,
                  "--show quality: also cut at the slice plane and colour the cross-section's tets");
    add_live_solver_options(*cmd, options->solver, "in a context shared with the window");
    cmd->footer(
        "Mouse: left drag uses the current tool; right drag (or Alt+left) orbits, middle drag (or Shift+right)\n"
        "pans, the wheel zooms, Home resets the view, Esc cancels a stroke or drag.\n"
        "With --hide-ui the first frame shows exactly what `waxwork render` writes for the same volume,\n"
        "materials, lights, --view and window size.");
    organise_help(*cmd, "waxwork edit assets/meshes/spot.obj --material skin1",
                  {{"Custom material (per mm, instead of --material)", {"--mua", "--musp", "--eta"}},
                   {"Meshing a surface (docs/meshing.md)", {"--max-tets", "--edge", "--mesher", "--min-dihedral", "--radius-edge"}},
                   {"Repairing a broken surface", {"--fill-holes", "--autorefine", "--repair", "--wrap-alpha", "--wrap-offset"}},
                   {"Views and shading", {"--view", "--show", "--slice-normal", "--slice-offset", "--quality-interior",
                                          "--crease-angle"}},
                   {"Live solver (docs/solvers.md)", {"--backend", "--method", "--frame-ms"}},
                   {"Scripts and screenshots (docs/editor.md)", {"--screenshot", "--input", "--frames", "--hide-ui"}}});
    cmd->callback([options] { run_edit_command(*options); });
}

}  // namespace waxwork
