#include "tetops/exact_cut.h"

#include "base/error.h"
#include "tetops/connectivity.h"
#include "tetops/quality.h"
#include "tetops/split_quality.h"
#include "tetops/vertex_map.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <string>
#include <tuple>

namespace waxwork {
namespace {

uint64_t edge_key(int32_t a, int32_t b) {
    const auto lo = static_cast<uint32_t>(std::min(a, b));
    const auto hi = static_cast<uint32_t>(std::max(a, b));
    return (uint64_t{lo} << 32) | hi;
}

int sign_of(double v) { return v > 0 ? 1 : (v < 0 ? -1 : 0); }

bool crosses(int si, int sj) { return si * sj < 0; }

Eigen::Vector3d to_rest(const TetMesh& mesh, int32_t piece, const Eigen::Vector3d& world) {
    if (piece < 0 || static_cast<size_t>(piece) >= mesh.piece_transforms.size()) return world;
    const RigidTransform& m = mesh.piece_transforms[piece];
    return m.rotation.transpose() * (world - m.translation);
}

// The tets a crossed tet splits into, each with the side it lies on. The two parts of the tet (the
// intersection with either side) are convex; each is tetrahedralised by coning from its lowest vertex
// index over the faces that do not contain it, every face being fanned from its own lowest index. A
// face's triangulation therefore depends only on its vertex set, so a face shared with the neighbour
// tet (or the cross-section shared by the two parts) is split identically on both sides: the result
// is conforming without looking at the neighbours.
struct Child {
    Tet tet;
    bool positive;
};

void split_tet(const Tet& g, const std::array<int, 4>& s, const std::array<int32_t, 6>& cut_vertex,
               std::vector<Child>& out) {
    // The cross-section polygon: vertices on the surface and crossing points, in cyclic order. With
    // two vertices on each side the four crossings form a quad: consecutive crossings share a vertex.
    std::vector<int32_t> cap;
    std::array<int, 2> pos{}, neg{};
    int n_pos = 0, n_neg = 0;
    for (int i = 0; i < 4; ++i) {
        if (s[i] == 0) cap.push_back(g[i]);
        if (s[i] > 0) pos[n_pos < 2 ? n_pos : 1] = i, ++n_pos;
        if (s[i] < 0) neg[n_neg < 2 ? n_neg : 1] = i, ++n_neg;
    }
    if (n_pos == 2 && n_neg == 2) {
        const auto c = [&](int p, int n) { return cut_vertex[tet_edge_index(pos[p], neg[n])]; };
        cap = {c(0, 0), c(0, 1), c(1, 1), c(1, 0)};
    } else {
        for (int e = 0; e < 6; ++e)
            if (cut_vertex[e] >= 0) cap.push_back(cut_vertex[e]);
    }

    for (int side : {1, -1}) {
        // Faces of this part: the tet's faces clipped to the side, plus the cross-section.
        std::vector<std::vector<int32_t>> faces;
        for (const auto& f : kTetFaces) {
            std::vector<int32_t> polygon;
            bool has_strict = false;
            for (int k = 0; k < 3; ++k) {
                const int i = f[k], j = f[(k + 1) % 3];
                if (side * s[i] >= 0) polygon.push_back(g[i]);
                if (side * s[i] > 0) has_strict = true;
                if (crosses(s[i], s[j])) polygon.push_back(cut_vertex[tet_edge_index(i, j)]);
            }
            if (polygon.size() >= 3 && has_strict) faces.push_back(std::move(polygon));
        }
        faces.push_back(cap);
        int32_t apex = std::numeric_limits<int32_t>::max();
        for (const auto& face : faces)
            for (int32_t v : face) apex = std::min(apex, v);
        for (auto face : faces) {
            if (std::find(face.begin(), face.end(), apex) != face.end()) continue;
            std::rotate(face.begin(), std::min_element(face.begin(), face.end()), face.end());
            for (size_t k = 1; k + 1 < face.size(); ++k) out.push_back({{apex, face[0], face[k], face[k + 1]}, side > 0});
        }
    }
}

// Whether v may slide towards w: the step must stay in the plane of every kept face at v (so every
// wall, flat part and straight crease of the boundary keeps its shape) and run along an edge of a
// boundary face (of a wall face when v is on walls only), never into the volume. Where the boundary faces at v
// are all within max_bend_deg of each other (a smooth, curved surface rather than a crease), steps
// up to max_bend_deg out of their planes are allowed: the outer surface then changes slightly.
bool may_slide(const TetMesh& mesh, const std::vector<KeptFace>& faces, int32_t v, int32_t w, double max_bend_deg) {
    const Eigen::Vector3d step = mesh.positions[w] - mesh.positions[v];
    auto normal = [&](const KeptFace& face) -> Eigen::Vector3d {
        const auto& f = face.vertices;
        return (mesh.positions[f[1]] - mesh.positions[f[0]]).cross(mesh.positions[f[2]] - mesh.positions[f[0]]);
    };
    const double bend_sine = std::sin(max_bend_deg * std::numbers::pi / 180.0);
    const double bend_cosine = std::cos(max_bend_deg * std::numbers::pi / 180.0);
    bool smooth = max_bend_deg > 0;
    Eigen::Vector3d reference = Eigen::Vector3d::Zero();
    for (const KeptFace& face : faces) {
        if (!face.on_boundary) continue;
        const Eigen::Vector3d n = normal(face);
        if (reference.isZero()) reference = n;
        smooth = smooth && n.dot(reference) >= bend_cosine * n.norm() * reference.norm();
    }
    // On the boundary the step runs along a boundary edge (else it could cut into the volume at up to
    // the bend angle); on walls only, along a wall edge.
    const bool on_boundary = std::any_of(faces.begin(), faces.end(), [](const KeptFace& f) { return f.on_boundary; });
    bool along_a_face = false;
    for (const KeptFace& face : faces) {
        const auto& f = face.vertices;
        if (face.on_boundary == on_boundary) along_a_face |= std::find(f.begin(), f.end(), w) != f.end();
        const Eigen::Vector3d n = normal(face);
        const double limit = face.on_boundary && smooth ? std::max(bend_sine, 1e-12) : 1e-12;
        if (std::abs(n.dot(step)) > limit * n.norm() * step.norm()) return false;
    }
    return along_a_face;
}

// A crossing this close to a boundary vertex (as a fraction of its edge) is snapped to even where the
// boundary lets no edge slide (snap_vertices): small enough to leave the shape of the volume as it is
// to the eye (1e-3 of an edge, 68 times less than a slide at the default bend may move it), large
// enough to catch the near-degenerate crossings that rounding, relaxation and earlier cuts leave next
// to a corner or a wall. Random edit sequences found 4e-9 of an edge (a 3e-6 degree sliver), 3e-6 next
// to a cube's corner (0.004 degrees) and 1e-3 next to a relaxed cross-section (0.014 degrees);
// LiveSolver.RandomEditSequences* in tests/scene/live_solver_test.cpp.
constexpr double kHairline = 1e-3;

// Moves vertices whose crossing is within snap_fraction of them onto the surface when the guard on
// their star allows it. Sequential in vertex order (deterministic); only vertices next to the
// surface are involved, a small fraction of the mesh. A vertex on the boundary of the volume or on a
// wall between regions only slides along an edge of those faces that stays in their planes (may_slide),
// so the volume and earlier walls keep their shape; where no such edge reaches the surface the edges
// are split instead, unless the crossing lies within kHairline of a boundary vertex.
size_t snap_vertices(TetMesh& mesh, std::vector<Eigen::Vector3d>& world, std::vector<double>& values,
                     const std::vector<int32_t>& crossed, const std::vector<int>& sign, const SplitField& field,
                     const SplitOptions& options, const std::vector<int32_t>& piece_of,
                     std::vector<double>& reference, std::vector<uint8_t>& touched) {
    struct Candidate {
        int32_t vertex;
        int32_t other;  // the far end of the edge the crossing is on
        double fraction;
        Eigen::Vector3d target;  // world
    };
    std::vector<Candidate> candidates;
    for (int32_t t : crossed) {
        const Tet& tet = mesh.tets[t];
        for (const auto& e : kTetEdges) {
            const int32_t a = std::min(tet[e[0]], tet[e[1]]), b = std::max(tet[e[0]], tet[e[1]]);
            if (!crosses(sign[a], sign[b])) continue;
            const double u = field.crossing(world[a], world[b], values[a], values[b]);
            const Eigen::Vector3d point = world[a] + u * (world[b] - world[a]);
            if (u < options.snap_fraction) candidates.push_back({a, b, u, point});
            if (1 - u < options.snap_fraction) candidates.push_back({b, a, 1 - u, point});
        }
    }
    if (candidates.empty()) return 0;
    // Per vertex its crossings nearest first; duplicates (one per tet around the edge) dropped.
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
        return std::tie(x.vertex, x.fraction, x.other) < std::tie(y.vertex, y.fraction, y.other);
    });
    candidates.erase(std::unique(candidates.begin(), candidates.end(),
                                 [](const Candidate& x, const Candidate& y) {
                                     return x.vertex == y.vertex && x.other == y.other;
                                 }),
                     candidates.end());

