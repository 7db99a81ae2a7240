// Cross-section accuracy and quality of the two cut modes: TransCut's remove +
// relaxation against the exact cut, on the same mesh and plane. Cross-section vertices are the
// boundary vertices after the cut that were not on the original boundary (a vertex that was interior,
// or one the exact cut created on an interior edge); their distance to the plane says how well the
// cross-section follows the cut, and the per-tet minimum dihedral angles what it cost in quality.
// `waxwork bench --only cut_modes` charts both distributions (cut_modes.svg, cut_quality.svg).
#pragma once

#include "tetops/cut.h"
#include "tetops/tet_mesh.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace waxwork {

struct CutModeResult {
    std::string mode;                        // "remove+relax" or "exact"
    size_t tets_after = 0;
    double milliseconds = 0;                 // cut (+ relaxation), without the connectivity rebuild
    std::vector<double> distances_per_edge;  // cross-section vertex distances / mean edge length, ascending
    std::vector<double> min_dihedral_deg;    // per tet after the cut, ascending
    size_t tets_under_guard = 0;             // exact mode: ExactCutResult::tets_under_guard
    double max_distance_per_edge() const { return distances_per_edge.empty() ? 0 : distances_per_edge.back(); }
    double rms_distance_per_edge() const;
    double worst_dihedral_deg() const { return min_dihedral_deg.empty() ? 0 : min_dihedral_deg.front(); }
    size_t tets_below(double degrees) const;
};

// Both modes on copies of `mesh`: remove + 10 relaxation sweeps with the 0.5 degree guard, then the
// exact cut (default options).
std::vector<CutModeResult> compare_cut_modes(const TetMesh& mesh, const PlaneCut& plane);

nlohmann::ordered_json to_json(const std::vector<CutModeResult>& results);

}  // namespace waxwork
