#include "tetops/relaxation.h"

#include "base/error.h"
#include "tetops/quality.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace waxwork {
namespace {

// Outcome of one vertex in one sweep, written by the parallel update and counted afterwards so the
// report does not depend on scheduling.
enum class Outcome : uint8_t { Skipped, Moved, Landed, Rejected };

}  // namespace

RelaxationReport relax_cut_vertices(TetMesh& mesh, const TetConnectivity& connectivity,
                                    const CuttingSurface& surface, const RelaxationOptions& options) {
    if (!(options.step > 0) || !std::isfinite(options.step))
        throw InvalidArgumentError("relaxation: the step rho must be a positive number");
    if (!(options.min_dihedral_guard_deg >= 0) || !(options.min_dihedral_guard_deg < 60))
        throw InvalidArgumentError("relaxation: the dihedral guard must be in [0, 60) degrees");
    if (options.max_iterations < 0) throw InvalidArgumentError("relaxation: negative iteration count");
    if (connectivity.vertex_tets.row_count() != mesh.vertex_count() ||
        connectivity.vertex_vertices.row_count() != mesh.vertex_count())
        throw InvalidArgumentError("relaxation: the connectivity was built for a different mesh");

    const size_t vertex_count = mesh.vertex_count();
    const RigidTransform identity;
    // A vertex belongs to the piece of any of its tets (all of them share it).
    auto motion_of = [&](size_t v) -> const RigidTransform& {
        const auto star = connectivity.vertex_tets.row(v);
        if (star.empty() || mesh.piece_ids.size() != mesh.tet_count()) return identity;
        const int32_t piece = mesh.piece_ids[star[0]];
        return piece >= 0 && static_cast<size_t>(piece) < mesh.piece_transforms.size() ? mesh.piece_transforms[piece]
                                                                                      : identity;
    };
    auto to_world = [](const RigidTransform& m, const Eigen::Vector3d& x) -> Eigen::Vector3d {
        return m.rotation * x + m.translation;
    };

    std::vector<uint8_t> movable_flag(vertex_count, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertex_count, 4096), [&](const auto& range) {
        for (size_t v = range.begin(); v != range.end(); ++v)
            movable_flag[v] = !connectivity.vertex_tets.row(v).empty() &&
                              surface.cuts_away(to_world(motion_of(v), mesh.positions[v]));
    });
    std::vector<int32_t> movable;
    for (size_t v = 0; v < vertex_count; ++v)
        if (movable_flag[v]) movable.push_back(static_cast<int32_t>(v));

    RelaxationReport report;
    report.movable_vertices = movable.size();

    // Greedy colouring in index order: vertices of one colour share no edge, hence no tet, so a colour
    // can move in parallel while every acceptance test sees the final positions of its whole star.
    std::vector<int32_t> colour(vertex_count, -1);
    std::vector<std::vector<int32_t>> colour_classes;
    for (int32_t v : movable) {
        std::vector<bool> used(colour_classes.size() + 1, false);
        for (int32_t u : connectivity.vertex_vertices.row(v))
            if (colour[u] >= 0) used[colour[u]] = true;
        const auto c = static_cast<int32_t>(std::find(used.begin(), used.end(), false) - used.begin());
        colour[v] = c;
        if (static_cast<size_t>(c) == colour_classes.size()) colour_classes.emplace_back();
        colour_classes[c].push_back(v);
    }

    std::vector<uint8_t> stopped(vertex_count, 0);
    std::vector<uint8_t> ever_moved(vertex_count, 0);
    std::vector<Outcome> outcome(vertex_count, Outcome::Skipped);
    const double guard = options.min_dihedral_guard_deg;

    auto update = [&](int32_t v) -> Outcome {
        if (stopped[v]) return Outcome::Skipped;
        const auto ring = connectivity.vertex_vertices.row(v);
        if (ring.empty()) return Outcome::Skipped;
        Eigen::Vector3d average = Eigen::Vector3d::Zero();
        for (int32_t u : ring) average += mesh.positions[u];
        average /= static_cast<double>(ring.size());
        const Eigen::Vector3d& x = mesh.positions[v];
        const Eigen::Vector3d proposal = x + options.step * (average - x);
        // The side test is in world space; a rigid motion preserves the step parameter t.
        const RigidTransform& motion = motion_of(v);
        const double t = surface.step_to_surface(to_world(motion, x), to_world(motion, proposal));
        const bool lands = t < 1.0;
        const Eigen::Vector3d target = x + t * (proposal - x);
        if (target == x) {
            if (lands) stopped[v] = 1;  // already on the surface: nothing left to do
            return Outcome::Skipped;
        }
        for (int32_t tet_index : connectivity.vertex_tets.row(v)) {
            std::array<Eigen::Vector3d, 4> p;
            for (int k = 0; k < 4; ++k) {
                const int32_t w = mesh.tets[tet_index][k];
                p[k] = w == v ? target : mesh.positions[w];
            }
            if (!(signed_volume(p[0], p[1], p[2], p[3]) > 0)) return Outcome::Rejected;
            if (guard > 0) {
                const double after = min_dihedral_angle_deg(p[0], p[1], p[2], p[3]);
                if (after < guard) {
                    const Tet& tet = mesh.tets[tet_index];
                    const double before = min_dihedral_angle_deg(mesh, tet);
                    if (after < before) return Outcome::Rejected;
                }
            }
        }
        mesh.positions[v] = target;
        if (lands) stopped[v] = 1;
        return lands ? Outcome::Landed : Outcome::Moved;
    };

    for (int iteration = 0; iteration < options.max_iterations && !movable.empty(); ++iteration) {
        report.iterations = iteration + 1;
        size_t accepted = 0;
        for (const std::vector<int32_t>& members : colour_classes) {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, members.size(), 64), [&](const auto& range) {
                for (size_t i = range.begin(); i != range.end(); ++i) outcome[members[i]] = update(members[i]);
            });
            for (int32_t v : members) {
                switch (outcome[v]) {
                    case Outcome::Landed: ++report.vertices_on_surface; [[fallthrough]];
                    case Outcome::Moved: ++accepted; ever_moved[v] = 1; break;
                    case Outcome::Rejected: ++report.moves_rejected; break;
                    case Outcome::Skipped: break;
                }
            }
        }
        report.moves_accepted += accepted;
        if (accepted == 0) break;
    }
    for (int32_t v : movable) report.vertices_moved += ever_moved[v];
    report.min_dihedral_deg = mesh_min_dihedral_deg(mesh);
    return report;
}

}  // namespace waxwork