    // Stars of the candidates only.
    std::vector<int32_t> slot(mesh.vertex_count(), -1);
    int32_t slots = 0;
    for (const Candidate& c : candidates)
        if (slot[c.vertex] < 0) slot[c.vertex] = slots++;
    std::vector<std::vector<int32_t>> star(slots);
    for (size_t t = 0; t < mesh.tet_count(); ++t)
        for (int32_t v : mesh.tets[t])
            if (slot[v] >= 0) star[slot[v]].push_back(static_cast<int32_t>(t));

    // A tet's reference is taken the first time it is touched (split_quality.h): the guard holds when
    // every tet of the star stays at or above min(guard, reference) or does not get worse.
    auto guard_holds = [&](int32_t v, const Eigen::Vector3d& target) {
        for (int32_t t : star[slot[v]]) {
            const Tet& tet = mesh.tets[t];
            std::array<Eigen::Vector3d, 4> p;
            for (int k = 0; k < 4; ++k) p[k] = tet[k] == v ? target : mesh.positions[tet[k]];
            if (!(signed_volume(p[0], p[1], p[2], p[3]) > 0)) return false;
            const double after = min_dihedral_angle_deg(p[0], p[1], p[2], p[3]);
            if (after >= options.min_dihedral_guard_deg) continue;
            const double before = min_dihedral_angle_deg(mesh, tet);
            const double floor =
                guard_floor_deg(options.min_dihedral_guard_deg, std::isnan(reference[t]) ? before : reference[t]);
            if (after < floor && after < before) return false;
        }
        return true;
    };

