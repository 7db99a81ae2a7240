#include "tetops/split_quality.h"

#include "base/error.h"
#include "tetops/connectivity.h"
#include "tetops/exact_cut.h"
#include "tetops/quality.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <optional>

namespace waxwork {

std::vector<KeptFace> kept_faces_at(const TetMesh& mesh, const std::vector<int32_t>& star, int32_t v,
                                    const std::vector<int64_t>* labels) {
    std::vector<std::array<int32_t, 3>> sorted_faces, faces;
    std::vector<int64_t> face_label;
    for (int32_t t : star) {
        const Tet& tet = mesh.tets[t];
        for (int k = 0; k < 4; ++k) {
            if (tet[k] == v) continue;  // the face opposite v does not contain it
            const auto& f = kTetFaces[k];
            std::array<int32_t, 3> key = {tet[f[0]], tet[f[1]], tet[f[2]]};
            faces.push_back(key);
            std::sort(key.begin(), key.end());
            sorted_faces.push_back(key);
            face_label.push_back(labels ? (*labels)[t] : 0);
        }
    }
    std::vector<size_t> order(faces.size());
    std::iota(order.begin(), order.end(), size_t{0});
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return sorted_faces[a] < sorted_faces[b]; });
    std::vector<KeptFace> kept;
    for (size_t i = 0; i < order.size();) {
        size_t j = i + 1;
        while (j < order.size() && sorted_faces[order[j]] == sorted_faces[order[i]]) ++j;
        if (j - i == 1) kept.push_back({faces[order[i]], true});
        if (j - i == 2 && face_label[order[i]] != face_label[order[i + 1]]) kept.push_back({faces[order[i]], false});
        i = j;
    }
    return kept;
}

namespace {

// Angle and volume sign of `tet` with vertex v at x.
std::array<Eigen::Vector3d, 4> moved_corners(const TetMesh& mesh, const Tet& tet, int32_t v, const Eigen::Vector3d& x) {
    std::array<Eigen::Vector3d, 4> p;
    for (int k = 0; k < 4; ++k) p[k] = tet[k] == v ? x : mesh.positions[tet[k]];
    return p;
}

// Adds the part of `n` orthogonal to `basis` when it is not (numerically) in its span already. Face
// normals of one plane agree to rounding (more loosely for thin faces); 1e-8 tells a plane from one
// bent by more than 10 nanoradians.
void add_constraint(std::vector<Eigen::Vector3d>& basis, const Eigen::Vector3d& n) {
    Eigen::Vector3d r = n;
    for (const Eigen::Vector3d& b : basis) r -= b.dot(r) * b;
    if (r.norm() > 1e-8) basis.push_back(r.normalized());
}

struct VertexState {
    int32_t vertex = -1;
    std::vector<int32_t> star;
    std::vector<Eigen::Vector3d> basis;  // unit normals the step must be orthogonal to (rest frame)
    bool reproject = false;              // on the surface of a field that can project: project after the step
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();      // the surface normal (rest frame)
    Eigen::Vector3d correction = Eigen::Vector3d::Zero();  // direction back onto the surface (rest frame)
    bool fixed = false;
    const RigidTransform* frame = nullptr;
};

}  // namespace

size_t count_tets_under_guard(const TetMesh& mesh, const std::vector<double>& reference_deg, double guard_deg,
                              const std::vector<uint8_t>* only) {
    if (reference_deg.size() != mesh.tet_count() || (only && only->size() != mesh.tet_count()))
        throw InvalidArgumentError("guard count: one reference angle (and flag) per tet expected");
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, mesh.tet_count(), 4096), size_t{0},
        [&](const tbb::blocked_range<size_t>& range, size_t count) {
            for (size_t t = range.begin(); t != range.end(); ++t)
                if (!std::isnan(reference_deg[t]) && (!only || (*only)[t]) &&
                    min_dihedral_angle_deg(mesh, mesh.tets[t]) < guard_floor_deg(guard_deg, reference_deg[t]))
                    ++count;
            return count;
        },
        std::plus<>());
}

