// "Model no more than a scene needs": how mesh size and solver stopping trade the
// rendered image's error for time. For one surface, material, scale and view, meshes from several
// multiples of the default size (solver/mesh_resolution.h) are solved to several tolerances, each
// image compared with a converged reference (half the default edge length, tolerance 1e-6) rendered at
// the same resolution and exposure. The smallest per-frame cost that keeps the image within the bound
// is the recommendation; the study also reports where the shipped defaults (size factor 1, tolerance
// 1e-3) land, so the docs can say whether they are right.
#pragma once

#include "io/image_io.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace waxwork {

struct ResolutionStudyOptions {
    std::filesystem::path surface;     // a closed surface file
    std::string material = "marble";   // preset name
    double mm_per_unit = 30;           // a 5 cm spot (README, "Materials and scale")
    int width = 480;
    int height = 360;
    double error_bound = 0.01;         // relative image error the recommendation must stay within
    std::vector<double> size_factors = {3.0, 2.0, 1.5, 1.0, 0.7};  // x the default edge lengths
    std::vector<double> tolerances = {0.3, 0.1, 0.03, 0.01, 3e-3, 1e-3};
    double reference_size_factor = 0.5;
    double reference_tolerance = 1e-6;
};

struct ResolutionSample {
    double size_factor = 0;
    double tolerance = 0;
    size_t tets = 0;
    double meshing_ms = 0;
    double solve_ms = 0;          // assembly + three-channel solve (what a frame pays after an edit)
    int iterations = 0;           // largest over the channels
    double image_error = 0;       // relative L1 of linear rgb over the object's pixels
};

struct ResolutionStudy {
    size_t reference_tets = 0;
    std::vector<ResolutionSample> samples;
    int recommended = -1;  // index of the cheapest sample within the bound, -1 if none
    int shipped_default = -1;  // index of the size factor 1, tolerance 1e-3 sample, -1 if not sampled

    nlohmann::ordered_json to_json() const;
};

// Relative L1 difference of two renders in linear rgb (sRGB decoded), over the pixels where the
// reference is not the background colour. Throws InvalidArgumentError for different sizes.
double relative_image_error(const Image& image, const Image& reference, const std::array<uint8_t, 3>& background);

// Throws what meshing, solving and rendering throw (FileError for the surface, InvalidArgumentError
// for options: an unknown material, empty factor or tolerance lists, non-positive values).
ResolutionStudy run_resolution_study(const ResolutionStudyOptions& options);

}  // namespace waxwork
