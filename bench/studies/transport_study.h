// Where the diffusion approximation fails (docs/diffusion_vs_transport.md): TransCut's live image
// (Eq. 3 from the diffusion's phi, solver/reference/camera_rays.h) against the Monte Carlo image traced
// with camera rays (solver/reference/monte_carlo_image.h), pixel for pixel, over materials, scales,
// plate thicknesses in transport mean free paths and a cut cross-section. `waxwork bench --only
// diffusion_vs_transport` writes the table, the JSON and the charts.
#pragma once

#include "render/radiance_image.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace waxwork {

struct TransportStudyOptions {
    std::vector<std::string> materials = {"marble", "skimmilk", "skin1", "ketchup"};
    std::vector<double> cube_scales = {3, 30, 300};                 // mm per unit of a cube of side 1
    std::vector<double> plate_thicknesses = {1, 2, 4, 8, 16};       // transport mean free paths (green)
    double cut_scale = 30;                                         // mm per unit of the cut cube
    int width = 48, height = 36;
    int cube_cells = 8;          // per side (6 tets per cell)
    double mc_seconds = 2;       // per case
    uint64_t seed = 1;
    std::function<void(const std::string&)> progress;  // one line per case; may be empty
};

struct TransportCase {
    std::string shape;     // "cube", "plate, lit side", "plate, far side", "cut cube"
    std::string material;
    double mm_per_unit = 1;
    double size_mfp = 0;   // the cube's side or the plate's thickness in transport mean free paths (green)
    double albedo = 0;     // reduced single-scattering albedo mu_s' / (mu_s' + mu_a), green
    int64_t tets = 0;
    double live_ms = 0;    // the live solve: assembly and iterations
    double mc_seconds = 0;
    int64_t mc_paths = 0;  // per channel
    double mc_noise = 0;   // the Monte Carlo image's own relative standard error (all channels)
    ImageDifference difference;  // the live image against the Monte Carlo image
    // Per round of the trace: seconds and the image's relative standard error (worst channel).
    std::vector<std::pair<double, double>> convergence;
};

// Runs every case: cubes at each scale, plates at each thickness seen from the lit side and from the
// far side (light through the plate), and a cube with a corner cut off seen on its cross-section, for
// each material, under a white directional light from the upper front left without ambient light.
std::vector<TransportCase> run_transport_study(const TransportStudyOptions& options);

// The part of the error after the best brightness factor that the Monte Carlo noise does not explain:
// sqrt(max(0, scaled_relative_l2^2 - mc_noise^2)) (independent errors add in quadrature).
double model_error(const TransportCase& result);

nlohmann::ordered_json to_json(const TransportCase& result);
// A pipe table, one row per case, with the statistic's definitions in its heading.
std::string transport_table_markdown(const std::vector<TransportCase>& cases);

}  // namespace waxwork