    size_t snapped = 0;
    for (size_t begin = 0; begin < candidates.size();) {
        const int32_t v = candidates[begin].vertex;
        size_t end = begin;
        while (end < candidates.size() && candidates[end].vertex == v) ++end;
        const std::vector<KeptFace> kept = kept_faces_at(mesh, star[slot[v]], v, options.tet_labels);
        std::optional<Eigen::Vector3d> target_world;
        if (kept.empty()) {
            target_world = field.project(world[v]);
            if (!target_world) target_world = candidates[begin].target;
        } else {
            for (size_t i = begin; i < end && !target_world; ++i)
                if (may_slide(mesh, kept, v, candidates[i].other, options.boundary_bend_deg))
                    target_world = candidates[i].target;
            // Where no boundary edge may slide (a corner, a crease, a bumpy part such as a relaxed
            // cut's cross-section), a crossing a hair's breadth from the vertex would still be split
            // off as a sliver of almost no angle. A step to it along its own edge moves the outer
            // surface by at most kHairline of an edge, far below what a slide may (sin(bend) x
            // snap_fraction); walls between cells keep their planes, and bend 0 keeps the surface exactly.
            const bool on_walls = std::any_of(kept.begin(), kept.end(), [](const KeptFace& f) { return !f.on_boundary; });
            if (!target_world && !on_walls && options.boundary_bend_deg > 0 && candidates[begin].fraction <= kHairline)
                target_world = candidates[begin].target;
        }
        begin = end;
        if (!target_world || values[v] == 0) continue;
        const Eigen::Vector3d target = to_rest(mesh, piece_of[v], *target_world);
        if (!guard_holds(v, target)) continue;
        for (int32_t t : star[slot[v]]) {
            if (std::isnan(reference[t])) {
                const Tet& tet = mesh.tets[t];
                reference[t] = min_dihedral_angle_deg(mesh, tet);
            }
            touched[t] = 1;
        }
        mesh.positions[v] = target;
        world[v] = *target_world;
        values[v] = 0;
        ++snapped;
    }
    return snapped;
}

