#include "tetops/refine.h"

#include "base/error.h"
#include "base/progress.h"
#include "tetops/connectivity.h"
#include "tetops/paint.h"
#include "tetops/quality.h"
#include "tetops/split_quality.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <tuple>

namespace waxwork {
namespace {

using Edge = std::array<int32_t, 2>;  // lo < hi

bool contains(const Tet& tet, int32_t v) { return tet[0] == v || tet[1] == v || tet[2] == v || tet[3] == v; }

// The bisection state of one refine_tets call. Every change of one mark's refinement is journalled so
// that it can be undone whole (a child under the guard, or the budget passed).
class Bisector {
public:
    Bisector(TetMesh& mesh, double guard_deg, RefineResult& result)
        : mesh_(mesh), guard_deg_(guard_deg), tets_before_(mesh.tet_count()), result_(result) {
        const CompressedRows rows = vertex_elements(mesh.tets, mesh.vertex_count());
        vertex_tets_.resize(mesh.vertex_count());
        for (size_t v = 0; v < mesh.vertex_count(); ++v) {
            const auto row = rows.row(v);
            vertex_tets_[v].assign(row.begin(), row.end());
        }
        reference_deg_.assign(mesh.tet_count(), std::numeric_limits<double>::quiet_NaN());
        bisected_.assign(mesh.tet_count(), 0);
        result_.new_to_old_tet.resize(mesh.tet_count());
        std::iota(result_.new_to_old_tet.begin(), result_.new_to_old_tet.end(), 0);
        result_.vertex_origins.resize(mesh.vertex_count());
        for (size_t v = 0; v < mesh.vertex_count(); ++v)
            result_.vertex_origins[v] = VertexOrigin::vertex(static_cast<int32_t>(v));
    }

    bool bisected(int32_t t) const { return bisected_[t] != 0; }

    void begin() {
        journal_.tets = mesh_.tet_count();
        journal_.vertices = mesh_.vertex_count();
        journal_.modified.clear();
        journal_.flagged.clear();
    }

    void rollback() {
        for (auto it = journal_.modified.rbegin(); it != journal_.modified.rend(); ++it) mesh_.tets[it->first] = it->second;
        const size_t n = journal_.tets;
        mesh_.tets.resize(n);
        if (mesh_.has_materials()) mesh_.materials.resize(n);
        mesh_.original_ids.resize(n);
        mesh_.piece_ids.resize(n);
        result_.new_to_old_tet.resize(n);
        reference_deg_.resize(n);
        mesh_.positions.resize(journal_.vertices);
        result_.vertex_origins.resize(journal_.vertices);
        // Lists of the vertices before may name tets that no longer exist, or whose slot a later tet
        // reuses: tets_around filters them by content, so they can stay.
        vertex_tets_.resize(journal_.vertices);
        for (const int32_t t : journal_.flagged) bisected_[t] = 0;
    }

    // Bisects tet t along its longest edge, with the propagation that keeps the mesh conforming. False
    // when a tet would be created under the guard (the caller rolls back).
    bool refine(int32_t t) { return split_edge(longest_edge(mesh_.tets[t])); }

private:
    // Edges in a strict total order: longer first, ties broken by the vertex indices, so that every tet
    // around an edge agrees on which of its edges is the longest and the propagation cannot cycle (it
    // climbs strictly in this order).
    std::tuple<double, int32_t, int32_t> rank(const Edge& e) const {
        return {(mesh_.positions[e[1]] - mesh_.positions[e[0]]).squaredNorm(), e[0], e[1]};
    }

    Edge longest_edge(const Tet& tet) const {
        Edge best{};
        bool first = true;
        for (const auto& [i, j] : kTetEdges) {
            const Edge e = tet[i] < tet[j] ? Edge{tet[i], tet[j]} : Edge{tet[j], tet[i]};
            if (first || rank(e) > rank(best)) best = e;
            first = false;
        }
        return best;
    }

    // The tets that have edge e now, ascending.
    void tets_around(const Edge& e, std::vector<int32_t>& out) const {
        out.clear();
        for (const int32_t t : vertex_tets_[e[0]])
            if (static_cast<size_t>(t) < mesh_.tet_count() && contains(mesh_.tets[t], e[0]) && contains(mesh_.tets[t], e[1]))
                out.push_back(t);
        std::sort(out.begin(), out.end());
        out.erase(std::unique(out.begin(), out.end()), out.end());
    }

