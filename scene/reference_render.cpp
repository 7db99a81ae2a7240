#include "scene/reference_render.h"

#include "base/error.h"
#include "io/atomic_file.h"
#include "io/image_io.h"
#include "render/difference_map.h"
#include "render/srgb.h"
#include "scene/scene_core.h"
#include "solver/reference/monte_carlo.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>

namespace waxwork {

namespace {

void check_options(const ReferenceOptions& o) {
    if (!(std::isfinite(o.max_seconds) && o.max_seconds >= 0))
        throw InvalidArgumentError("reference render: the time limit must be zero (none) or positive");
    if (!(std::isfinite(o.target_error) && o.target_error >= 0 && o.target_error < 1))
        throw InvalidArgumentError("reference render: the target error must be in [0, 1)");
    if (o.max_seconds == 0 && o.target_error == 0)
        throw InvalidArgumentError("reference render: give a time limit or a target error (both are 0)");
    if (o.threads < 0) throw InvalidArgumentError("reference render: the thread count must not be negative");
}

int trace_threads(const ReferenceOptions& o) {
    if (o.threads > 0) return o.threads;
    const int hardware = static_cast<int>(std::thread::hardware_concurrency());
    return std::max(1, hardware - 1);
}

// The fraction done: the noise falls as 1 / sqrt(time), so (target / noise)^2 of the way to the target.
float fraction_done(const MonteCarloProgress& p, const ReferenceOptions& o) {
    double fraction = 0;
    if (o.max_seconds > 0) fraction = p.seconds / o.max_seconds;
    const double noise = *std::max_element(p.relative_error.begin(), p.relative_error.end());
    if (o.target_error > 0 && noise > 0) fraction = std::max(fraction, (o.target_error / noise) * (o.target_error / noise));
    return static_cast<float>(std::clamp(fraction, 0.0, 1.0));
}

void paste(Image& into, const Image& image, int x0) {
    for (int y = 0; y < image.height; ++y)
        std::copy_n(image.pixel(0, y), 4 * static_cast<size_t>(image.width), into.pixel(x0, y));
}

}  // namespace

ReferenceScene snapshot_reference_scene(SceneCore& core) {
    core.converge();
    ReferenceScene s;
    s.mesh = core.document().mesh();
    s.connectivity = core.live().connectivity();
    s.solved = core.live().solved_scene(true);
    s.lighting = core.live().lighting();
    s.mm_per_unit = core.live().options().mm_per_unit;
    return s;
}

ReferenceComparison render_reference(const ReferenceScene& scene, const PixelCamera& camera,
                                     const ReferenceOptions& options, Progress* progress) {
    check_options(options);
    const SolvedScene& solved = scene.solved;
    report_stage(progress, "preparing the reference");
    const FirstHitGrid grid = surface_hit_grid(solved.surface);
    const TriangleBvh bvh = build_shadow_bvh(solved.surface);
    const std::vector<PhotonSource> sources = photon_sources(solved.surface, bvh, scene.lighting);
    MonteCarloOptions mc;
    mc.mm_per_unit = scene.mm_per_unit;
    mc.seed = options.seed;
    mc.max_seconds = options.max_seconds;
    mc.target_relative_error = options.target_error;

    ReferenceComparison r;
    report_stage(progress, "tracing the reference");
    tbb::task_arena arena(trace_threads(options));
    arena.execute([&] {
        r.live = surface_radiance_image(solved.surface, solved.shading, solved.radiance_factor, grid, camera);
        r.traced = trace_camera_image(
            scene.mesh, scene.connectivity, scene.mesh.materials, solved.surface, grid, sources, camera, mc,
            [&](const MonteCarloProgress& p) {
                if (!progress) return;
                char stage[96];
                std::snprintf(stage, sizeof stage, "tracing the reference: noise %.1f %%",
                              100 * *std::max_element(p.relative_error.begin(), p.relative_error.end()));
                progress->set_stage(stage);
                progress->set_fraction(fraction_done(p, options));
            },
            progress);
    });

    r.live_exposure = radiance_image_exposure(r.live);
    r.traced_exposure = radiance_image_exposure(r.traced.image);
    r.difference = compare_radiance_images(r.live, r.live_exposure, r.traced.image, r.traced_exposure);
    r.live_image = tone_mapped_image(r.live, r.live_exposure);
    r.traced_at_live_exposure = tone_mapped_image(r.traced.image, r.live_exposure);
    r.traced_at_own_exposure = tone_mapped_image(r.traced.image, r.traced_exposure);
    DifferenceMapOptions map;
    r.difference_image = difference_map(r.live, r.traced.image, r.traced.radiance_error, map);
    // A fit of 0 (an unlit reference) leaves nothing to scale by: the map as it is.
    if (r.difference.scale > 0 && std::isfinite(r.difference.scale)) map.scale = r.difference.scale;
    r.scaled_difference_image = difference_map(r.live, r.traced.image, r.traced.radiance_error, map);
    return r;
}

Image comparison_strip(const ReferenceComparison& c, bool scaled, int gap) {
    const Image& traced = scaled ? c.traced_at_own_exposure : c.traced_at_live_exposure;
    const Image& difference = scaled ? c.scaled_difference_image : c.difference_image;
    gap = std::max(0, gap);
    Image strip;
    strip.width = 3 * c.live_image.width + 2 * gap;
    strip.height = c.live_image.height;
    strip.rgba.assign(4 * static_cast<size_t>(strip.width) * strip.height, 255);
    for (size_t p = 0; p < strip.rgba.size(); p += 4) std::copy_n(kViewBackground.data(), 3, &strip.rgba[p]);
    paste(strip, c.live_image, 0);
    paste(strip, traced, c.live_image.width + gap);
    paste(strip, difference, 2 * (c.live_image.width + gap));
    return strip;
}

nlohmann::ordered_json reference_summary(const ReferenceComparison& c) {
    const MonteCarloImage& t = c.traced;
    nlohmann::ordered_json j;
    j["width"] = t.image.width;
    j["height"] = t.image.height;
    j["passes"] = t.passes;
    j["paths"] = t.paths;
    j["lost_paths"] = t.lost_paths;
    j["seconds"] = t.seconds;
    j["stop_reason"] = t.stop_reason;
    j["noise"] = t.relative_error;
    j["live_exposure"] = c.live_exposure;
    j["traced_exposure"] = c.traced_exposure;
    j["pixels_compared"] = c.difference.pixels;
    j["relative_l2"] = c.difference.relative_l2;
    j["scaled_relative_l2"] = c.difference.scaled_relative_l2;
    j["traced_over_live"] = c.difference.scale;
    // Infinite for identical images: JSON has no infinity, so null then.
    if (std::isfinite(c.difference.psnr_db)) j["psnr_db"] = c.difference.psnr_db;
    else j["psnr_db"] = nullptr;
    return j;
}

void save_reference_comparison(const ReferenceComparison& comparison, bool scaled, const std::filesystem::path& png) {
    if (png.extension() != ".png")
        throw InvalidArgumentError(png.string() + ": a reference comparison is saved as a .png (its numbers go beside it as .json)");
    write_png(comparison_strip(comparison, scaled), png);
    std::filesystem::path json = png;
    json.replace_extension(".json");
    const std::string text = reference_summary(comparison).dump(2) + "\n";
    write_file_atomically(json, [&](std::ostream& out) { out << text; });
}

}  // namespace waxwork
