#include "tetops/refine.h"

#include "base/error.h"
#include "base/progress.h"
#include "tetops/connectivity.h"
#include "tetops/quality.h"
#include "tetops/split_quality.h"

#include <tbb/parallel_for.h>

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

// The maps of a refinement that has not changed anything yet: every tet and vertex is itself.
void start_maps(const TetMesh& mesh, RefineResult& result) {
    result.new_to_old_tet.resize(mesh.tet_count());
    std::iota(result.new_to_old_tet.begin(), result.new_to_old_tet.end(), 0);
    result.vertex_origins.resize(mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) result.vertex_origins[v] = VertexOrigin::vertex(static_cast<int32_t>(v));
}

// The bisection state of one refine_tets call. Every change of one mark's refinement is journalled so
// that it can be undone whole (a child under the guard, or the budget passed).
class Bisector {
public:
    Bisector(TetMesh& mesh, double guard_deg, RefineResult& result)
        : mesh_(mesh), guard_deg_(guard_deg), result_(result) {
        const CompressedRows rows = vertex_elements(mesh.tets, mesh.vertex_count());
        vertex_tets_.resize(mesh.vertex_count());
        for (size_t v = 0; v < mesh.vertex_count(); ++v) {
            const auto row = rows.row(v);
            vertex_tets_[v].assign(row.begin(), row.end());
        }
        reference_deg_.assign(mesh.tet_count(), std::numeric_limits<double>::quiet_NaN());
        stamp_.assign(mesh.tet_count(), 0);
        start_maps(mesh, result_);
    }

    // Marks name tets of the mesh as a round starts; a round's marks of tets its earlier marks already
    // bisected do nothing more.
    void next_round() { ++round_; }
    bool bisected(int32_t t) const { return stamp_[t] == round_; }

    // The tets bisected (in place or appended) since the last call, ascending, each once.
    std::vector<int32_t> take_touched() {
        std::vector<int32_t> touched = std::move(touched_);
        touched_.clear();
        std::sort(touched.begin(), touched.end());
        touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
        return touched;
    }

    // Refines the marks in order, each a transaction; counts into the result.
    void apply_marks(std::span<const int32_t> marks, size_t budget, Progress* progress) {
        result_.marks += marks.size();
        for (size_t i = 0; i < marks.size(); ++i) {
            if (i % 256 == 0) {
                check_cancelled(progress);
                if (progress) progress->set_fraction(static_cast<float>(i) / static_cast<float>(marks.size()));
            }
            const int32_t t = marks[i];
            if (bisected(t)) {
                ++result_.marks_refined;
                continue;
            }
            begin();
            if (!refine(t)) {
                rollback();
                ++result_.marks_skipped_guard;
                continue;
            }
            if (mesh_.tet_count() > budget) {
                rollback();
                result_.marks_skipped_budget += marks.size() - i;
                break;
            }
            ++result_.marks_refined;
        }
    }

private:
    void begin() {
        journal_.tets = mesh_.tet_count();
        journal_.vertices = mesh_.vertex_count();
        journal_.touched = touched_.size();
        journal_.modified.clear();
        journal_.stamps.clear();
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
        stamp_.resize(n);
        for (auto it = journal_.stamps.rbegin(); it != journal_.stamps.rend(); ++it) stamp_[it->first] = it->second;
        touched_.resize(journal_.touched);
    }

    // Bisects tet t along its longest edge, with the propagation that keeps the mesh conforming. False
    // when a tet would be created under the guard (the caller rolls back).
    bool refine(int32_t t) { return split_edge(longest_edge(mesh_.tets[t])); }

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
        if (stamp_[t] != round_) {
            journal_.stamps.emplace_back(t, stamp_[t]);
            stamp_[t] = round_;
        }
        const auto n = static_cast<int32_t>(mesh_.tet_count());
        mesh_.tets[t] = kept;
        mesh_.tets.push_back(added);
        if (mesh_.has_materials()) mesh_.materials.push_back(mesh_.materials[t]);
        mesh_.original_ids.push_back(mesh_.original_ids[t]);
        mesh_.piece_ids.push_back(mesh_.piece_ids[t]);
        result_.new_to_old_tet.push_back(result_.new_to_old_tet[t]);
        reference_deg_.push_back(reference);
        stamp_.push_back(round_);
        touched_.push_back(t);
        touched_.push_back(n);
        vertex_tets_[m].push_back(t);
        for (const int32_t v : added) vertex_tets_[v].push_back(n);
        return true;
    }

    struct Journal {
        size_t tets = 0, vertices = 0, touched = 0;
        std::vector<std::pair<int32_t, Tet>> modified;    // tets changed in place, with their content before
        std::vector<std::pair<int32_t, uint32_t>> stamps; // tets stamped, with their stamp before
    };

    TetMesh& mesh_;
    double guard_deg_;
    RefineResult& result_;
    // Per vertex: every tet that has it, and possibly tets that no longer do (bisection only appends,
    // so a superset costs nothing to keep and nothing to roll back).
    std::vector<std::vector<int32_t>> vertex_tets_;
    // Per tet: the minimum dihedral angle of the tet before it came from (NaN until it is first split).
    std::vector<double> reference_deg_;
    // Per tet: the round in which it was last bisected (0: never, in this call).
    std::vector<uint32_t> stamp_;
    uint32_t round_ = 0;
    std::vector<int32_t> touched_;
    Journal journal_;
};

