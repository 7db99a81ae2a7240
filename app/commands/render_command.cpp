// `waxwork render VOLUME -o IMAGE.png|.jpg`: a volume, its materials and lights -> diffusion -> an image.
// `--method mc` traces the light with the Monte Carlo reference (solver/reference/monte_carlo.h) instead.
// `--engine petsc` solves with several processes under mpirun (render/distributed_render.h).
#include "app/cli.h"
#include "app/commands.h"
#include "app/options/engine_options.h"
#include "app/options/help_sections.h"
#include "app/options/scene_light_options.h"
#include "base/error.h"
#include "base/peak_memory.h"
#include "io/file_extension.h"
#include "io/image_io.h"
#include "io/volume_file.h"
#include "render/camera.h"
#include "render/distributed_render.h"
#include "render/image_background.h"
#include "render/radiance_image.h"
#include "render/render_input.h"
#include "render/view_modes.h"
#include "render/volume_render.h"
#include "scene/fields_csv.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "solver/petsc_peers.h"
#include "solver/petsc_runtime.h"
#include "solver/radiance.h"
#include "solver/reference/camera_rays.h"
#include "solver/reference/monte_carlo.h"
#include "solver/reference/monte_carlo_image.h"
#include "solver/solved_scene.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
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
    std::string background;  // image_background.h's words; "" automatic
    std::string linear;      // also the linear radiance, a 16-bit PNG
    bool ground = false;
    // --method mc: the trace stops at the first of the time budget and the error target.
    std::optional<double> mc_seconds;
    std::optional<double> mc_error;
    std::optional<double> mc_g;
    std::optional<int64_t> mc_photons;
    std::optional<uint64_t> seed;
    EngineOptions engine;
};

// Defaults of the trace: a minute at most, 1% relative standard error (of phi at the boundary, of the
// image's radiance over the object).
constexpr double kDefaultMcSeconds = 60;
constexpr double kDefaultMcError = 0.01;
// The share of the time budget the fluence trace (the --fields columns) gets; the image the rest.
constexpr double kFluenceTimeShare = 0.25;

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
    if (!is_image_extension(o.output)) fail("-o " + o.output + ": the image must be a .png, .jpg or .jpeg");
    const BackgroundKind background = parse_background(o.background).kind;
    if (background == BackgroundKind::Transparent && lower_extension(o.output) != ".png")
        fail("--background transparent needs a .png output (JPEG has no alpha)");
    if (background == BackgroundKind::Environment && o.light.environment.empty())
        fail("--background environment needs --env");
    if (!o.linear.empty()) {
        if (lower_extension(o.linear) != ".png") fail("--linear " + o.linear + ": the linear image is a 16-bit .png");
        if (o.show != "radiance") fail("--linear applies only to --show radiance");
    }
    // The renderer exposes in float: beyond 1e30 the product with the radiance leaves its range.
    if (o.exposure && !(*o.exposure > 0 && *o.exposure <= 1e30)) fail("--exposure must be positive and at most 1e30");
    if (!o.view.empty()) {
        const Eigen::Vector3d v(o.view[0], o.view[1], o.view[2]);
        if (!v.allFinite() || v.norm() == 0) fail("--view must be a finite, non-zero direction");
    }
    if (o.ground && o.show != "radiance") fail("--ground applies only to --show radiance");
    check_engine_options(o.engine);
    if (o.engine.petsc()) {
        if (o.light.method != "transcut" && o.light.method != "fem")
            fail("--engine petsc solves --method transcut or fem (got " + o.light.method + ")");
        if (o.light.backend != "cpu") fail("--engine petsc solves on the CPU processes: it cannot take --backend gpu");
    }
    if (o.light.method == "mc" && (o.ground || !o.linear.empty() || background == BackgroundKind::Transparent ||
                                   background == BackgroundKind::Environment))
        fail("--method mc draws over a colour: --ground, --linear and --background transparent or environment need "
             "the diffusion's image");
    if (o.light.method != "mc") {
        if (o.mc_seconds || o.mc_error || o.mc_g || o.mc_photons || o.seed)
            fail("--mc-seconds, --mc-error, --mc-g, --mc-photons and --seed apply only with --method mc");
        return;
    }
    if (o.mc_seconds && !(*o.mc_seconds > 0 && std::isfinite(*o.mc_seconds)))
        fail("--mc-seconds must be a positive, finite number of seconds");
    if (o.mc_error && !(*o.mc_error > 0 && *o.mc_error < 1))
        fail("--mc-error must be a relative standard error in (0, 1)");
    if (o.mc_g && !(*o.mc_g > -1 && *o.mc_g < 1)) fail("--mc-g must be a Henyey-Greenstein anisotropy in (-1, 1)");
    if (o.mc_photons && !(*o.mc_photons > 0)) fail("--mc-photons must be a positive number of paths");
}

