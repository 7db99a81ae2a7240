// Error against mesh size: the analytic ball (solver/reference/analytic_ball.h) for TransCut
// and the FEM discretisation under uniform and directional light, and a shipped surface against a
// fine reference mesh of itself. Each series is what a log-log chart of error against tet size shows.
#pragma once

#include "bench/studies/stability_study.h"
#include "solver/methods/alternative_method.h"
#include "tetops/triangle_surface.h"

#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace waxwork {

// The ball every study measures against the analytic series: radius 10 mm (one model unit per mm),
// mu_a 0.01 and mu_s' 1 per mm, eta 1.3.
inline constexpr double kStudyBallRadiusMm = 10.0;
inline const TetMaterial kStudyBallMaterial{{0.01, 0.01, 0.01}, {1.0, 1.0, 1.0}, 1.3};
// TetGen's mesh of the icosphere of that radius at `surface_level`, aiming at `target_tets`.
TetMesh study_ball_mesh(int surface_level, size_t target_tets);

// The mean tet size (volume / tets)^(1/3), in mm.
double mean_tet_size_mm(const TetMesh& mesh, double mm_per_unit);

struct ConvergencePoint {
    size_t tets = 0;
    double tet_size_mm = 0;  // (volume / tets)^(1/3)
    double relative_error = 0;
    double solve_ms = 0;     // assembly + solve of channel 0..2
};

// The order of a series with how far to trust it.
struct OrderFit {
    double order = 0;                  // least-squares slope of log(error) on log(tet size)
    double ci95_low = 0, ci95_high = 0;  // 95% confidence interval of the slope (unbounded below 3 points)
    double size_range = 0;             // largest over smallest tet size
    std::vector<double> local_orders;  // slope between consecutive points, coarse to fine
    bool reliable = false;
    std::string why_unreliable;        // the failed conditions in words; empty when reliable
};

struct ConvergenceSeries {
    std::string name;
    std::vector<ConvergencePoint> points;  // coarse to fine
    // The least-squares line through (log h, log error): order = slope (2 for linear elements in L2), its
    // standard error from the residuals with n - 2 degrees of freedom and the 95% interval order +- t SE
    // (Student's t at n - 2). Unreliable, with the reasons, when any of: fewer than 4 points, sizes
    // spanning less than a factor of 4, an interval half-width above 0.5, or local orders spreading by
    // more than 1.0 (max - min): an order from fewer or closer points, or from points off one line, is
    // not yet the asymptotic one.
    OrderFit fit_order() const;
    // fit_order().order.
    double observed_order() const;
};

nlohmann::ordered_json to_json(const std::vector<ConvergenceSeries>& series);

// A pipe table, one row per series: points, tet size range, order, 95% interval, reliable (or why not).
std::string order_table_markdown(const std::vector<ConvergenceSeries>& series);

// The ball of radius 10 mm (mu_a 0.01, mu_s' 1 per mm, eta 1.3) meshed from ~2K to ~128K tets
// (quick: 2K to 16K): transcut/fem x uniform/directional.
std::vector<ConvergenceSeries> study_ball_convergence(const StudySize& size);

// The same ball and four series as a nested family: a coarse mesh refined `refinements` times by 1:8
// subdivision (tetops/uniform_refinement.h) with the new boundary vertices projected onto the sphere, so
// the tet size halves exactly per level and the surface converges with the volume. Coarse mesh: TetGen's
// 320-tet mesh of the 320-triangle icosphere, to 164K tets after 3 refinements; quick: the 80 triangles
// of the coarser icosphere joined to the centre, to 41K. Series "ball nested METHOD LIGHT".
std::vector<ConvergenceSeries> study_ball_nested_convergence(const StudySize& size, int refinements = 3);

struct SurfaceConvergenceOptions {
    std::filesystem::path surface;
    std::string material = "marble";
    double mm_per_unit = 30;
    std::vector<double> size_factors = {3.0, 2.0, 1.5, 1.0};  // x the default mesh size
    double reference_size_factor = 0.5;
};

// One solve of a surface meshed by TetGen at size_factor x its default size, lit by the default key
// light (tolerance 1e-8, or the alternative method's own), with phi read at the input surface's
// vertices, which every TetGen mesh of the surface keeps exactly, so that meshes of any size compare.
struct SurfaceSolve {
    std::vector<std::array<double, 3>> phi;  // per input surface vertex
    size_t tets = 0, vertices = 0;
    double tet_size_mm = 0;
    double setup_ms = 0, solve_ms = 0;       // assembly (or the method's setup) and solve
    int iterations = 0;                      // channel 0
    std::optional<MethodSolution> alternative;  // with an alternative method: its statistics (phi moved out)
};
// Throws AlgorithmError naming `surface_name` if the mesher moved an input vertex.
SurfaceSolve solve_at_input_vertices(const TriangleSurface& surface, const std::string& surface_name,
                                     const TetMaterial& material, double mm_per_unit, double size_factor,
                                     const AlternativeMethodSettings* alternative = nullptr);

// sqrt(sum |phi - reference|^2 / sum |reference|^2) over every vertex and channel.
double relative_l2_error(const std::vector<std::array<double, 3>>& phi, const std::vector<std::array<double, 3>>& reference);

// phi on the input surface's vertices (which every TetGen mesh of the surface keeps exactly) against
// the reference mesh's, default key light, tolerance 1e-8. One series: "NAME (MATERIAL, xSCALE mm)".
ConvergenceSeries study_surface_convergence(const SurfaceConvergenceOptions& options);

}  // namespace waxwork
