// Where the methods fail: each study builds the failing case on purpose, runs every
// relevant path on it and returns a table with what fails, how it shows and what Waxwork does about
// it. `waxwork bench` writes them to stability.json and stability.md; tests/editor/
// stability_study_test.cpp asserts the behaviour each table documents.
//
// References are exact where one exists (the analytic ball, solver/reference/analytic_ball.h) and otherwise
// the double-precision direct solution of the same discrete system (so the tables separate the
// solver's failures from the discretisation's), or a twice-refined mesh for discretisation studies.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace waxwork {

struct StudyTable {
    std::string name;
    std::string what_fails;
    std::string how_it_shows;
    std::string what_waxwork_does;
    std::vector<std::string> columns;
    std::vector<std::vector<nlohmann::json>> rows;

    nlohmann::ordered_json to_json() const;
    std::string to_markdown() const;  // heading, the three explanations, a pipe table
};

struct StudySize {
    bool quick = false;  // smaller meshes and fewer rows (tests, `waxwork bench --quick`)
};

// Slivers with minimum dihedral angles from ~1 down to ~0.01 degrees, in float and double, with the
// gradient and the cotangent (Eq. 10) forms of the stiffness weights.
StudyTable study_slivers(const StudySize& size);

// A tilted plane cut relaxed with and without the 0.5 degree guard (TransCut Fig. 9).
StudyTable study_relaxation_guard(const StudySize& size);

// Albedo from spectralon (mu_a = 0) to ketchup (diffusion length well under the tet size), against the
// analytic ball.
StudyTable study_material_extremes(const StudySize& size);

// Slabs one to four tets thick with mean free paths from a tenth of the tet size to ten times it,
// against a twice-refined mesh.
StudyTable study_thin_parts(const StudySize& size);

// Neighbouring tets whose kappa differs by up to 1000x: iterations, and whether the error estimate
// still bounds the true error.
StudyTable study_kappa_contrast(const StudySize& size);

// Coarse levels made singular, indefinite or non-finite on purpose: the multires fallbacks.
StudyTable study_coarse_breakdown(const StudySize& size);

// The multigrid V-cycle (multires/multigrid_preconditioner.h) on slivers: where its row-sum lumped
// setup fails and what the absolute-lumping fallback gives.
StudyTable study_multigrid_slivers(const StudySize& size);

// All of the above, in that order.
std::vector<StudyTable> run_stability_studies(const StudySize& size);

}  // namespace waxwork
