// The seeds' methods side by side (solver/methods/alternative_method.h) with TransCut's own solvers,
// on the same problems against the same exact references:
//   - the analytic ball (R = 10 mm, mu_a 0.01, mu_s' 1 per mm, eta 1.3) under uniform and directional
//     light, at three (quick) or five resolutions, 2K to 300K tets (TetGen meshes; the grid methods at
//     the cell size that gives as many cells as the mesh has vertices; the dipole, quadratic in the
//     vertices, up to 120K), against the series (analytic_ball.h);
//   - a shipped surface (spot in marble) at its default mesh, against TransCut on a mesh of half the
//     default size, compared at the input surface's vertices.
// Each run records its setup (grid, graph, hierarchy or assembly) and solve times apart, its unknowns,
// its error and its warnings; each (scene, method) series gets an observed order.
#pragma once

#include "bench/studies/accuracy_study.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace waxwork {

struct MethodRun {
    size_t tets = 0;
    size_t unknowns = 0;        // vertices (TransCut, fvm, dipole) or voxels (fd, lbm)
    double resolution_mm = 0;   // mean tet size (volume / tets)^(1/3), or the voxel size
    double setup_ms = 0;        // TransCut: assembly (and the hierarchy for multigrid CG)
    double solve_ms = 0;        // three channels
    int iterations = 0;         // channel 0
    double relative_error = 0;
    std::vector<std::string> warnings;
};

struct MethodSeries {
    std::string scene;   // "ball uniform", "ball directional", "spot"
    std::string method;  // "transcut_cg", "transcut_multigrid_cg", or an alternative method's name
    std::vector<MethodRun> runs;  // coarse to fine
    // The order of error against resolution_mm (accuracy_study.h's fit).
    OrderFit fit_order() const;
};

struct MethodStudyOptions {
    bool quick = false;
    std::vector<AlternativeMethod> methods = all_alternative_methods();
    std::filesystem::path surface;  // spot.obj; empty: the ball only
    double relative_tolerance = 1e-6;
    std::function<void(const std::string&)> progress;  // one line per run; may be empty
};

// Every method on every scene. A method that throws on a scene (it cannot handle it) is recorded as a
// warning of an empty series, not an error of the study.
std::vector<MethodSeries> study_methods(const MethodStudyOptions& options);

nlohmann::ordered_json to_json(const std::vector<MethodSeries>& series);
// One row per (scene, method): finest run's unknowns, setup and solve ms, error, and the observed order.
std::string method_table_markdown(const std::vector<MethodSeries>& series);

}  // namespace waxwork