// The trace's options from the command's.
MonteCarloOptions monte_carlo_options(const RenderCommandOptions& o, double mm_per_unit) {
    MonteCarloOptions mc;
    mc.mm_per_unit = mm_per_unit;
    mc.anisotropy = o.mc_g.value_or(kDefaultMonteCarloAnisotropy);
    mc.seed = o.seed.value_or(1);
    mc.max_seconds = o.mc_seconds.value_or(kDefaultMcSeconds);
    mc.target_relative_error = o.mc_error.value_or(kDefaultMcError);
    mc.max_photons = o.mc_photons.value_or(0);
    return mc;
}

// The status line of a running trace.
std::string trace_status(const MonteCarloProgress& p, const char* what) {
    char line[160];
    std::snprintf(line, sizeof line, "monte carlo: %lld %s per channel, relative error %.2f%% %.2f%% %.2f%%, %.0f s",
                  static_cast<long long>(p.photons), what, 100 * p.relative_error[0], 100 * p.relative_error[1],
                  100 * p.relative_error[2], p.seconds);
    return line;
}

// The trace reports after every round (several a second), so it keeps its own status line on stderr,
// rewritten in place ("\r") at most once a second and blanked when the trace ends or fails, so that
// stderr keeps its one-line error (StderrProgress shows a stage only once it has run for a second).
class TraceStatusLine {
public:
    TraceStatusLine(std::string prefix, const char* what) : prefix_(std::move(prefix)), what_(what) {}
    ~TraceStatusLine() {
        if (shown_ > 0) std::cerr << '\r' << std::string(shown_, ' ') << '\r' << std::flush;
    }
    void show(const MonteCarloProgress& p) {
        if (p.seconds < next_) return;
        next_ = p.seconds + 1;
        std::string line = prefix_ + trace_status(p, what_);
        const size_t length = line.size();
        if (length < shown_) line += std::string(shown_ - length, ' ');
        std::cerr << '\r' << line << std::flush;
        shown_ = std::max(shown_, length);
    }

private:
    std::string prefix_;
    const char* what_;
    double next_ = 1;  // seconds into the trace
    size_t shown_ = 0;
};

struct TracedRender {
    VolumeRender render;
    MonteCarloFluence fluence;
    MonteCarloImage image;
    std::array<double, 3> over_diffusion{};  // sum of phi over boundary vertices, MC over diffusion
    // Sums of radiance over the pixels both cover: the camera-ray image over the image drawn from the
    // traced phi through Eq. 3, and over the diffusion's own (live) image.
    std::array<double, 3> image_over_eq3{}, image_over_diffusion{};
};

// The pixel rays of the image `settings` frame, as the renderer frames the surface.
PixelCamera render_pixel_camera(const BoundarySurface& surface, const ImageSettings& image) {
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3d& p : surface.positions) box.extend(p);
    const CameraFrame frame = frame_camera(box, image.camera, static_cast<double>(image.width) / image.height);
    return pixel_camera(frame.eye, frame.view, frame.projection, image.width, image.height);
}

