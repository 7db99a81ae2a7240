// `waxwork turntable VOLUME|SESSION -o DIR --frames N`: the model seen from N cameras circling its
// vertical axis, as DIR/frame_0000.png ..., and DIR/turntable.mp4 when ffmpeg is on the PATH.
// One light solve, N draws (render/turntable.h), at the first frame's exposure throughout.
#include "app/commands.h"
#include "app/options/help_sections.h"
#include "app/options/scene_light_options.h"
#include "app/stderr_progress.h"
#include "base/error.h"
#include "gl/gl_context.h"
#include "io/file_extension.h"
#include "io/image_io.h"
#include "io/output_folder.h"
#include "io/video_encoder.h"
#include "io/volume_file.h"
#include "render/image_background.h"
#include "render/render_input.h"
#include "render/surface_renderer.h"
#include "render/turntable.h"
#include "render/volume_render.h"
#include "scene/session.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace waxwork {
namespace {

namespace fs = std::filesystem;

struct TurntableOptions {
    std::string input;
    std::string output;
    SceneLightOptions light;
    int frames = 0;
    std::optional<double> elevation;
    double seconds_per_turn = kDefaultSecondsPerTurn;
    std::optional<int> width, height;
    std::optional<double> exposure;
    std::string background;
    bool ground = false;
};

// More frames than this is a mistake (an hour of 60 fps video per turn), not a turntable.
constexpr int kMaxFrames = 100000;

bool is_session(const std::string& input) { return lower_extension(input) == ".json"; }

void check_options(const TurntableOptions& o) {
    auto fail = [](const std::string& what) { throw InvalidArgumentError(what); };
    if (o.frames < 1 || o.frames > kMaxFrames)
        fail("--frames must be between 1 and " + std::to_string(kMaxFrames) + " (got " + std::to_string(o.frames) + ")");
    if (o.elevation && !(std::abs(*o.elevation) < 90)) fail("--elevation must be between -90 and 90 degrees");
    if (!(o.seconds_per_turn > 0 && o.seconds_per_turn <= 3600))
        fail("--seconds-per-turn must be positive and at most 3600");
    for (const auto& side : {o.width, o.height})
        if (side && (*side <= 0 || *side > kMaxImageSide))
            fail("--width/--height must be between 1 and " + std::to_string(kMaxImageSide));
    if (o.exposure && !(*o.exposure > 0 && *o.exposure <= 1e30)) fail("--exposure must be positive and at most 1e30");
    const BackgroundKind background = parse_background(o.background).kind;
    if (is_session(o.input)) {
        if (!o.light.lights.empty() || !o.light.environment.empty())
            fail(o.input + ": a session sets its own lights; --light and --env apply to a volume");
    } else {
        check_scene_light_options(o.light);
        if (background == BackgroundKind::Environment && o.light.environment.empty())
            fail("--background environment needs --env");
    }
}

// What every frame draws: the solved scene, its lighting, and the camera it starts from.
struct TurntableScene {
    TetMesh mesh;
    SolvedScene scene;
    Lighting lighting;
    ImageSettings image;
};

TurntableScene solve_turntable_scene(const TurntableOptions& o) {
    TurntableScene t;
    if (is_session(o.input)) {
        SessionScene replayed = replay_session_scene(read_session(o.input));
        t.mesh = std::move(replayed.mesh);
        t.scene = std::move(replayed.scene);
        t.lighting = std::move(replayed.lighting);
        t.image.camera = replayed.camera;
        t.image.width = replayed.width;
        t.image.height = replayed.height;
        return t;
    }
    VolumeFile file = read_volume_file(o.input);
    const ModelScale scale = chosen_scale(o.light, file);
    const VolumeRenderSettings settings = scene_light_settings(o.light, scale);
    VolumeLight light = solve_volume_light(file.mesh, o.input, settings);
    report_solve_warnings(o.input, light.scene);
    t.mesh = std::move(file.mesh);
    t.scene = std::move(light.scene);
    t.lighting = settings.lighting;
    report_chosen_scale(o.input, scale, t.mesh);
    return t;
}

void run_turntable_command(const TurntableOptions& o) {
    check_options(o);
    const fs::path dir = o.output;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) throw FileError(dir.string(), "cannot create the output folder" + (ec ? ": " + ec.message() : ""));