size_t smooth_split_vertices(TetMesh& mesh, std::vector<Eigen::Vector3d>& world, const std::vector<double>& values,
                             const SplitField& field, const std::vector<int64_t>& labels,
                             std::vector<double>& reference_deg, const std::vector<uint8_t>& start,
                             std::vector<uint8_t>& touched, const SplitSmoothingOptions& options) {
    const size_t tet_count = mesh.tet_count();
    const size_t vertex_count = mesh.vertex_count();
    if (labels.size() != tet_count || reference_deg.size() != tet_count || start.size() != tet_count ||
        touched.size() != tet_count ||
        world.size() != vertex_count || values.size() != vertex_count)
        throw InvalidArgumentError("split smoothing: per-tet or per-vertex arrays do not match the mesh");
    if (options.max_sweeps <= 0) return 0;
    const double guard = options.guard_deg;
    const double target = options.target_deg;

    // Vertices of the flagged tets under the target.
    std::vector<uint8_t> poor(tet_count, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tet_count, 4096), [&](const auto& range) {
        for (size_t t = range.begin(); t != range.end(); ++t)
            poor[t] = start[t] && min_dihedral_angle_deg(mesh, mesh.tets[t]) < target;
    });
    std::vector<int32_t> slot(vertex_count, -1);
    std::vector<VertexState> states;
    for (size_t t = 0; t < tet_count; ++t) {
        if (!poor[t]) continue;
        for (int32_t v : mesh.tets[t])
            if (slot[v] < 0) {
                slot[v] = static_cast<int32_t>(states.size());
                states.emplace_back().vertex = v;
            }
    }
    if (states.empty()) return 0;
    // Keep vertex order (deterministic colouring).
    std::sort(states.begin(), states.end(), [](const VertexState& a, const VertexState& b) { return a.vertex < b.vertex; });
    for (size_t i = 0; i < states.size(); ++i) slot[states[i].vertex] = static_cast<int32_t>(i);
    for (size_t t = 0; t < tet_count; ++t)
        for (int32_t v : mesh.tets[t])
            if (slot[v] >= 0) states[slot[v]].star.push_back(static_cast<int32_t>(t));

    const RigidTransform identity;
    const bool has_pieces = mesh.piece_ids.size() == tet_count;
    tbb::parallel_for(size_t{0}, states.size(), [&](size_t i) {
        VertexState& s = states[i];
        const int32_t v = s.vertex;
        s.frame = &identity;
        if (has_pieces) {
            const int32_t piece = mesh.piece_ids[s.star[0]];
            if (piece >= 0 && static_cast<size_t>(piece) < mesh.piece_transforms.size())
                s.frame = &mesh.piece_transforms[piece];
        }
        const std::vector<KeptFace> kept = kept_faces_at(mesh, s.star, v, &labels);
        // The surface normal (world space) when the field can project: the projection of a probe point
        // one unit off. Faces on the surface are then covered by it exactly.
        const bool on_surface = values[v] == 0;
        Eigen::Vector3d normal = Eigen::Vector3d::Zero();
        if (on_surface && field.project(world[v])) {
            for (int axis = 0; axis < 3; ++axis) {
                const Eigen::Vector3d probe = world[v] + Eigen::Vector3d::Unit(axis);
                const Eigen::Vector3d offset = probe - *field.project(probe);
                if (offset.norm() > normal.norm()) normal = offset;
            }
            if (normal.norm() > 0) normal = s.frame->rotation.transpose() * normal.normalized();
        }
        s.reproject = normal.norm() > 0;
        bool on_surface_face = false;
        // Planes to keep, best-shaped face first: the rounding error of a face normal grows as the
        // face gets thinner (about eps x longest edge^2 / twice the area), and the first face of a plane
        // sets the plane the vertex moves in.
        std::vector<std::pair<double, Eigen::Vector3d>> normals;
        for (const KeptFace& face : kept) {
            const auto& f = face.vertices;
            const bool surface_face =
                on_surface && !face.on_boundary && values[f[0]] == 0 && values[f[1]] == 0 && values[f[2]] == 0;
            on_surface_face |= surface_face;
            if (surface_face && s.reproject) continue;
            const Eigen::Vector3d& a = mesh.positions[f[0]];
            const Eigen::Vector3d& b = mesh.positions[f[1]];
            const Eigen::Vector3d& c = mesh.positions[f[2]];
            const Eigen::Vector3d n = (b - a).cross(c - a);
            const double longest = std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), (c - b).squaredNorm()});
            if (!(n.norm() > 0)) {
                s.fixed = true;  // a flat face has no plane to keep
                return;
            }
            normals.emplace_back(n.norm() / longest, n.normalized());
        }
        std::stable_sort(normals.begin(), normals.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
        for (const auto& [shape, n] : normals) add_constraint(s.basis, n);
        if (s.reproject) {
            // Back onto the surface along the part of its normal the other planes leave free, so the
            // correction does not move the vertex off the boundary or a wall.
            Eigen::Vector3d c = normal;
            for (const Eigen::Vector3d& b : s.basis) c -= b.dot(c) * b;
            if (!(c.norm() > 1e-6) || s.basis.size() >= 2) {
                s.fixed = true;
                return;
            }
            s.normal = normal;
            s.correction = c;
            add_constraint(s.basis, normal);
        } else if (on_surface && !on_surface_face) {
            s.fixed = true;  // no plane known to slide in
        }
        if (s.basis.size() >= 3) s.fixed = true;
    });

    // Greedy colouring in vertex order over the movable vertices: one colour shares no tet.
    std::vector<int32_t> colour(states.size(), -1);
    std::vector<std::vector<int32_t>> classes;
    std::vector<uint8_t> used;
    for (size_t i = 0; i < states.size(); ++i) {
        if (states[i].fixed) continue;
        used.assign(classes.size() + 1, 0);
        for (int32_t t : states[i].star)
            for (int32_t u : mesh.tets[t])
                if (slot[u] >= 0 && colour[slot[u]] >= 0) used[colour[slot[u]]] = 1;
        const auto c = static_cast<int32_t>(std::find(used.begin(), used.end(), 0) - used.begin());
        colour[i] = c;
        if (static_cast<size_t>(c) == classes.size()) classes.emplace_back();
        classes[c].push_back(static_cast<int32_t>(i));
    }

    std::vector<uint8_t> moved(states.size(), 0), moved_now(states.size(), 0);
    auto update = [&](VertexState& s) -> bool {
        const int32_t v = s.vertex;
        const Eigen::Vector3d x = mesh.positions[v];
        std::vector<double> current(s.star.size());
        double worst = std::numeric_limits<double>::infinity();
        size_t worst_index = 0;
        for (size_t k = 0; k < s.star.size(); ++k) {
            current[k] = min_dihedral_angle_deg(mesh, mesh.tets[s.star[k]]);
            if (current[k] < worst) worst = current[k], worst_index = k;
        }
        if (!(worst < target)) return false;
        // The star of an untouched vertex is as it was before the operation: its own reference.
        for (size_t k = 0; k < s.star.size(); ++k)
            if (std::isnan(reference_deg[s.star[k]])) reference_deg[s.star[k]] = current[k];

        auto constrain = [&](Eigen::Vector3d d) {
            for (const Eigen::Vector3d& b : s.basis) d -= b.dot(d) * b;
            return d;
        };
        // The star's worst angle with v at y, or nothing when a tet would invert, fall under
        // min(guard, reference) while getting worse, or not beat `bar` (then y cannot win). The worst
        // tet is tried first: it is the likeliest to end the test early.
        std::vector<size_t> order(s.star.size());
        std::iota(order.begin(), order.end(), size_t{0});
        std::swap(order[0], order[worst_index]);
        auto evaluate = [&](const Eigen::Vector3d& y, double bar) -> std::optional<double> {
            double w = std::numeric_limits<double>::infinity();
            for (size_t k : order) {
                const auto p = moved_corners(mesh, mesh.tets[s.star[k]], v, y);
                if (!(signed_volume(p[0], p[1], p[2], p[3]) > 0)) return std::nullopt;
                const double a = min_dihedral_angle_deg(p[0], p[1], p[2], p[3]);
                if (!(a > bar)) return std::nullopt;
                if (a < guard_floor_deg(guard, reference_deg[s.star[k]]) && a < current[k]) return std::nullopt;
                w = std::min(w, a);
            }
            return w;
        };
        auto place = [&](const Eigen::Vector3d& y, Eigen::Vector3d& y_world) {
            y_world = s.frame->rotation * y + s.frame->translation;
            if (!s.reproject) return y;
            // The signed distance off the surface, from the projection; then back along `correction`.
            const Eigen::Vector3d off = s.frame->rotation.transpose() * (y_world - *field.project(y_world));
            const Eigen::Vector3d z = y - (off.dot(s.normal) / s.correction.dot(s.normal)) * s.correction;
            y_world = s.frame->rotation * z + s.frame->translation;
            return z;
        };

        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        double length = 0;
        int ring = 0;
        for (int32_t t : s.star)
            for (int32_t u : mesh.tets[t])
                if (u != v) centroid += mesh.positions[u], length += (mesh.positions[u] - x).norm(), ++ring;
        centroid /= ring;
        length /= ring;

        std::vector<Eigen::Vector3d> candidates;
        const Eigen::Vector3d to_centroid = constrain(centroid - x);
        for (double f : {1.0, 0.5, 0.25}) candidates.push_back(x + f * to_centroid);
        // Steepest ascent of the worst tet's angle (central differences).
        const Tet& worst_tet = mesh.tets[s.star[worst_index]];
        const double h = 1e-5 * length;
        Eigen::Vector3d gradient;
        for (int axis = 0; axis < 3; ++axis) {
            const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(axis);
            const auto plus = moved_corners(mesh, worst_tet, v, x + e);
            const auto minus = moved_corners(mesh, worst_tet, v, x - e);
            gradient[axis] = min_dihedral_angle_deg(plus[0], plus[1], plus[2], plus[3]) -
                             min_dihedral_angle_deg(minus[0], minus[1], minus[2], minus[3]);
        }
        // A gradient (nearly) normal to the kept planes leaves only rounding noise in them: no direction.
        const Eigen::Vector3d free_gradient = constrain(gradient);
        if (free_gradient.norm() > 1e-6 * gradient.norm()) {
            const Eigen::Vector3d direction = constrain(free_gradient.normalized());
            for (double f : {0.3, 0.15, 0.08, 0.04, 0.02, 0.01, 0.005}) candidates.push_back(x + f * length * direction);
        }

        double best = worst;
        Eigen::Vector3d best_rest = x, best_world = world[v];
        for (const Eigen::Vector3d& c : candidates) {
            if (c == x) continue;
            Eigen::Vector3d c_world;
            const Eigen::Vector3d y = place(c, c_world);
            const std::optional<double> w = evaluate(y, best);
            if (w && *w > best) best = *w, best_rest = y, best_world = c_world;
        }
        if (!(best > worst)) return false;
        mesh.positions[v] = best_rest;
        world[v] = best_world;
        return true;
    };

    // A vertex whose star did not change since its last visit would find the same answer: skip it.
    std::vector<uint8_t> dirty(states.size(), 1), next_dirty(states.size(), 0);
    for (int sweep = 0; sweep < options.max_sweeps; ++sweep) {
        size_t accepted = 0;
        std::fill(next_dirty.begin(), next_dirty.end(), 0);
        for (const std::vector<int32_t>& members : classes) {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, members.size(), 16), [&](const auto& range) {
                for (size_t i = range.begin(); i != range.end(); ++i)
                    moved_now[members[i]] = dirty[members[i]] && update(states[members[i]]);
            });
            for (int32_t i : members) {
                if (!moved_now[i]) continue;
                ++accepted;
                moved[i] = 1;
                for (int32_t t : states[i].star) {
                    touched[t] = 1;
                    for (int32_t u : mesh.tets[t])
                        if (slot[u] >= 0) next_dirty[slot[u]] = 1;
                }
            }
        }
        if (accepted == 0) break;
        dirty.swap(next_dirty);
    }
    return static_cast<size_t>(std::count(moved.begin(), moved.end(), uint8_t{1}));
}

}  // namespace waxwork