    // Rivara's propagation with an explicit stack: an edge is split once every tet around it has it as
    // its longest edge; a tet around it whose longest edge is another one gets that edge split first.
    // New edges are shorter than the edge they split (a median of a triangle is shorter than its
    // longest side), so the stack holds strictly increasing edges and the loop ends.
    bool split_edge(const Edge& start) {
        std::vector<Edge> stack{start};
        std::vector<int32_t> around;
        while (!stack.empty()) {
            const Edge e = stack.back();
            tets_around(e, around);
            if (around.empty()) {
                stack.pop_back();
                continue;
            }
            bool blocked = false;
            for (const int32_t t : around) {
                const Edge longest = longest_edge(mesh_.tets[t]);
                if (longest != e) {
                    stack.push_back(longest);
                    blocked = true;
                    break;
                }
            }
            if (blocked) continue;
            const auto m = static_cast<int32_t>(mesh_.vertex_count());
            mesh_.positions.push_back(0.5 * (mesh_.positions[e[0]] + mesh_.positions[e[1]]));
            result_.vertex_origins.push_back({e[0], e[1], 0.5});
            vertex_tets_.emplace_back();
            for (const int32_t t : around)
                if (!bisect(t, e, m)) return false;
            stack.pop_back();
        }
        return true;
    }

    // Tet t = (.., a, .., b, ..) becomes (.., a, .., m, ..) in place and (.., m, .., b, ..) is appended:
    // each replaces one vertex by the midpoint of an edge it lies on, which keeps the orientation.
    bool bisect(int32_t t, const Edge& e, int32_t m) {
        const Tet old = mesh_.tets[t];
        double& reference = reference_deg_[t];
        if (std::isnan(reference)) reference = min_dihedral_angle_deg(mesh_, old);  // untouched: its angle before
        Tet kept = old, added = old;
        for (int k = 0; k < 4; ++k) {
            if (old[k] == e[1]) kept[k] = m;
            if (old[k] == e[0]) added[k] = m;
        }
        const double floor_deg = guard_floor_deg(guard_deg_, reference);
        for (const Tet& child : {kept, added}) {
            const auto& p = mesh_.positions;
            if (!(signed_volume(p[child[0]], p[child[1]], p[child[2]], p[child[3]]) > 0)) return false;
            if (guard_deg_ > 0 && min_dihedral_angle_deg(mesh_, child) < floor_deg) return false;
        }
        journal_.modified.emplace_back(t, old);
        if (static_cast<size_t>(t) < tets_before_ && !bisected_[t]) {
            bisected_[t] = 1;
            journal_.flagged.push_back(t);
        }
        const auto n = static_cast<int32_t>(mesh_.tet_count());
        mesh_.tets[t] = kept;
        mesh_.tets.push_back(added);
        if (mesh_.has_materials()) mesh_.materials.push_back(mesh_.materials[t]);
        mesh_.original_ids.push_back(mesh_.original_ids[t]);
        mesh_.piece_ids.push_back(mesh_.piece_ids[t]);
        result_.new_to_old_tet.push_back(result_.new_to_old_tet[t]);
        reference_deg_.push_back(reference);
        vertex_tets_[m].push_back(t);
        for (const int32_t v : added) vertex_tets_[v].push_back(n);
        return true;
    }

    struct Journal {
        size_t tets = 0, vertices = 0;
        std::vector<std::pair<int32_t, Tet>> modified;  // tets changed in place, with their content before
        std::vector<int32_t> flagged;                   // tets before marked as bisected
    };

