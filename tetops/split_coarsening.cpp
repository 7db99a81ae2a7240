#include "tetops/split_coarsening.h"

#include "base/error.h"
#include "tetops/quality.h"
#include "tetops/split_quality.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

namespace waxwork {
namespace {

bool contains(const Tet& tet, int32_t v) { return std::find(tet.begin(), tet.end(), v) != tet.end(); }

}  // namespace

SplitCoarsening collapse_unneeded_split_vertices(TetMesh& mesh, std::vector<int64_t>& labels,
                                                 std::vector<double>& reference_deg,
                                                 std::vector<VertexOrigin>& vertex_origins, size_t first_candidate,
                                                 double keep_angle_deg, double guard_deg) {
    const size_t vertex_count = mesh.vertex_count(), tet_count = mesh.tet_count();
    if (!(keep_angle_deg > 0 && keep_angle_deg < 70) || !(guard_deg >= 0 && guard_deg < 70))
        throw InvalidArgumentError("collapse split vertices: the angles to keep must be in (0, 70) and [0, 70) degrees");
    if (labels.size() != tet_count || reference_deg.size() != tet_count || vertex_origins.size() != vertex_count)
        throw InvalidArgumentError("collapse split vertices: per-tet or per-vertex arrays do not match the mesh");
    SplitCoarsening result;

    // How many vertices name each vertex in their origin; a named vertex must stay.
    std::vector<int32_t> named(vertex_count, 0);
    for (size_t w = first_candidate; w < vertex_count; ++w) {
        const VertexOrigin& o = vertex_origins[w];
        ++named[static_cast<size_t>(o.a)];
        if (o.b != o.a) ++named[static_cast<size_t>(o.b)];
    }
    // Tets around each vertex; entries of dead tets are dropped when a star is read.
    std::vector<std::vector<int32_t>> vertex_tets(vertex_count);
    for (size_t t = 0; t < tet_count; ++t)
        for (int32_t v : mesh.tets[t]) vertex_tets[static_cast<size_t>(v)].push_back(static_cast<int32_t>(t));
    std::vector<uint8_t> tet_alive(tet_count, 1);

    std::vector<int32_t> targets;
    std::vector<double> references;
    for (size_t index = vertex_count; index-- > first_candidate;) {
        const auto v = static_cast<int32_t>(index);
        const VertexOrigin origin = vertex_origins[index];
        if (named[index] > 0 || origin.is_vertex()) continue;
        std::vector<int32_t>& star = vertex_tets[index];
        std::erase_if(star, [&](int32_t t) { return !tet_alive[static_cast<size_t>(t)]; });
        if (star.empty()) continue;
        // On the boundary or on a wall between cells: a face through v must keep its plane.
        if (!kept_faces_at(mesh, star, v, &labels).empty()) continue;

        // Per tet of the star: its reference angle (an untouched tet's own angle: it is about to be
        // reshaped), and the worst angle around v.
        double worst_before = std::numeric_limits<double>::infinity();
        references.clear();
        for (int32_t t : star) {
            const double angle = min_dihedral_angle_deg(mesh, mesh.tets[t]);
            worst_before = std::min(worst_before, angle);
            const double r = reference_deg[static_cast<size_t>(t)];
            references.push_back(std::isnan(r) ? angle : r);
        }
        // The neighbour whose collapse leaves the best worst angle.
        targets.clear();
        for (int32_t t : star)
            for (int32_t w : mesh.tets[t])
                if (w != v) targets.push_back(w);
        std::sort(targets.begin(), targets.end());
        targets.erase(std::unique(targets.begin(), targets.end()), targets.end());
        const double floor_deg = std::min(worst_before, keep_angle_deg);
        int32_t best_target = -1;
        double best_worst = -1;
        for (const int32_t u : targets) {
            bool valid = true;
            double worst = std::numeric_limits<double>::infinity();
            for (size_t i = 0; i < star.size() && valid; ++i) {
                Tet tet = mesh.tets[star[i]];
                if (contains(tet, u)) continue;
                std::replace(tet.begin(), tet.end(), v, u);
                const double angle =
                    signed_volume(mesh.positions[tet[0]], mesh.positions[tet[1]], mesh.positions[tet[2]],
                                  mesh.positions[tet[3]]) > 0
                        ? min_dihedral_angle_deg(mesh, tet)
                        : -1.0;
                // A target whose worst angle cannot beat the best so far is dropped at once.
                valid = angle >= floor_deg && angle >= guard_floor_deg(guard_deg, references[i]) && angle > best_worst;
                worst = std::min(worst, angle);
            }
            if (valid && worst > best_worst) {
                best_target = u;
                best_worst = worst;
            }
        }
        if (best_target < 0) continue;

        for (size_t i = 0; i < star.size(); ++i) {
            const int32_t t = star[i];
            Tet& tet = mesh.tets[t];
            if (contains(tet, best_target)) {
                tet_alive[static_cast<size_t>(t)] = 0;
                continue;
            }
            std::replace(tet.begin(), tet.end(), v, best_target);
            vertex_tets[static_cast<size_t>(best_target)].push_back(t);
            reference_deg[static_cast<size_t>(t)] = references[i];
        }
        star.clear();
        --named[static_cast<size_t>(origin.a)];
        --named[static_cast<size_t>(origin.b)];
        ++result.vertices_collapsed;
    }
    if (result.vertices_collapsed == 0) return result;

    // Compaction, in order: the collapsed vertices are left without a tet, so remove_tets drops them
    // with the dead tets; the arrays the mesh does not hold follow its maps.
    std::vector<uint8_t> dead(tet_count);
    for (size_t t = 0; t < tet_count; ++t) dead[t] = !tet_alive[t];
    const CutResult removed = remove_tets(mesh, dead);
    result.tets_removed = removed.tets_removed;
    for (size_t t = 0; t < removed.new_to_old_tet.size(); ++t) {
        labels[t] = labels[static_cast<size_t>(removed.new_to_old_tet[t])];
        reference_deg[t] = reference_deg[static_cast<size_t>(removed.new_to_old_tet[t])];
    }
    labels.resize(mesh.tet_count());
    reference_deg.resize(mesh.tet_count());
    for (size_t v = 0; v < vertex_count; ++v) {
        const int32_t w = removed.old_to_new_vertex[v];
        if (w < 0) continue;
        const VertexOrigin& o = vertex_origins[v];
        vertex_origins[static_cast<size_t>(w)] = {removed.old_to_new_vertex[static_cast<size_t>(o.a)],
                                                  removed.old_to_new_vertex[static_cast<size_t>(o.b)], o.t};
    }
    vertex_origins.resize(mesh.vertex_count());
    return result;
}

}  // namespace waxwork