std::vector<int32_t> find_crossed_tets(const TetMesh& mesh, const std::vector<int>& sign) {
    std::vector<uint8_t> flag(mesh.tet_count(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.tet_count(), 4096), [&](const auto& range) {
        for (size_t t = range.begin(); t != range.end(); ++t) {
            bool any_pos = false, any_neg = false;
            for (int32_t v : mesh.tets[t]) {
                any_pos |= sign[v] > 0;
                any_neg |= sign[v] < 0;
            }
            flag[t] = any_pos && any_neg;
        }
    });
    std::vector<int32_t> crossed;
    for (size_t t = 0; t < flag.size(); ++t)
        if (flag[t]) crossed.push_back(static_cast<int32_t>(t));
    return crossed;
}

std::vector<int> signs_of(const std::vector<double>& values, double tolerance, std::vector<double>& mutable_values) {
    std::vector<int> sign(values.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, values.size(), 4096), [&](const auto& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) {
            if (std::abs(mutable_values[v]) <= tolerance) mutable_values[v] = 0;
            sign[v] = sign_of(mutable_values[v]);
        }
    });
    return sign;
}

}  // namespace

SplitReport split_along_field(TetMesh& mesh, std::vector<Eigen::Vector3d>& world, std::vector<double>& values,
                              const SplitField& field, const SplitOptions& options) {
    if (world.size() != mesh.vertex_count() || values.size() != mesh.vertex_count())
        throw InvalidArgumentError("split: one world position and one field value per vertex expected");
    if (!(options.snap_fraction >= 0) || !(options.snap_fraction < 0.5))
        throw InvalidArgumentError("split: the snap fraction must be in [0, 0.5)");
    if (!(options.min_dihedral_guard_deg >= 0) || !(options.min_dihedral_guard_deg < 60))
        throw InvalidArgumentError("split: the dihedral guard must be in [0, 60) degrees");
    if (!(options.zero_tolerance >= 0)) throw InvalidArgumentError("split: negative zero tolerance");
    if (!(options.boundary_bend_deg >= 0) || !(options.boundary_bend_deg < 90))
        throw InvalidArgumentError("split: the boundary bend must be in [0, 90) degrees");
    if (options.tet_labels && options.tet_labels->size() != mesh.tet_count())
        throw InvalidArgumentError("split: one label per tet expected");
    if (options.reference_deg && options.reference_deg->size() != mesh.tet_count())
        throw InvalidArgumentError("split: one reference angle per tet expected");
    if (!(options.smooth_below_deg >= 0) || !(options.smooth_below_deg < 70))
        throw InvalidArgumentError("split: the smoothing target must be in [0, 70) degrees");
    for (double v : values)
        if (!std::isfinite(v)) throw InvalidArgumentError("split: non-finite field value");

    SplitReport report;
    std::vector<double>& reference = report.reference_deg;
    if (options.reference_deg)
        reference = *options.reference_deg;
    else
        reference.assign(mesh.tet_count(), std::numeric_limits<double>::quiet_NaN());
    std::vector<uint8_t> touched(mesh.tet_count(), 0);  // new or moved by this split
    const std::vector<int32_t> piece_of = vertex_pieces(mesh);
    std::vector<int> sign = signs_of(values, options.zero_tolerance, values);
    std::vector<int32_t> crossed = find_crossed_tets(mesh, sign);
    if (options.snap_fraction > 0 && !crossed.empty()) {
        report.vertices_snapped = snap_vertices(mesh, world, values, crossed, sign, field, options, piece_of,
                                                reference, touched);
        if (report.vertices_snapped > 0) {
            sign = signs_of(values, options.zero_tolerance, values);
            crossed = find_crossed_tets(mesh, sign);
        }
    }

    // One new vertex per crossed edge, numbered in edge order so the result does not depend on the
    // order tets are visited in.
    std::vector<uint64_t> keys;
    for (int32_t t : crossed) {
        const Tet& tet = mesh.tets[t];
        for (const auto& e : kTetEdges)
            if (crosses(sign[tet[e[0]]], sign[tet[e[1]]])) keys.push_back(edge_key(tet[e[0]], tet[e[1]]));
    }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    const size_t first_new = mesh.vertex_count();
    mesh.positions.resize(first_new + keys.size());
    world.resize(first_new + keys.size());
    values.resize(first_new + keys.size(), 0.0);
    report.appended_vertex_origins.resize(keys.size());
    tbb::parallel_for(size_t{0}, keys.size(), [&](size_t i) {
        const auto a = static_cast<int32_t>(keys[i] >> 32), b = static_cast<int32_t>(keys[i] & 0xffffffffu);
        const double u = std::clamp(field.crossing(world[a], world[b], values[a], values[b]), 0.0, 1.0);
        mesh.positions[first_new + i] = mesh.positions[a] + u * (mesh.positions[b] - mesh.positions[a]);
        world[first_new + i] = world[a] + u * (world[b] - world[a]);
        report.appended_vertex_origins[i] = {a, b, u};
    });
    auto new_vertex = [&](int32_t a, int32_t b) {
        const uint64_t key = edge_key(a, b);
        return static_cast<int32_t>(first_new + (std::lower_bound(keys.begin(), keys.end(), key) - keys.begin()));
    };

    const size_t tets_before = mesh.tet_count();
    report.positive.resize(tets_before);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tets_before, 4096), [&](const auto& range) {
        for (size_t t = range.begin(); t != range.end(); ++t) {
            bool any_pos = false;
            for (int32_t v : mesh.tets[t]) any_pos |= sign[v] > 0;
            report.positive[t] = any_pos;  // crossed tets are overwritten below
        }
    });
    const bool has_materials = mesh.materials.size() == tets_before;
    const bool has_original_ids = mesh.original_ids.size() == tets_before;
    const bool has_piece_ids = mesh.piece_ids.size() == tets_before;
    for (int32_t t : crossed) {
        if (std::isnan(reference[t])) {
            const Tet& tet = mesh.tets[t];
            reference[t] = min_dihedral_angle_deg(mesh, tet);
        }
        touched[t] = 1;
    }
    std::vector<Child> children;
    for (int32_t t : crossed) {
        const Tet parent = mesh.tets[t];
        std::array<int, 4> s;
        for (int k = 0; k < 4; ++k) s[k] = sign[parent[k]];
        std::array<int32_t, 6> cut_vertex;
        for (int e = 0; e < 6; ++e) {
            const int i = kTetEdges[e][0], j = kTetEdges[e][1];
            cut_vertex[e] = crosses(s[i], s[j]) ? new_vertex(parent[i], parent[j]) : -1;
        }
        children.clear();
        split_tet(parent, s, cut_vertex, children);
        for (size_t c = 0; c < children.size(); ++c) {
            Tet tet = children[c].tet;
            double volume = signed_volume(mesh.positions[tet[0]], mesh.positions[tet[1]], mesh.positions[tet[2]],
                                          mesh.positions[tet[3]]);
            if (volume < 0) {
                std::swap(tet[2], tet[3]);
                volume = -volume;
            }
            if (!(volume > 0))
                throw AlgorithmError("exact split: tet " + std::to_string(t) +
                                     " would leave a flat piece (its crossing is too close to a vertex that "
                                     "could not be snapped)");
            if (c == 0) {
                mesh.tets[t] = tet;
                report.positive[t] = children[c].positive;
                continue;
            }
            mesh.tets.push_back(tet);
            report.positive.push_back(children[c].positive);
            report.appended_parents.push_back(t);
            const double parent_reference = reference[t];
            reference.push_back(parent_reference);
            touched.push_back(1);
            if (has_materials) mesh.materials.push_back(mesh.materials[t]);
            if (has_original_ids) mesh.original_ids.push_back(mesh.original_ids[t]);
            if (has_piece_ids) mesh.piece_ids.push_back(mesh.piece_ids[t]);
        }
    }
    report.tets_split = crossed.size();

    if (options.smooth_below_deg > 0 && !crossed.empty()) {
        // Regions after the split: the given labels, told apart by side, so the new surface and the
        // earlier walls are both kept faces.
        std::vector<int64_t> labels(mesh.tet_count());
        std::vector<uint8_t> start = touched;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.tet_count(), 4096), [&](const auto& range) {
            for (size_t t = range.begin(); t != range.end(); ++t) {
                const size_t source =
                    t < tets_before ? t : static_cast<size_t>(report.appended_parents[t - tets_before]);
                labels[t] = (options.tet_labels ? (*options.tet_labels)[source] : 0) * 2 + report.positive[t];
                if (!options.smooth_positive_side && report.positive[t]) start[t] = 0;
            }
        });
        SplitSmoothingOptions smoothing;
        smoothing.guard_deg = options.min_dihedral_guard_deg;
        smoothing.target_deg = options.smooth_below_deg;
        report.vertices_smoothed =
            smooth_split_vertices(mesh, world, values, field, labels, reference, start, touched, smoothing);
    }
    // Only tets this split touched can have changed since the reference was taken.
    report.tets_under_guard = count_tets_under_guard(mesh, reference, options.min_dihedral_guard_deg, &touched);
    return report;
}

