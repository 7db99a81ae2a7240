#include "bench/studies/cut_study.h"

#include "base/timing.h"
#include "tetops/connectivity.h"
#include "tetops/exact_cut.h"
#include "tetops/quality.h"
#include "tetops/relaxation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <utility>

namespace waxwork {
namespace {

// Distances of the cross-section vertices (boundary now, not on the original boundary) to the plane.
std::vector<double> cross_section_distances(const TetMesh& mesh, const std::vector<uint8_t>& on_original_boundary,
                                            const PlaneCut& plane, double edge) {
    const TetConnectivity after = build_connectivity(mesh);
    std::vector<double> distances;
    for (int32_t v : after.boundary_vertices)
        if (!on_original_boundary[v]) distances.push_back(std::abs(plane.side(mesh.positions[v])) / edge);
    std::sort(distances.begin(), distances.end());
    return distances;
}

}  // namespace

double CutModeResult::rms_distance_per_edge() const {
    double sum = 0;
    for (double d : distances_per_edge) sum += d * d;
    return distances_per_edge.empty() ? 0 : std::sqrt(sum / static_cast<double>(distances_per_edge.size()));
}

size_t CutModeResult::tets_below(double degrees) const {
    return static_cast<size_t>(std::lower_bound(min_dihedral_deg.begin(), min_dihedral_deg.end(), degrees) -
                               min_dihedral_deg.begin());
}

std::vector<CutModeResult> compare_cut_modes(const TetMesh& source, const PlaneCut& plane) {
    const TetConnectivity before = build_connectivity(source);
    const double edge = measure_quality(source).mean_edge_length;
    std::set<std::pair<int32_t, int32_t>> boundary_edges;
    for (const BoundaryFace& f : before.boundary_faces)
        for (int k = 0; k < 3; ++k) {
            const int32_t a = f.vertices[k], b = f.vertices[(k + 1) % 3];
            boundary_edges.insert({std::min(a, b), std::max(a, b)});
        }

    std::vector<CutModeResult> results(2);
    {
        CutModeResult& r = results[0];
        r.mode = "remove+relax";
        TetMesh mesh = source;
        const auto start = std::chrono::steady_clock::now();
        const CutResult cut = remove_cut_away_tets(mesh, plane);
        relax_cut_vertices(mesh, build_connectivity(mesh), plane);
        r.milliseconds = milliseconds_since(start);
        std::vector<uint8_t> on_original_boundary(mesh.vertex_count(), 0);
        for (size_t v = 0; v < cut.old_to_new_vertex.size(); ++v)
            if (cut.old_to_new_vertex[v] >= 0) on_original_boundary[cut.old_to_new_vertex[v]] = before.is_boundary_vertex[v];
        r.distances_per_edge = cross_section_distances(mesh, on_original_boundary, plane, edge);
        r.min_dihedral_deg = min_dihedral_angles_deg(mesh);
        std::sort(r.min_dihedral_deg.begin(), r.min_dihedral_deg.end());
        r.tets_after = mesh.tet_count();
    }
    {
        CutModeResult& r = results[1];
        r.mode = "exact";
        TetMesh mesh = source;
        const auto start = std::chrono::steady_clock::now();
        const ExactCutResult cut = cut_exact(mesh, plane);
        r.milliseconds = milliseconds_since(start);
        r.tets_under_guard = cut.tets_under_guard;
        std::vector<uint8_t> on_original_boundary(mesh.vertex_count(), 0);
        for (size_t v = 0; v < mesh.vertex_count(); ++v) {
            const auto [a, b, t] = cut.vertex_origins[v];
            on_original_boundary[v] = a == b ? before.is_boundary_vertex[a]
                                             : boundary_edges.count({std::min(a, b), std::max(a, b)}) > 0;
        }
        r.distances_per_edge = cross_section_distances(mesh, on_original_boundary, plane, edge);
        r.min_dihedral_deg = min_dihedral_angles_deg(mesh);
        std::sort(r.min_dihedral_deg.begin(), r.min_dihedral_deg.end());
        r.tets_after = mesh.tet_count();
    }
    return results;
}

nlohmann::ordered_json to_json(const std::vector<CutModeResult>& results) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const CutModeResult& r : results) {
        nlohmann::ordered_json row = {{"mode", r.mode},
                                      {"tets_after", r.tets_after},
                                      {"milliseconds", r.milliseconds},
                                      {"cross_section_vertices", r.distances_per_edge.size()},
                                      {"max_distance_per_edge", r.max_distance_per_edge()},
                                      {"rms_distance_per_edge", r.rms_distance_per_edge()},
                                      {"worst_dihedral_deg", r.worst_dihedral_deg()},
                                      {"tets_below_0.5_deg", r.tets_below(0.5)},
                                      {"tets_below_5_deg", r.tets_below(5.0)}};
        if (r.mode == "exact") row["tets_under_guard"] = r.tets_under_guard;
        out.push_back(std::move(row));
    }
    return out;
}

}  // namespace waxwork