// Throws for options refine_tets refuses; returns the budget (kMaxRefinedTets for none).
size_t checked_budget(const TetMesh& mesh, const RefineOptions& options) {
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
    return options.max_tets != 0 ? options.max_tets : kMaxRefinedTets;
}

}  // namespace

RefineResult refine_tets(TetMesh& mesh, std::span<const int32_t> marks, const RefineOptions& options,
                         Progress* progress) {
    const size_t budget = checked_budget(mesh, options);
    for (const int32_t t : marks)
        if (t < 0 || static_cast<size_t>(t) >= mesh.tet_count())
            throw InvalidArgumentError("refine: marked tet " + std::to_string(t) + " is out of range (the mesh has " +
                                       std::to_string(mesh.tet_count()) + " tets)");

    const size_t tets_before = mesh.tet_count();
    RefineResult result;
    report_stage(progress, "refining");
    {
        Bisector bisector(mesh, options.guard_deg, result);
        bisector.next_round();
        bisector.apply_marks(marks, budget, progress);
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

    const size_t budget = checked_budget(mesh, options);

    // Inside when the tet's centroid (world space) is within `radius` of a point: a box around the
    // points first, then the points one by one.
    Eigen::Vector3d lo = points[0], hi = points[0];
    for (const Eigen::Vector3d& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    lo.array() -= radius;
    hi.array() += radius;
    const double radius_sq = radius * radius, longest_allowed_sq = edge_length * edge_length;
    const RigidTransform identity;
    const auto wanted = [&](int32_t t) {
        const Tet& tet = mesh.tets[t];
        const int32_t piece = mesh.piece_ids[t];
        const RigidTransform& frame =
            piece >= 0 && static_cast<size_t>(piece) < mesh.piece_transforms.size() ? mesh.piece_transforms[piece] : identity;
        const Eigen::Vector3d c = frame.rotation * (0.25 * (mesh.positions[tet[0]] + mesh.positions[tet[1]] +
                                                            mesh.positions[tet[2]] + mesh.positions[tet[3]])) +
                                  frame.translation;
        if ((c.array() < lo.array()).any() || (c.array() > hi.array()).any()) return false;
        double longest_sq = 0;
        for (const auto& [i, j] : kTetEdges)
            longest_sq = std::max(longest_sq, (mesh.positions[tet[i]] - mesh.positions[tet[j]]).squaredNorm());
        if (!(longest_sq > longest_allowed_sq)) return false;
        for (const Eigen::Vector3d& p : points)
            if ((c - p).squaredNorm() < radius_sq) return true;
        return false;
    };

    const auto marks_among = [&](const std::vector<int32_t>& candidates) {
        std::vector<uint8_t> keep(candidates.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size(), 4096), [&](const auto& range) {
            for (size_t i = range.begin(); i != range.end(); ++i) keep[i] = wanted(candidates[i]);
        });
        std::vector<int32_t> marks;
        for (size_t i = 0; i < candidates.size(); ++i)
            if (keep[i]) marks.push_back(candidates[i]);
        return marks;
    };

    const size_t tets_before = mesh.tet_count();
    RefineResult total;
    report_stage(progress, "refining");
    // The first round looks at every tet; later ones only at those the previous round bisected (the
    // others were too short, out of reach, or skipped by the guard, and are unchanged).
    std::vector<int32_t> all(mesh.tet_count());
    std::iota(all.begin(), all.end(), 0);
    std::vector<int32_t> marks = marks_among(all);
    if (marks.empty()) {
        start_maps(mesh, total);  // nothing to do: no bisection state to build
    } else {
        Bisector bisector(mesh, options.guard_deg, total);
        constexpr int kMaxRounds = 200;  // 3 generations per halving: far beyond any double's range of sizes
        for (int round = 0; round < kMaxRounds && !marks.empty(); ++round) {
            const size_t skipped_budget = total.marks_skipped_budget;
            bisector.next_round();
            bisector.apply_marks(marks, budget, progress);
            if (total.marks_skipped_budget > skipped_budget) break;
            marks = marks_among(bisector.take_touched());
        }
    }
    total.bisections = mesh.tet_count() - tets_before;
    total.min_dihedral_deg = mesh_min_dihedral_deg(mesh);
    return total;
}

}  // namespace waxwork
