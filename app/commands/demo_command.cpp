// `waxwork demo [-o DIR]`: the tour of what Waxwork does, on the embedded model (Spot, CC0): mesh it,
// save the volume, render it in a few materials and lights, a cut and a painted variant, then replay
// the example editing sessions of assets/sessions/.
#include "app/commands.h"
#include "app/options/help_sections.h"
#include "app/options/surface_meshing_options.h"
#include "base/error.h"
#include "editor/editor_app.h"
#include "io/surface_reader.h"
#include "io/volume_file.h"
#include "render/render_input.h"
#include "scene/session.h"
#include "solver/material.h"
#include "solver/mesh_resolution.h"
#include "solver/solved_scene.h"
#include "tetops/cut.h"
#include "tetops/paint.h"
#include "tetops/relaxation.h"
#include "tetops/tetrahedralize.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <vector>

namespace waxwork {
namespace {

namespace fs = std::filesystem;

struct DemoCommandOptions {
    std::string output = "out/demo";
    // Spot is about 1.7 model units long and tall. At 30 mm per unit it is a 5 cm figurine: marble's
    // diffusion length (3.9 mm blue, 8.5 mm red) is then small against the body (about 25 mm across),
    // which stays opaque-looking and shaded, but large against the ears, horns and legs (1-10 mm),
    // which glow when back-lit. At 1 mm per unit the whole cow would be thinner than one diffusion
    // length and look flat and uniformly lit; at 300 it would look like a chalky, nearly opaque cow.
    double scale = 30.0;
    std::optional<size_t> max_tets;
    int width = 800;
    int height = 600;
    bool no_editor = false;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// One image of the tour.
struct DemoShot {
    std::string file;
    std::string what;
    const TetMesh* mesh;
    const TetConnectivity* connectivity;
    std::vector<TetMaterial> materials;
    Lighting lighting;
};

// Spot faces -z (its horns and ears are at z < 0, its tail at z = +1): the camera looks at its face
// from the front right, somewhat above.
const Eigen::Vector3d kCameraDirection(0.75, 0.5, -1.0);

// The key light comes from the upper left of the camera, in front of the cow, so the camera sees the
// lit face next to the shaded flank and the soft, reddish terminator marble gets from diffusion.
Light key_light() {
    Light light;
    light.vector = Eigen::Vector3d(1.0, -0.8, 0.3).normalized();
    return light;
}

// A light from behind the cow, above, travelling towards the camera: the camera sees mostly faces in
// shade, and what glows is light that crossed thin parts (ears, horns, legs).
Light back_light() {
    Light light;
    light.vector = Eigen::Vector3d(0.75, -1.1, -1.0).normalized();
    light.intensity = {1.5, 1.5, 1.5};
    return light;
}

// A stroke along the top of the back, found on the surface itself so it follows the model: for a few
// positions along z, the highest boundary vertex near the mid-plane x = 0, pushed a little inside.
std::vector<Eigen::Vector3d> back_stroke(const TetMesh& mesh, const TetConnectivity& connectivity) {
    const auto [lo, hi] = bounding_box(mesh);
    const double length = hi.z() - lo.z();
    const double band = 0.04 * length;
    std::vector<Eigen::Vector3d> stroke;
    for (double f = 0.25; f <= 0.6 + 1e-9; f += 0.05) {
        const double z = lo.z() + f * length;
        std::optional<Eigen::Vector3d> top;
        for (const int32_t v : connectivity.boundary_vertices) {
            const Eigen::Vector3d& p = mesh.positions[v];
            if (std::abs(p.x()) < band && std::abs(p.z() - z) < band && (!top || p.y() > top->y())) top = p;
        }
        if (top) stroke.push_back(*top - Eigen::Vector3d(0, 0.01 * length, 0));
    }
    return stroke;
}

// The example editing sessions (assets/sessions/*.json: carving, a painted marble vein, relighting
// from behind) replayed headless into DIR/sessions/NAME/. A session that meshes the embedded spot at
// the demo's scale with the default sizing starts from the volume the demo just made instead of
// meshing it again; images take the demo's size.
void run_example_sessions(const fs::path& dir, const fs::path& spot_volume, const DemoCommandOptions& o) {
    const fs::path sessions_dir = fs::path(WAXWORK_ASSET_DIR) / "sessions";
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(sessions_dir))
        if (entry.path().extension() == ".json") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& file : files) {
        const auto start = std::chrono::steady_clock::now();
        Session session = read_session(file);
        const bool default_spot = session.input.surface.filename() == "spot.obj" && !session.input.max_tets &&
                                  !session.input.edge && session.scale == o.scale && !o.max_tets;
        if (default_spot) {
            session.input = SessionInput{};
            session.input.volume = spot_volume;
        }
        session.width = o.width;
        session.height = o.height;
        const fs::path out = dir / "sessions" / file.stem();
        const SessionResult result = run_session(session, out);
        std::cout << "ran session " << file.filename().string() << " (" << session.steps.size() << " steps, "
                  << seconds_since(start) << " s): ";
        for (size_t i = 0; i < result.written.size(); ++i)
            std::cout << (i ? ", " : "") << result.written[i].lexically_relative(dir).string();
        std::cout << "\n";
    }
}

void run_demo_command(const DemoCommandOptions& o) {
    if (o.width <= 0 || o.height <= 0 || o.width > kMaxImageSide || o.height > kMaxImageSide)
        throw InvalidArgumentError("--width/--height must be between 1 and " + std::to_string(kMaxImageSide));
    if (!std::isfinite(o.scale) || o.scale <= 0) throw InvalidArgumentError("--scale must be positive");
    const fs::path dir = o.output;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw FileError(dir.string(), "cannot create the directory: " + ec.message());

    const std::string model = std::string(WAXWORK_ASSET_DIR) + "/meshes/spot.obj";
    const auto mesh_start = std::chrono::steady_clock::now();
    const LoadedSurface loaded = load_closed_surface(model);
    const TetMaterial marble = material_preset("marble");
    MeshingOptions meshing;
    if (o.max_tets) {
        meshing.sizing.target_tets = o.max_tets;
    } else {
        meshing.sizing = default_mesh_sizing(loaded.surface, marble, o.scale);
    }
    const TetMesh mesh = tetrahedralize(loaded.surface, meshing).mesh;
    const fs::path volume_path = dir / "spot.vtu";
    write_volume(mesh, volume_path, VolumeMetadata{o.scale});
    std::cout << "wrote " << volume_path.string() << " (" << mesh.tet_count() << " tets, " << mesh.vertex_count()
              << " vertices, marble-driven sizing at " << o.scale << " mm per unit, " << seconds_since(mesh_start)
              << " s)\n";
    const TetConnectivity connectivity = build_connectivity(mesh);

    Lighting key;
    key.lights = {key_light()};
    key.ambient = {0.02, 0.02, 0.02};
    Lighting back;
    back.lights = {back_light()};
    back.ambient = {0.01, 0.01, 0.01};

    const size_t n = mesh.tet_count();
    std::vector<DemoShot> shots = {
        {"spot_marble.png", "marble, key light from the upper front-left", &mesh, &connectivity,
         std::vector<TetMaterial>(n, marble), key},
        {"spot_marble_backlit.png", "marble, back-lit: thin ears, horns and legs glow", &mesh, &connectivity,
         std::vector<TetMaterial>(n, marble), back},
        {"spot_skin1.png", "skin1, key light", &mesh, &connectivity,
         std::vector<TetMaterial>(n, material_preset("skin1")), key},
        {"spot_ketchup.png", "ketchup, key light", &mesh, &connectivity,
         std::vector<TetMaterial>(n, material_preset("ketchup")), key},
    };

    // Painted: a ketchup stripe blended into a marble cow along its back (tetops/paint.h).
    TetMesh painted = mesh;
    PaintBrush brush;
    brush.material = material_preset("ketchup");
    brush.sigma = 0.03 * (bounding_box(mesh)[1] - bounding_box(mesh)[0]).norm();
    paint_stroke(painted, back_stroke(mesh, connectivity), brush, marble);
    shots.push_back({"spot_painted.png", "marble painted with a ketchup stripe along the back", &painted,
                     &connectivity, painted.materials, key});

    // Cut: the right half (x > 0) cut away by a plane and the cross-section relaxed onto it
    // (tetops/cut.h, relaxation.h); the camera looks at the cut face, lit only from inside.
    TetMesh cut = mesh;
    const PlaneCut plane(Eigen::Vector3d(1, 0, 0), 0.0);
    remove_cut_away_tets(cut, plane);
    const TetConnectivity cut_connectivity = build_connectivity(cut);
    // More and longer steps than the editor's per-frame default (10 x 0.1): the demo relaxes once, so
    // it runs until the jagged tet faces have settled onto the plane.
    RelaxationOptions relaxation;
    relaxation.max_iterations = 60;
    relaxation.step = 0.3;
    relax_cut_vertices(cut, cut_connectivity, plane, relaxation);
    shots.push_back({"spot_marble_cut.png", "marble cut in half: the cross-section glows with light from inside",
                     &cut, &cut_connectivity, std::vector<TetMaterial>(cut.tet_count(), marble), key});

    HeadlessGlContext context;
    SurfaceRenderer renderer(context.gl());
    DiffusionOptions diffusion;
    diffusion.mm_per_unit = o.scale;
    ImageSettings settings;
    settings.width = o.width;
    settings.height = o.height;
    settings.camera.eye_direction = kCameraDirection;
    for (const DemoShot& shot : shots) {
        const auto start = std::chrono::steady_clock::now();
        const SolvedScene scene = solve_scene(*shot.mesh, *shot.connectivity, shot.materials, shot.lighting, diffusion);
        const Image image = render_scene(renderer, make_render_input(*shot.mesh, scene, shot.lighting, settings));
        const fs::path path = dir / shot.file;
        write_png(image, path);
        std::cout << "wrote " << path.string() << " (" << shot.what << "; " << scene.diffusion.iterations[0] << "/"
                  << scene.diffusion.iterations[1] << "/" << scene.diffusion.iterations[2] << " CG iterations, "
                  << seconds_since(start) << " s)\n";
    }

    run_example_sessions(dir, volume_path, o);

    // The interactive editor on the demo's volume when a window can open (a desktop); on a server, or
    // with --no-editor, the demo ends here with its images written.
    if (!o.no_editor) {
        EditorOptions editor;
        editor.file = volume_path;
        editor.scale = o.scale;
        editor.camera.eye_direction = kCameraDirection;
        editor.lights = {key_light()};
        if (try_open_editor(editor)) return;
    }
    std::cout << "no display: not opening the editor (see `waxwork edit --help`)\n";
}

}  // namespace

void add_demo_command(CLI::App& app) {
    auto options = std::make_shared<DemoCommandOptions>();
    CLI::App* cmd = app.add_subcommand("demo", "Mesh the embedded model (Spot) and render it in several materials");
    cmd->add_option("-o,--output", options->output, "Directory to write into")->capture_default_str();
    cmd->add_option("--scale", options->scale, "Millimetres per model unit (Spot is about 1.7 units long)")
        ->capture_default_str();
    add_max_tets_option(*cmd, options->max_tets, "About this many tets (default: sized by marble's diffusion length)");
    cmd->add_option("--width", options->width, "Image width in pixels")->capture_default_str();
    cmd->add_flag("--no-editor", options->no_editor, "Do not open the interactive editor even when a display is present");
    cmd->add_option("--height", options->height, "Image height in pixels")->capture_default_str();
    organise_help(*cmd, "waxwork demo -o out/demo", {});
    cmd->callback([options] { run_demo_command(*options); });
}

}  // namespace waxwork