    StderrProgress progress("waxwork: " + o.input + ": ");
    progress.set_stage("solving the light");
    TurntableScene t = solve_turntable_scene(o);
    if (o.width) t.image.width = *o.width;
    if (o.height) t.image.height = *o.height;
    const ImageBackground background = parse_background(o.background);

    HeadlessGlContext context;
    SurfaceRenderer renderer(context.gl());
    std::optional<float> exposure;
    if (o.exposure) exposure = static_cast<float>(*o.exposure);
    for (int i = 0; i < o.frames; ++i) {
        progress.set_stage("frame " + std::to_string(i + 1) + " of " + std::to_string(o.frames));
        ImageSettings image = t.image;
        image.camera = orbit_camera(t.image.camera, i, o.frames, o.elevation);
        // The first frame's exposure for all: an automatic exposure per view would flicker.
        image.exposure = exposure;
        SurfaceRenderInput input = make_render_input(t.mesh, t.scene, t.lighting, image);
        apply_background(background, input);
        input.ground = o.ground;
        exposure = input.exposure;
        write_png(render_scene(renderer, input), contained_output_path(dir, turntable_frame_name(i)));
    }
    progress.finish();

    const fs::path mp4 = dir / "turntable.mp4";
    const std::string ffmpeg = find_on_path("ffmpeg");
    bool wrote_mp4 = false;
    if (ffmpeg.empty()) {
        std::cerr << "waxwork: ffmpeg is not on the PATH, so no turntable.mp4; the frames are in " << dir.string()
                  << " (install ffmpeg for the video)\n";
    } else {
        wrote_mp4 = encode_mp4(ffmpeg, dir, contained_output_path(dir, "turntable.mp4"), o.frames / o.seconds_per_turn);
        if (!wrote_mp4) std::cerr << "waxwork: warning: " << ffmpeg << " failed, so no turntable.mp4; the frames are written\n";
    }
    const nlohmann::ordered_json summary = {
        {"output", dir.string()},
        {"frames", o.frames},
        {"width", t.image.width},
        {"height", t.image.height},
        {"exposure", exposure.value_or(1.0f)},
        {"mp4", wrote_mp4 ? nlohmann::json(mp4.string()) : nlohmann::json(nullptr)},
    };
    std::cout << summary.dump() << "\n";
}

}  // namespace

void add_turntable_command(CLI::App& app) {
    auto options = std::make_shared<TurntableOptions>();
    CLI::App* cmd = app.add_subcommand("turntable", "Render an orbit around a volume or a session's result as PNG frames (and an MP4)");
    cmd->add_option("input", options->input, "Volume file (.vtu, .msh, .mesh, .node/.ele) or session (.json)")->required();
    cmd->add_option("-o,--output", options->output, "Folder for frame_0000.png ... and turntable.mp4 (created)")->required();
    cmd->add_option("--frames", options->frames, "Frames in one turn (at least 1)")->required();
    cmd->add_option("--elevation", options->elevation,
                    "Degrees above the horizontal the camera circles at (default: the starting camera's)");
    cmd->add_option("--seconds-per-turn", options->seconds_per_turn, "Length of one turn in the MP4")->capture_default_str();
    cmd->add_option("--width", options->width, "Frame width in pixels (default 800, or the session's)");
    cmd->add_option("--height", options->height, "Frame height in pixels (default 600, or the session's)");
    cmd->add_option("--exposure", options->exposure, "Fixed exposure (default: the first frame's automatic one, kept for all)");
    cmd->add_option("--background", options->background,
                    "Behind the model: R,G,B (0-255) or #RRGGBB, transparent, or environment (as render's)");
    cmd->add_flag("--ground", options->ground, "Put the model on a ground plane with its shadows (as render's)");
    add_scene_light_options(*cmd, options->light);
    cmd->footer(
        "The camera starts where render's does (or the session's camera) and turns counter-clockwise seen from\n"
        "above about the vertical axis through the model's centre. The light is solved once (it does not depend\n"
        "on the view). With a session, its edits, lights and camera are replayed first; its render and save\n"
        "steps are skipped. turntable.mp4 (H.264) is made when ffmpeg is on the PATH.\n"
        "Example: waxwork turntable spot.vtu -o spin --frames 72 --elevation 20");
    organise_help(*cmd, "waxwork turntable spot.vtu -o spin --frames 36 --ground", {});
    cmd->callback([options] { run_turntable_command(*options); });
}

}  // namespace waxwork