    TetMesh& mesh_;
    double guard_deg_;
    size_t tets_before_;
    RefineResult& result_;
    // Per vertex: every tet that has it, and possibly tets that no longer do (bisection only appends,
    // so a superset costs nothing to keep and nothing to roll back).
    std::vector<std::vector<int32_t>> vertex_tets_;
    // Per tet: the minimum dihedral angle of the tet before it came from (NaN until it is first split).
    std::vector<double> reference_deg_;
    std::vector<uint8_t> bisected_;  // per tet before: bisected by this call
    Journal journal_;
};

}  // namespace

RefineResult refine_tets(TetMesh& mesh, std::span<const int32_t> marks, const RefineOptions& options,
                         Progress* progress) {
    if (!(options.guard_deg >= 0 && options.guard_deg < 60))
        throw InvalidArgumentError("refine: the angle guard must be in [0, 60) degrees, got " +
                                   number_text(options.guard_deg));
    if (options.max_tets > kMaxRefinedTets)
        throw InvalidArgumentError("refine: a budget of " + std::to_string(options.max_tets) + " tets is above the " +
                                   std::to_string(kMaxRefinedTets) + " a mesh can index");
    if (options.max_tets != 0 && options.max_tets < mesh.tet_count())
        throw InvalidArgumentError("refine: the budget of " + std::to_string(options.max_tets) +
                                   " tets is below the mesh's " + std::to_string(mesh.tet_count()));
    if (mesh.original_ids.size() != mesh.tet_count() || mesh.piece_ids.size() != mesh.tet_count() ||
        (mesh.has_materials() && mesh.materials.size() != mesh.tet_count()))
        throw InvalidArgumentError("refine: the per-tet arrays do not match the tets");
    for (const int32_t t : marks)
        if (t < 0 || static_cast<size_t>(t) >= mesh.tet_count())
            throw InvalidArgumentError("refine: marked tet " + std::to_string(t) + " is out of range (the mesh has " +
                                       std::to_string(mesh.tet_count()) + " tets)");
    const size_t budget = options.max_tets != 0 ? options.max_tets : kMaxRefinedTets;

    const size_t tets_before = mesh.tet_count();
    RefineResult result;
    result.marks = marks.size();
    report_stage(progress, "refining");
    {
        Bisector bisector(mesh, options.guard_deg, result);
        for (size_t i = 0; i < marks.size(); ++i) {
            if (i % 256 == 0) {
                check_cancelled(progress);
                if (progress) progress->set_fraction(static_cast<float>(i) / static_cast<float>(marks.size()));
            }
            const int32_t t = marks[i];
            if (bisector.bisected(t)) {
                ++result.marks_refined;
                continue;
            }
            bisector.begin();
            if (!bisector.refine(t)) {
                bisector.rollback();
                ++result.marks_skipped_guard;
                continue;
            }
            if (mesh.tet_count() > budget) {
                bisector.rollback();
                result.marks_skipped_budget = marks.size() - i;
                break;
            }
            ++result.marks_refined;
        }
    }
    result.bisections = mesh.tet_count() - tets_before;
    result.min_dihedral_deg = mesh_min_dihedral_deg(mesh);
    return result;
}

RefineResult refine_near_points(TetMesh& mesh, std::span<const Eigen::Vector3d> points, double radius,
                                double edge_length, const RefineOptions& options, Progress* progress) {
    if (points.empty()) throw InvalidArgumentError("refine: no points to refine around");
    for (const Eigen::Vector3d& p : points)
        if (!p.allFinite()) throw InvalidArgumentError("refine: a point to refine around is not finite");
    if (!(radius > 0) || !std::isfinite(radius))
        throw InvalidArgumentError("refine: the radius must be a positive number, got " + number_text(radius));
    if (!(edge_length > 0) || !std::isfinite(edge_length))
        throw InvalidArgumentError("refine: the edge length must be a positive number, got " + number_text(edge_length));

    RefineResult total;
    total.new_to_old_tet.resize(mesh.tet_count());
    std::iota(total.new_to_old_tet.begin(), total.new_to_old_tet.end(), 0);
    total.vertex_origins.resize(mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) total.vertex_origins[v] = VertexOrigin::vertex(static_cast<int32_t>(v));
    const double longest_allowed_sq = edge_length * edge_length;
    constexpr int kMaxRounds = 200;  // 3 generations per halving: far beyond any double's range of sizes
    for (int round = 0; round < kMaxRounds; ++round) {
        std::vector<int32_t> marks;
        for (const auto& [t, distance_sq] : PaintIndex(mesh).nearest_within(points, radius)) {
            const Tet& tet = mesh.tets[t];
            double longest_sq = 0;
            for (const auto& [i, j] : kTetEdges)
                longest_sq = std::max(longest_sq, (mesh.positions[tet[i]] - mesh.positions[tet[j]]).squaredNorm());
            if (longest_sq > longest_allowed_sq) marks.push_back(static_cast<int32_t>(t));
        }
        if (marks.empty()) break;
        const size_t vertices_before = mesh.vertex_count();
        RefineResult step = refine_tets(mesh, marks, options, progress);
        total.marks += step.marks;
        total.marks_refined += step.marks_refined;
        total.marks_skipped_guard += step.marks_skipped_guard;
        total.marks_skipped_budget += step.marks_skipped_budget;
        total.bisections += step.bisections;
        for (int32_t& parent : step.new_to_old_tet) parent = total.new_to_old_tet[parent];
        total.new_to_old_tet = std::move(step.new_to_old_tet);
        // Vertices keep their indices: the new ones' origins name vertices of this round's mesh, which
        // are the final mesh's.
        total.vertex_origins.insert(total.vertex_origins.end(), step.vertex_origins.begin() + static_cast<std::ptrdiff_t>(vertices_before),
                                    step.vertex_origins.end());
        if (step.bisections == 0 || step.marks_skipped_budget > 0) break;
    }
    total.min_dihedral_deg = mesh_min_dihedral_deg(mesh);
    return total;
}

}  // namespace waxwork
