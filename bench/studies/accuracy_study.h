// Error against mesh size: the analytic ball (solver/reference/analytic_ball.h) for TransCut
// and the FEM discretisation under uniform and directional light, and a shipped surface against a
// fine reference mesh of itself. Each series is what a log-log chart of error against tet size shows.
#pragma once

#include "bench/studies/stability_study.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace waxwork {

struct ConvergencePoint {
    size_t tets = 0;
    double tet_size_mm = 0;  // (volume / tets)^(1/3)
    double relative_error = 0;
    double solve_ms = 0;     // assembly + solve of channel 0..2
};

struct ConvergenceSeries {
    std::string name;
    std::vector<ConvergencePoint> points;  // coarse to fine
    // Least-squares slope of log(error) against log(tet size) (2 for linear elements in L2).
    double observed_order() const;
};

nlohmann::ordered_json to_json(const std::vector<ConvergenceSeries>& series);

// The ball of radius 10 mm (mu_a 0.01, mu_s' 1 per mm, eta 1.3) meshed from ~2K to ~128K tets
// (quick: 2K to 16K): transcut/fem x uniform/directional.
std::vector<ConvergenceSeries> study_ball_convergence(const StudySize& size);

struct SurfaceConvergenceOptions {
    std::filesystem::path surface;
    std::string material = "marble";
    double mm_per_unit = 30;
    std::vector<double> size_factors = {3.0, 2.0, 1.5, 1.0};  // x the default mesh size
    double reference_size_factor = 0.5;
};

// phi on the input surface's vertices (which every TetGen mesh of the surface keeps exactly) against
// the reference mesh's, default key light, tolerance 1e-8. One series: "NAME (MATERIAL, xSCALE mm)".
ConvergenceSeries study_surface_convergence(const SurfaceConvergenceOptions& options);

}  // namespace waxwork