// Sums of a's over b's radiance per channel, over the pixels both cover fully.
std::array<double, 3> radiance_ratio(const RadianceImage& a, const RadianceImage& b) {
    std::array<double, 3> sum_a{}, sum_b{}, ratio{};
    for (size_t p = 0; p < a.radiance.size(); ++p) {
        if (a.coverage[p] < 1 || b.coverage[p] < 1) continue;
        for (int c = 0; c < 3; ++c) {
            sum_a[c] += a.radiance[p][c];
            sum_b[c] += b.radiance[p][c];
        }
    }
    for (int c = 0; c < 3; ++c) ratio[c] = sum_b[c] > 0 ? sum_a[c] / sum_b[c] : 0.0;
    return ratio;
}

// Solves the diffusion for the surface and its light (and as a comparison), traces the fluence (the
// --fields columns) and then the image with camera rays (monte_carlo_image.h), which is what is drawn
// (for the radiance view; the other views draw the traced phi).
TracedRender render_traced(const TetMesh& mesh, const RenderCommandOptions& o, const VolumeRenderSettings& settings) {
    VolumeLight light = solve_volume_light(mesh, o.volume, settings);
    SolvedScene& scene = light.scene;
    const TriangleBvh bvh = build_shadow_bvh(scene.surface);
    const std::vector<PhotonSource> sources = photon_sources(scene.surface, bvh, settings.lighting);
    const PixelCamera camera = render_pixel_camera(scene.surface, settings.image);
    const FirstHitGrid grid = surface_hit_grid(scene.surface);
    const RadianceImage diffusion_image =
        surface_radiance_image(scene.surface, scene.shading, scene.radiance_factor, grid, camera);
    const MonteCarloOptions options = monte_carlo_options(o, settings.diffusion.mm_per_unit);
    TracedRender traced;
    {
        MonteCarloOptions fluence_options = options;
        fluence_options.max_seconds = kFluenceTimeShare * options.max_seconds;
        TraceStatusLine status("waxwork: " + o.volume + ": ", "photons");
        traced.fluence = trace_fluence(mesh, light.connectivity, light.materials, scene.surface, sources, fluence_options,
                                       [&](const MonteCarloProgress& p) { status.show(p); });
    }
    {
        MonteCarloOptions image_options = options;
        image_options.max_seconds = std::max(1e-3, options.max_seconds - traced.fluence.seconds);
        TraceStatusLine status("waxwork: " + o.volume + ": image: ", "paths");
        traced.image = trace_camera_image(mesh, light.connectivity, light.materials, scene.surface, grid, sources, camera,
                                          image_options, [&](const MonteCarloProgress& p) { status.show(p); });
    }
    std::array<double, 3> mc_sum{}, diffusion_sum{};
    for (int32_t v : light.connectivity.boundary_vertices)
        for (int c = 0; c < 3; ++c) {
            mc_sum[c] += traced.fluence.phi[v][c];
            diffusion_sum[c] += scene.diffusion.phi[v][c];
        }
    for (int c = 0; c < 3; ++c) traced.over_diffusion[c] = diffusion_sum[c] > 0 ? mc_sum[c] / diffusion_sum[c] : 0.0;
    scene.diffusion.phi = traced.fluence.phi;
    scene.radiance_factor = shading_radiance_factors(scene.surface, scene.shading, scene.diffusion.phi, scene.shading_light.q);
    const RadianceImage eq3_image = surface_radiance_image(scene.surface, scene.shading, scene.radiance_factor, grid, camera);
    traced.image_over_eq3 = radiance_ratio(traced.image.image, eq3_image);
    traced.image_over_diffusion = radiance_ratio(traced.image.image, diffusion_image);
    traced.render = render_volume_light(mesh, std::move(light), settings);
    if (settings.view.mode == ViewMode::Radiance) {
        const float exposure = settings.image.exposure ? *settings.image.exposure : radiance_image_exposure(traced.image.image);
        const ImageBackground& background = settings.background;
        traced.render.image = tone_mapped_image(traced.image.image, exposure,
                                                background.kind == BackgroundKind::Colour ? background.colour : kViewBackground);
        traced.render.exposure = exposure;
    }
    return traced;
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

// The picture's settings from the options, at the volume's scale.
VolumeRenderSettings render_settings(const RenderCommandOptions& o, const ModelScale& scale, const ViewOptions& view) {
    VolumeRenderSettings settings = scene_light_settings(o.light, scale);
    settings.image.width = o.width;
    settings.image.height = o.height;
    settings.image.camera = camera_for_view(o.view);
    if (o.exposure) settings.image.exposure = static_cast<float>(*o.exposure);
    settings.view = view;
    settings.background = parse_background(o.background);
    settings.linear = !o.linear.empty();
    settings.ground = o.ground;
    return settings;
}

// The summary line's fields that every engine reports.
nlohmann::ordered_json render_summary(const RenderCommandOptions& o, const TetMesh& mesh, const VolumeRender& render,
                                      const VolumeRenderSettings& settings, const ModelScale& scale) {
    const SolvedScene& scene = render.scene;
    const DiffusionSolution& s = scene.diffusion;
    nlohmann::ordered_json summary = {
        {"output", o.output},
        {"vertices", mesh.vertex_count()},
        {"tets", mesh.tet_count()},
        {"materials", settings.material ? "option" : mesh.has_materials() ? "stored" : "marble default"},
        {"method", o.light.method},
        {"backend", s.backend == SolverBackend::Gpu ? "gpu" : "cpu"},
        {"engine", o.engine.engine},
        {"mm_per_unit", scale.mm_per_unit},
        {"scale_source", scale_source_name(scale.source)},
        {"lights", settings.lighting.lights.size()},
        {"lights_inside", render.lights_inside},
        {"exposure", render.exposure},
        {"crease_angle_deg", o.light.crease_angle},
        {"shading_copies", scene.shading.size() - scene.surface.vertices.size()},
        {"lighting_ms", scene.lighting_ms},
        {"assembly_ms", s.assembly_ms},
        {"solve_ms", s.solve_ms},
        {"render_ms", render.render_ms},
        {"view", view_mode_name(settings.view.mode)},
    };
    add_solve_summary(summary, scene);
    return summary;
}

#ifdef WAXWORK_HAVE_PETSC
// `--engine petsc`: every process reads the volume (errors agreed across processes), the processes solve
// together, and rank 0 draws, writes and prints as the CPU engine does, with the partition, the solve's
// phases and every process's peak memory in the summary.
void run_petsc_render(const RenderCommandOptions& o, const ViewOptions& view) {
    const ProgramArguments arguments = program_arguments();
    ensure_petsc_runtime(arguments.argc, arguments.argv);
    std::optional<VolumeFile> file;
    std::optional<ModelScale> scale;
    VolumeRenderSettings settings;
    agreed_step([&] {
        file.emplace(read_volume_file(o.volume));
        scale.emplace(chosen_scale(o.light, *file));
        settings = render_settings(o, *scale, view);
    });
    const TetMesh& mesh = file->mesh;
    const PetscPeer pc = chosen_preconditioner(o.engine);
    const DistributedRender distributed = render_volume_distributed(mesh, o.volume, settings, pc);
    const std::vector<int64_t> peak_kib = gather_from_all(static_cast<int64_t>(peak_resident_mib() * 1024));
    agreed_step([&] {
        if (distributed.rank != 0) return;
        const VolumeRender& render = distributed.render;
        write_image(render.image, o.output);
        if (!o.linear.empty()) write_linear_png(render.linear, o.linear, render.exposure);
        report_chosen_scale(o.volume, *scale, mesh);
        if (!o.fields.empty()) write_fields_csv(o.fields, mesh, render.connectivity, render.scene, nullptr);
        nlohmann::ordered_json summary = render_summary(o, mesh, render, settings, *scale);
        std::vector<double> peak_mib;
        for (const int64_t kib : peak_kib) peak_mib.push_back(static_cast<double>(kib) / 1024);
        const DistributedSolveReport& solve = distributed.solve;
        summary["petsc"] = {
            {"processes", distributed.processes},
            {"preconditioner", preconditioner_word(pc)},
            {"partition", "contiguous vertex ranges of the mesh order"},
            {"rows_per_process", distributed.rows_per_process},
            {"tets_per_process", distributed.tets_per_process},
            {"edges", distributed.edges},
            {"edge_cut", distributed.edge_cut},
            {"owned_rows_assembly_ms", distributed.assembly_ms},
            {"conversion_ms", solve.conversion_ms},
            {"preconditioner_setup_ms", solve.preconditioner_ms},
            {"cg_ms", solve.solve_ms},
            {"gather_ms", solve.gather_ms},
            {"peak_rss_mib_per_process", peak_mib},
        };
        if (view.mode != ViewMode::Radiance) summary["legend"] = render.view.legend.title;
        if (!o.fields.empty()) summary["fields"] = o.fields;
        if (!o.linear.empty()) summary["linear"] = o.linear;
        std::cout << summary.dump() << "\n";
    });
}
#endif

void run_render_command(const RenderCommandOptions& o) {
    check_options(o);
    const ViewOptions view = view_options(o);
#ifdef WAXWORK_HAVE_PETSC
    if (o.engine.petsc()) return run_petsc_render(o, view);
#endif
    const VolumeFile file = read_volume_file(o.volume);
    const TetMesh& mesh = file.mesh;
    const ModelScale scale = chosen_scale(o.light, file);
    const VolumeRenderSettings settings = render_settings(o, scale, view);

    const bool traced = o.light.method == "mc";
    std::optional<TracedRender> trace;
    if (traced) trace.emplace(render_traced(mesh, o, settings));
    const VolumeRender render = traced ? std::move(trace->render) : render_volume(mesh, o.volume, settings);
    const SolvedScene& scene = render.scene;
    report_solve_warnings(o.volume, scene);
    write_image(render.image, o.output);
    if (!o.linear.empty()) write_linear_png(render.linear, o.linear, render.exposure);
    report_chosen_scale(o.volume, scale, mesh);
    if (!o.fields.empty())
        write_fields_csv(o.fields, mesh, render.connectivity, scene, traced ? &trace->fluence.phi_error : nullptr);

    nlohmann::ordered_json summary = render_summary(o, mesh, render, settings, scale);
    if (traced) {
        const MonteCarloFluence& mc = trace->fluence;
        summary["monte_carlo"] = {
            {"photons_per_channel", mc.photons},
            {"batches", mc.batches},
            {"seconds", mc.seconds},
            {"relative_error", mc.relative_error},
            {"stopped_by", mc.stop_reason},
            {"seed", o.seed.value_or(1)},
            {"anisotropy", o.mc_g.value_or(kDefaultMonteCarloAnisotropy)},
            {"lost_photons", mc.lost_photons},
            {"over_diffusion", trace->over_diffusion},
        };
        const MonteCarloImage& image = trace->image;
        summary["monte_carlo_image"] = {
            {"samples_per_pixel", image.passes},
            {"paths_per_channel", image.paths},
            {"seconds", image.seconds},
            {"relative_error", image.relative_error},
            {"stopped_by", image.stop_reason},
            {"lost_paths", image.lost_paths},
            {"over_eq3", trace->image_over_eq3},
            {"over_diffusion", trace->image_over_diffusion},
        };
    }
    if (view.mode != ViewMode::Radiance) summary["legend"] = render.view.legend.title;
    if (!o.fields.empty()) summary["fields"] = o.fields;
    if (!o.linear.empty()) summary["linear"] = o.linear;
    std::cout << summary.dump() << "\n";
}

}  // namespace