CuttingSurfaceField::CuttingSurfaceField(const CuttingSurface& surface)
    : surface_(surface), plane_(dynamic_cast<const PlaneCut*>(&surface)) {}

double CuttingSurfaceField::crossing(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double va,
                                     double vb) const {
    // The plane's side() is affine along the segment: the closed form is exact up to rounding.
    if (plane_) return va / (va - vb);
    // step_to_surface walks from the cut-away end; the crossing is then measured from `a`.
    if (va > 0) return surface_.step_to_surface(a, b);
    return 1.0 - surface_.step_to_surface(b, a);
}

std::optional<Eigen::Vector3d> CuttingSurfaceField::project(const Eigen::Vector3d& world) const {
    if (!plane_) return std::nullopt;
    return world - plane_->side(world) * plane_->unit_normal();
}

ExactCutResult cut_exact(TetMesh& mesh, const CuttingSurface& surface, const ExactCutOptions& options) {
    ExactCutResult result;
    const size_t tets_before = mesh.tet_count();
    const size_t vertices_before = mesh.vertex_count();
    std::vector<Eigen::Vector3d> world = world_positions(mesh);
    std::vector<double> values(world.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, world.size(), 4096), [&](const auto& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) values[v] = surface.side(world[v]);
    });
    SplitOptions split = options.split;
    if (split.zero_tolerance == 0 && !world.empty()) {
        // Rounding of a world-space side test: a few ulps of the model's extent.
        Eigen::Vector3d lo = world[0], hi = world[0];
        for (const auto& p : world) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
        split.zero_tolerance = 1e-13 * std::max((hi - lo).norm(), lo.cwiseAbs().maxCoeff() + hi.cwiseAbs().maxCoeff());
    }
    split.smooth_positive_side = false;  // cut away right after
    const CuttingSurfaceField field(surface);
    SplitReport report = split_along_field(mesh, world, values, field, split);
    result.tets_split = report.tets_split;
    result.vertices_snapped = report.vertices_snapped;
    result.vertices_added = report.appended_vertex_origins.size();
    result.vertices_smoothed = report.vertices_smoothed;

    const CutResult removal = remove_tets(mesh, report.positive);
    result.tets_removed = removal.tets_removed;
    result.vertices_removed = vertices_before + result.vertices_added - mesh.vertex_count();
    result.new_to_old_tet.resize(mesh.tet_count());
    for (size_t n = 0; n < mesh.tet_count(); ++n) {
        const int32_t t = removal.new_to_old_tet[n];
        result.new_to_old_tet[n] =
            static_cast<size_t>(t) < tets_before ? t : report.appended_parents[t - tets_before];
    }
    result.vertex_origins.resize(mesh.vertex_count());
    for (size_t v = 0; v < removal.old_to_new_vertex.size(); ++v) {
        const int32_t n = removal.old_to_new_vertex[v];
        if (n < 0) continue;
        result.vertex_origins[n] = v < vertices_before ? VertexOrigin::vertex(static_cast<int32_t>(v))
                                                       : report.appended_vertex_origins[v - vertices_before];
    }
    result.min_dihedral_deg = mesh_min_dihedral_deg(mesh);
    // Recounted on the cut mesh: each tet against the reference of the tet before the cut it came from.
    std::vector<double> reference(mesh.tet_count());
    for (size_t n = 0; n < mesh.tet_count(); ++n) reference[n] = report.reference_deg[removal.new_to_old_tet[n]];
    result.tets_under_guard = count_tets_under_guard(mesh, reference, split.min_dihedral_guard_deg);
    return result;
}

}  // namespace waxwork
