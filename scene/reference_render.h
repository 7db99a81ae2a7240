// A reference for the live image: the Monte Carlo image (solver/reference/monte_carlo_image.h) of the
// scene as it was at one moment, the live image from the same camera (Eq. 3 on the CPU, the
// renderer's subsurface term: solver/reference/camera_rays.h) and where the two differ
// (render/difference_map.h). What the editor's "Render reference" shows beside the view.
//
// The trace works on a snapshot (a copy), so it runs on a thread of its own while the document goes on
// changing, and in a task arena smaller than the machine so that the window and the live solve keep a
// core.
#pragma once

#include "base/progress.h"
#include "io/image_io.h"
#include "render/radiance_image.h"
#include "solver/lighting.h"
#include "solver/reference/camera_rays.h"
#include "solver/reference/monte_carlo_image.h"
#include "solver/solved_scene.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>

namespace waxwork {

class SceneCore;

struct ReferenceScene {
    TetMesh mesh;  // with its materials and piece transforms
    TetConnectivity connectivity;
    SolvedScene solved;  // the live light: the surface, its shading and radiance factors
    Lighting lighting;
    double mm_per_unit = 1;
};

// Converges the live light first (the comparison is of diffusion against transport, not of an
// unfinished solve), then copies what the trace needs. Call where `core` may be used (the window's
// worker, between its jobs).
ReferenceScene snapshot_reference_scene(SceneCore& core);

struct ReferenceOptions {
    double max_seconds = 30;     // wall clock of the trace; 0: no limit
    double target_error = 0.05;  // MonteCarloImage::relative_error of every channel; 0: no target
    uint64_t seed = 1;
    // Threads of the trace; 0: every hardware thread but one, so that the window and the live solve
    // keep one (at least one thread either way).
    int threads = 0;
};

struct ReferenceComparison {
    MonteCarloImage traced;
    RadianceImage live;
    float live_exposure = 1;     // the live image's automatic exposure
    float traced_exposure = 1;   // the traced image's own
    ImageDifference difference;  // the live image against the traced one
    // Tone-mapped: the live image, the traced one at the live exposure (absolute brightness compared)
    // and at its own (the light's distribution compared, as each image looks on screen alone).
    Image live_image, traced_at_live_exposure, traced_at_own_exposure;
    // difference_map of the live image against the traced one, as it is and after the brightness
    // factor (difference.scale) that fits it best.
    Image difference_image, scaled_difference_image;
};

// Traces and compares. `progress` (optional) gets the stage with the image's current noise, a fraction
// (the larger of the time and of the noise's way to its target) and is checked for cancellation
// between rounds of passes (CancelledError). Throws InvalidArgumentError for options out of range
// (negative or non-finite limits, both limits 0, threads < 0) and what trace_camera_image throws.
ReferenceComparison render_reference(const ReferenceScene& scene, const PixelCamera& camera,
                                     const ReferenceOptions& options, Progress* progress = nullptr);

// Live, reference and difference side by side, `gap` background pixels apart: the picture "Save
// comparison" writes. `scaled`: the traced image at its own exposure and the scaled difference.
Image comparison_strip(const ReferenceComparison& comparison, bool scaled, int gap = 8);

// The numbers of a comparison: the trace's passes, paths, seconds, noise and stop reason, both
// exposures and the ImageDifference (relative L2, scaled, brightness factor, PSNR).
nlohmann::ordered_json reference_summary(const ReferenceComparison& comparison);

// Writes comparison_strip to `png` and reference_summary beside it (the same name with .json), each
// atomically. Throws InvalidArgumentError for a name not ending in .png, FileError naming the file
// that could not be written.
void save_reference_comparison(const ReferenceComparison& comparison, bool scaled, const std::filesystem::path& png);

}  // namespace waxwork