void add_render_command(CLI::App& app) {
    auto options = std::make_shared<RenderCommandOptions>();
    CLI::App* cmd = app.add_subcommand("render", "Solve the light diffusion in a volume and render a PNG or JPEG");
    cmd->add_option("volume", options->volume, "Volume file (.vtu, .msh, .mesh, .node/.ele)")->required();
    cmd->add_option("-o,--output", options->output,
                    "Image to write: .png (8-bit sRGB with alpha) or .jpg/.jpeg (quality 92)")->required();
    add_scene_light_options(*cmd, options->light, true);
    cmd->add_option("--mc-seconds", options->mc_seconds,
                    "--method mc: stop tracing after this many seconds (default 60)");
    cmd->add_option("--mc-error", options->mc_error,
                    "--method mc: stop once the relative standard error of phi at the boundary is at most this in "
                    "every channel (default 0.01)");
    cmd->add_option("--mc-g", options->mc_g,
                    "--method mc: Henyey-Greenstein anisotropy g, mu_s = mu_s' / (1 - g) (default 0, isotropic)");
    cmd->add_option("--mc-photons", options->mc_photons,
                    "--method mc: stop each trace after this many photons (camera paths for the image) per channel");
    cmd->add_option("--seed", options->seed, "--method mc: random seed; the same seed gives the same result (default 1)");
    add_engine_options(*cmd, options->engine, "the diffusion");
    cmd->add_option("--width", options->width, "Image width in pixels")->capture_default_str();
    cmd->add_option("--height", options->height, "Image height in pixels")->capture_default_str();
    cmd->add_option("--fields", options->fields, "Also write q, phi and exitant radiance per vertex to this CSV");
    cmd->add_option("--view", options->view, "Direction from the object towards the camera, X,Y,Z")
        ->delimiter(',')
        ->expected(3);
    cmd->add_option("--exposure", options->exposure, "Fixed exposure (default: automatic)");
    cmd->add_option("--background", options->background,
                    "Behind the model: R,G,B (0-255) or #RRGGBB, transparent (.png: the coverage as alpha), or "
                    "environment (needs --env) (default: the environment when --env is drawn, else grey)");
    cmd->add_flag("--ground", options->ground,
                  "Put the model on a ground plane lit by the same lights, with its shadows and a soft contact shadow");
    cmd->add_option("--linear", options->linear,
                    "Also write the exposed linear radiance, before tone mapping, as a 16-bit PNG (linear, not sRGB)");
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
        "--exposure sets the multiplier instead. The summary (one JSON line) reports it.\n"
        "--method mc traces photons through the volume (per-tet coefficients, Fresnel at the boundary, the same\n"
        "lights and shadows) for the fluence (--fields gains phi_err_r,phi_err_g,phi_err_b, standard errors), then\n"
        "camera rays for the image (exitant radiance with single scattering, no highlight), until --mc-seconds\n"
        "(a quarter for the fluence), --mc-error or --mc-photons, with a status line on stderr. The summary's\n"
        "monte_carlo.over_diffusion compares the fluences, monte_carlo_image.over_diffusion the images.\n"
        "--method fd, fd-cg, fvm, fvm-cg, lbm and dipole solve the same light with the seeds' methods\n"
        "(docs/methods.md); the summary's alternative block gives their unknowns, setup and solve times.");
    organise_help(*cmd, "waxwork render spot.vtu -o spot.png --material skin1 --light dir:1,-1,-1 --view 0.7,0.5,1",
                  {{"Custom material (per mm, instead of --material)", {"--mua", "--musp", "--eta"}},
                   {"Light and shading details", {"--no-env-background", "--ambient", "--crease-angle"}},
                   {"Inspection views and data", {"--slice-normal", "--slice-offset", "--quality-interior", "--fields"}},
                   {"Solver (docs/solvers.md, docs/methods.md)", {"--method", "--tol", "--cell", "--backend"}},
                   {"Several processes (docs/scaling.md)", {"--engine", "--pc"}},
                   {"Monte Carlo reference (--method mc; docs/monte_carlo.md)",
                    {"--mc-seconds", "--mc-error", "--mc-g", "--mc-photons", "--seed"}}});
    cmd->callback([options] { run_render_command(*options); });
}

}  // namespace waxwork
