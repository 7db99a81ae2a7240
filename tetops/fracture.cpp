#include "tetops/fracture.h"

#include "base/error.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/disjoint_sets.h"
#include "tetops/exact_cut.h"
#include "tetops/point_kd_tree.h"
#include "tetops/quality.h"
#include "tetops/split_coarsening.h"
#include "tetops/split_quality.h"
#include "tetops/vertex_map.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <tuple>
#include <unordered_map>

namespace waxwork {
namespace {

Eigen::Vector3d tet_centroid(const std::vector<Eigen::Vector3d>& points, const Tet& tet) {
    return 0.25 * (points[tet[0]] + points[tet[1]] + points[tet[2]] + points[tet[3]]);
}

double extent_of(const std::vector<Eigen::Vector3d>& world) {
    if (world.empty()) return 1.0;
    Eigen::Vector3d lo = world[0], hi = world[0];
    for (const auto& p : world) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    return std::max({(hi - lo).norm(), lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff(), 1e-300});
}

// Field of the wall of Voronoi cell k: the minimum over the other seeds j of the signed distance to the
// bisector plane of (k, j), positive on k's side. Its zero set is exactly the cell's boundary; along
// a segment it is concave and piecewise linear, so a crossing is the first bisector the segment
// leaves k's side of.
class VoronoiWallField final : public SplitField {
public:
    VoronoiWallField(std::span<const Eigen::Vector3d> seeds, size_t k) {
        for (size_t j = 0; j < seeds.size(); ++j) {
            const Eigen::Vector3d d = seeds[j] - seeds[k];
            const double length = d.norm();
            if (j == k || !(length > 0)) continue;
            normals_.push_back(d / length);  // pointing away from k
            offsets_.push_back(0.5 * (seeds[j].squaredNorm() - seeds[k].squaredNorm()) / length);
        }
    }
    double plane(size_t i, const Eigen::Vector3d& x) const { return offsets_[i] - normals_[i].dot(x); }
    double value(const Eigen::Vector3d& x) const {
        double v = std::numeric_limits<double>::infinity();
        for (size_t i = 0; i < normals_.size(); ++i) v = std::min(v, plane(i, x));
        return v;
    }
    double crossing(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double va, double /*vb*/) const override {
        const bool from_a = va > 0;
        const Eigen::Vector3d& inside = from_a ? a : b;
        const Eigen::Vector3d& outside = from_a ? b : a;
        double t = 1.0;
        for (size_t i = 0; i < normals_.size(); ++i) {
            const double gi = plane(i, inside), go = plane(i, outside);
            if (go < 0 && gi > 0) t = std::min(t, gi / (gi - go));
        }
        return from_a ? t : 1.0 - t;
    }

private:
    std::vector<Eigen::Vector3d> normals_;
    std::vector<double> offsets_;
};

// A plane n.x = d as a field (positive where n.x > d).
class PlaneField final : public SplitField {
public:
    explicit PlaneField(const PlaneCut& plane) : plane_(plane) {}
    double crossing(const Eigen::Vector3d&, const Eigen::Vector3d&, double va, double vb) const override {
        return va / (va - vb);
    }
    std::optional<Eigen::Vector3d> project(const Eigen::Vector3d& x) const override {
        return x - plane_.side(x) * plane_.unit_normal();
    }

private:
    const PlaneCut& plane_;
};

void check_options(const FractureOptions& options) {
    if (options.min_piece_tets < 0) throw InvalidArgumentError("fracture: min_piece_tets must be >= 0");
    if (!(options.min_piece_volume >= 0 && options.min_piece_volume < 1))
        throw InvalidArgumentError("fracture: min_piece_volume must be in [0, 1) (of the mean cell's volume)");
    if (!(options.snap_fraction >= 0 && options.snap_fraction < 0.5))
        throw InvalidArgumentError("fracture: the snap fraction must be in [0, 0.5)");
    if (!(options.boundary_bend_deg >= 0 && options.boundary_bend_deg < 90))
        throw InvalidArgumentError("fracture: the boundary bend must be in [0, 90) degrees");
    if (!(options.smooth_below_deg >= 0 && options.smooth_below_deg < 70))
        throw InvalidArgumentError("fracture: the smoothing target must be in [0, 70) degrees");
}

// The exact Voronoi split builds the cells one seed at a time and each wall splits the tets earlier
// walls split (reordering the seeds does not help: in four orders, 30 pieces of spot made 67,553 to
// 75,413 tets), so the tet count grows much faster than the pieces even after the swallowed walls
// are collapsed (spot, 11,705 tets: 10 pieces 1.8x, 30 pieces 4.7x, 100 pieces 22x in 2 to 3 s; without
// the guard 300 pieces gave 142x and 0.00004-degree tets in 25 s). Past this growth (plus an allowance that lets small volumes grow
// into a few hundred thousand tets, which costs little) the fracture stops with an error instead of
// running for minutes into slivers no solver converges on.
constexpr size_t kMaxFractureGrowth = 32;
constexpr size_t kFractureGrowthAllowance = 100'000;

// Collapsing the vertices of swallowed walls may lower the worst angle around a vertex, but not under
// this (the angle under which the split's guarded optimisation starts; SplitOptions::smooth_below_deg).
constexpr double kCollapseKeepsAngleDeg = 5;

void check_fracture_growth(size_t tets_now, size_t tets_before, size_t walls_done, size_t seeds) {
    if (tets_now <= kMaxFractureGrowth * tets_before + kFractureGrowthAllowance) return;
    throw InvalidArgumentError("fracture: after " + std::to_string(walls_done) + " of " + std::to_string(seeds - 1) +
                               " cell walls the volume has " + std::to_string(tets_now) + " tets, more than " +
                               std::to_string(kMaxFractureGrowth) + " times the " + std::to_string(tets_before) +
                               " it started with and " + std::to_string(kFractureGrowthAllowance) +
                               " more (each exact wall splits the tets earlier walls split); ask for fewer pieces, or "
                               "keep whole tets (cracks along tet faces: --no-exact)");
}

// Turns per-tet cell labels into pieces: each face-connected part of one cell within one existing
// piece becomes a piece, parts under min_piece_tets join the neighbouring part they share most faces
// with, and every vertex on a crack is duplicated so pieces share none. Pieces are numbered by their
// lowest tet and take their parent's transform.
void make_pieces(TetMesh& mesh, const std::vector<int64_t>& label, const FractureOptions& options,
                 const std::vector<double>& reference, FractureResult& result) {
    const size_t n = mesh.tet_count();
    const std::vector<std::array<int32_t, 4>> neighbors = build_face_neighbors(mesh);
    DisjointSets parts(n);
    for (size_t t = 0; t < n; ++t)
        for (int f = 0; f < 4; ++f) {
            const int32_t u = neighbors[t][f];
            if (u > static_cast<int32_t>(t) && label[u] == label[t] && mesh.piece_ids[u] == mesh.piece_ids[t])
                parts.unite(static_cast<int32_t>(t), u);
        }

    // Dust: each part under min_piece_tets, or under min_piece_volume of the mean cell's volume,
    // joins the neighbouring part it shares most faces with, smallest parts first; rounds repeat
    // (sizes change) until no part is both small and next to another part (an isolated small
    // component stays a piece). Each round is one pass over the faces.
    std::vector<double> tet_volume(n);
    double total_volume = 0;
    for (size_t t = 0; t < n; ++t) total_volume += tet_volume[t] = std::abs(signed_volume(mesh, t));
    std::vector<int64_t> cells(label.begin(), label.end());
    std::sort(cells.begin(), cells.end());
    const auto cell_count = static_cast<double>(std::unique(cells.begin(), cells.end()) - cells.begin());
    const double min_volume = options.min_piece_volume * total_volume / std::max(cell_count, 1.0);
    if (options.min_piece_tets > 1 || min_volume > 0) {
        for (bool merged = true; merged;) {
            merged = false;
            std::vector<int32_t> root(n), size(n, 0);
            std::vector<double> volume(n, 0.0);
            for (size_t t = 0; t < n; ++t) {
                root[t] = parts.find(static_cast<int32_t>(t));
                ++size[root[t]];
                volume[root[t]] += tet_volume[t];
            }
            std::map<std::pair<int32_t, int32_t>, int32_t> shared;  // (dust part, neighbour part) -> faces
            for (size_t t = 0; t < n; ++t) {
                if (size[root[t]] >= options.min_piece_tets && !(volume[root[t]] < min_volume)) continue;
                for (int f = 0; f < 4; ++f) {
                    const int32_t u = neighbors[t][f];
                    if (u >= 0 && root[u] != root[t]) ++shared[{root[t], root[u]}];
                }
            }
            std::map<int32_t, std::pair<int32_t, int32_t>> best;  // dust part -> (faces, neighbour)
            for (const auto& [key, faces] : shared) {
                auto& b = best[key.first];
                if (faces > b.first) b = {faces, key.second};
            }
            std::vector<int32_t> dust;
            for (const auto& entry : best) dust.push_back(entry.first);
            std::stable_sort(dust.begin(), dust.end(), [&](int32_t a, int32_t b) { return size[a] < size[b]; });
            for (int32_t part : dust) {
                // A part that already absorbed or joined another this round waits for the recount.
                if (parts.find(part) != part || parts.find(best[part].second) != best[part].second) continue;
                parts.unite(part, best[part].second);
                merged = true;
            }
        }
    }

    // Number the parts by their lowest tet.
    std::vector<int32_t> piece_of_root(n, -1);
    std::vector<RigidTransform> transforms;
    std::vector<int32_t> new_piece(n);
    for (size_t t = 0; t < n; ++t) {
        const int32_t root = parts.find(static_cast<int32_t>(t));
        if (piece_of_root[root] < 0) {
            piece_of_root[root] = static_cast<int32_t>(transforms.size());
            transforms.push_back(mesh.piece_transforms[mesh.piece_ids[t]]);
        }
        new_piece[t] = piece_of_root[root];
    }

    // Duplicate crack vertices: the first piece (in tet order) to use a vertex keeps it.
    std::vector<int32_t> owner(mesh.vertex_count(), -1);
    std::unordered_map<uint64_t, int32_t> copies;
    for (size_t t = 0; t < n; ++t) {
        for (int32_t& v : mesh.tets[t]) {
            if (owner[v] < 0) owner[v] = new_piece[t];
            if (owner[v] == new_piece[t]) continue;
            const uint64_t key = (uint64_t{static_cast<uint32_t>(v)} << 32) | static_cast<uint32_t>(new_piece[t]);
            auto [it, inserted] = copies.try_emplace(key, static_cast<int32_t>(mesh.positions.size()));
            if (inserted) {
                mesh.positions.push_back(mesh.positions[v]);
                result.vertex_origins.push_back(VertexOrigin::vertex(v));
            }
            v = it->second;
        }
    }
    result.vertices_duplicated = copies.size();
    mesh.piece_ids = std::move(new_piece);
    mesh.piece_transforms = std::move(transforms);
    result.pieces_after = static_cast<int>(mesh.piece_transforms.size());
    result.min_dihedral_deg = mesh_min_dihedral_deg(mesh);
    // Tets keep their order and shapes above: the recount against the ancestors' angles.
    result.tets_under_guard = count_tets_under_guard(mesh, reference, SplitOptions{}.min_dihedral_guard_deg);
}

// Common start: the checks the fracture relies on (a full validate() sorts every face, costlier than
// the fracture itself) and the world positions every field is evaluated at.
std::vector<Eigen::Vector3d> prepare(TetMesh& mesh, FractureResult& result) {
    const size_t n = mesh.tet_count();
    if (mesh.piece_ids.size() != n || mesh.original_ids.size() != n || (mesh.has_materials() && mesh.materials.size() != n))
        throw InvalidMeshError("fracture: per-tet arrays do not match the tet count");
    for (size_t t = 0; t < n; ++t) {
        if (mesh.piece_ids[t] < 0 || static_cast<size_t>(mesh.piece_ids[t]) >= mesh.piece_transforms.size())
            throw InvalidMeshError("fracture: tet " + std::to_string(t) + " has a piece without a transform");
        for (int32_t v : mesh.tets[t])
            if (v < 0 || static_cast<size_t>(v) >= mesh.vertex_count())
                throw InvalidMeshError("fracture: tet " + std::to_string(t) + " has a vertex index out of range");
    }
    result.pieces_before = static_cast<int>(mesh.piece_transforms.size());
    result.vertex_origins.resize(mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) result.vertex_origins[v] = VertexOrigin::vertex(static_cast<int32_t>(v));
    return world_positions(mesh);
}

// Same tolerances as cut_exact: values within rounding of the model's extent are on the wall.
SplitOptions wall_split_options(const std::vector<Eigen::Vector3d>& world, const FractureOptions& options) {
    SplitOptions split;
    split.snap_fraction = options.snap_fraction;
    split.boundary_bend_deg = options.boundary_bend_deg;
    split.smooth_below_deg = options.smooth_below_deg;
    split.zero_tolerance = 1e-12 * extent_of(world);
    return split;
}

}  // namespace

std::vector<Eigen::Vector3d> scatter_fracture_seeds(const TetMesh& mesh, int count, uint32_t seed) {
    if (count < 1) throw InvalidArgumentError("fracture: the number of pieces must be at least 1");
    if (mesh.tets.empty()) throw InvalidArgumentError("fracture: the volume has no tets");
    if (static_cast<size_t>(count) > mesh.tet_count())
        throw InvalidArgumentError("fracture: " + std::to_string(count) + " pieces requested from a volume of only " +
                                   std::to_string(mesh.tet_count()) + " tets");
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    // A tet with probability proportional to its volume, then a uniform point in it (barycentric
    // weights from normalised exponentials are uniform on the simplex). Uniform doubles are built from
    // the raw mt19937 output because std's distributions differ between standard libraries.
    std::vector<double> cumulative(mesh.tet_count());
    double sum = 0;
    for (size_t t = 0; t < mesh.tet_count(); ++t) cumulative[t] = sum += std::abs(signed_volume(mesh, t));
    std::mt19937 random(seed);
    auto uniform = [&] { return (static_cast<double>(random()) + 0.5) / 4294967296.0; };
    std::vector<Eigen::Vector3d> seeds;
    for (int i = 0; i < count; ++i) {
        const double pick = uniform() * sum;
        const size_t t = std::min(static_cast<size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), pick) -
                                                      cumulative.begin()),
                                  mesh.tet_count() - 1);
        std::array<double, 4> w;
        double total = 0;
        for (double& x : w) total += x = -std::log(uniform());
        Eigen::Vector3d p = Eigen::Vector3d::Zero();
        for (int k = 0; k < 4; ++k) p += (w[k] / total) * world[mesh.tets[t][k]];
        seeds.push_back(p);
    }
    return seeds;
}

FractureResult fracture_voronoi(TetMesh& mesh, std::span<const Eigen::Vector3d> seeds,
                                const FractureOptions& options) {
    check_options(options);
    if (seeds.empty()) throw InvalidArgumentError("fracture: no seed points");
    for (const auto& s : seeds)
        if (!s.allFinite()) throw InvalidArgumentError("fracture: non-finite seed point");
    FractureResult result;
    std::vector<Eigen::Vector3d> world = prepare(mesh, result);
    if (mesh.tets.empty()) return result;
    const size_t tets_before = mesh.tet_count(), vertices_before = mesh.vertex_count();
    if (options.min_piece_tets > 0 && seeds.size() * static_cast<size_t>(options.min_piece_tets) > tets_before)
        throw InvalidArgumentError("fracture: " + std::to_string(seeds.size()) + " pieces of a volume of " +
                                   std::to_string(tets_before) + " tets: a piece needs at least " +
                                   std::to_string(options.min_piece_tets) + " tets (min_piece_tets), so at most " +
                                   std::to_string(tets_before / static_cast<size_t>(options.min_piece_tets)));

    PointCloud cloud{seeds};
    const PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    auto nearest = [&](const Eigen::Vector3d& x) {
        uint32_t index = 0;
        double distance = 0;
        tree.knnSearch(x.data(), 1, &index, &distance);
        return static_cast<int32_t>(index);
    };

    std::vector<int64_t> label(mesh.tet_count(), 0);
    // Per tet: the minimum dihedral angle of its ancestor before the fracture (NaN: untouched).
    std::vector<double> reference(mesh.tet_count(), std::numeric_limits<double>::quiet_NaN());
    if (options.exact && seeds.size() > 1) {
        // The Voronoi diagram built one seed at a time: adding seed k takes from every tet of cell j
        // the part closer to k than to j. Every tet lies in one cell of the previous diagram, where the
        // wall field of k is sign-equivalent to the bisector of (j, k), a linear function, so the
        // vertex signs tell exactly which tets it crosses (a field that is only concave could bulge
        // into a tet between its vertices). Snapping treats earlier walls between cells like the
        // boundary (split.tet_labels), so they stay flat.
        SplitOptions split = wall_split_options(world, options);
        std::vector<double> best(world.size());
        tbb::parallel_for(size_t{0}, world.size(), [&](size_t v) { best[v] = (world[v] - seeds[0]).squaredNorm(); });
        for (size_t k = 1; k < seeds.size(); ++k) {
            std::vector<uint8_t> closer(world.size());
            tbb::parallel_for(size_t{0}, world.size(),
                              [&](size_t v) { closer[v] = (world[v] - seeds[k]).squaredNorm() < best[v]; });
            std::vector<uint8_t> needs_value(world.size(), 0);
            for (const Tet& tet : mesh.tets) {
                const int inside = closer[tet[0]] + closer[tet[1]] + closer[tet[2]] + closer[tet[3]];
                if (inside > 0 && inside < 4)
                    for (int32_t v : tet) needs_value[v] = 1;
            }
            const VoronoiWallField field(seeds.first(k + 1), k);
            std::vector<double> values(world.size());
            tbb::parallel_for(size_t{0}, world.size(), [&](size_t v) {
                values[v] = needs_value[v] ? field.value(world[v]) : (closer[v] ? 1.0 : -1.0);
            });
            split.tet_labels = &label;
            split.reference_deg = &reference;
            SplitReport report = split_along_field(mesh, world, values, field, split);
            check_fracture_growth(mesh.tet_count(), tets_before, k, seeds.size());
            reference = std::move(report.reference_deg);
            result.tets_split += report.tets_split;
            result.vertex_origins.insert(result.vertex_origins.end(), report.appended_vertex_origins.begin(),
                                         report.appended_vertex_origins.end());
            for (int32_t parent : report.appended_parents) label.push_back(label[parent]);
            for (size_t t = 0; t < mesh.tet_count(); ++t)
                if (report.positive[t]) label[t] = static_cast<int64_t>(k);
            const size_t old_count = best.size();
            best.resize(world.size());
            tbb::parallel_for(size_t{0}, world.size(), [&](size_t v) {
                if (v < old_count) {
                    best[v] = std::min(best[v], (world[v] - seeds[k]).squaredNorm());
                } else {
                    best[v] = std::numeric_limits<double>::infinity();
                    for (size_t j = 0; j <= k; ++j) best[v] = std::min(best[v], (world[v] - seeds[j]).squaredNorm());
                }
            });
        }
        // Walls that later cells swallowed are no cracks: collapse the vertices they left inside cells.
        if (options.collapse_swallowed_walls) {
            result.vertices_collapsed =
                collapse_unneeded_split_vertices(mesh, label, reference, result.vertex_origins, vertices_before,
                                                 kCollapseKeepsAngleDeg, split.min_dihedral_guard_deg)
                    .vertices_collapsed;
        }
    } else {
        // Each tet goes to the cell of its centroid; cracks follow tet faces.
        tbb::parallel_for(size_t{0}, mesh.tet_count(),
                          [&](size_t t) { label[t] = nearest(tet_centroid(world, mesh.tets[t])); });
    }
    make_pieces(mesh, label, options, reference, result);
    return result;
}

FractureResult fracture_planes(TetMesh& mesh, std::span<const Eigen::Vector4d> planes,
                               const FractureOptions& options) {
    check_options(options);
    std::vector<PlaneCut> cuts;
    for (const Eigen::Vector4d& p : planes) cuts.emplace_back(p.head<3>(), p[3]);  // validates
    FractureResult result;
    std::vector<Eigen::Vector3d> world = prepare(mesh, result);
    if (mesh.tets.empty()) return result;

    std::vector<double> reference(mesh.tet_count(), std::numeric_limits<double>::quiet_NaN());
    if (options.exact) {
        // Regions so far (sides of the earlier planes) label the tets, so snapping onto a later
        // plane keeps the earlier ones flat (split.tet_labels).
        SplitOptions split = wall_split_options(world, options);
        std::vector<int64_t> region(mesh.tet_count(), 0);
        split.tet_labels = &region;
        split.reference_deg = &reference;
        for (const PlaneCut& cut : cuts) {
            const PlaneField field(cut);
            std::vector<double> values(world.size());
            tbb::parallel_for(size_t{0}, world.size(), [&](size_t v) { values[v] = cut.side(world[v]); });
            SplitReport report = split_along_field(mesh, world, values, field, split);
            reference = std::move(report.reference_deg);
            result.tets_split += report.tets_split;
            result.vertex_origins.insert(result.vertex_origins.end(), report.appended_vertex_origins.begin(),
                                         report.appended_vertex_origins.end());
            for (int32_t parent : report.appended_parents) region.push_back(region[parent]);
            std::map<std::pair<int64_t, uint8_t>, int64_t> renumber;
            for (size_t t = 0; t < region.size(); ++t)
                region[t] = renumber.try_emplace({region[t], report.positive[t]}, static_cast<int64_t>(renumber.size()))
                                .first->second;
        }
    }

    // The region of a tet: which side of every plane its centroid is on.
    std::map<std::vector<bool>, int64_t> regions;
    std::vector<int64_t> label(mesh.tet_count());
    std::vector<bool> sides(cuts.size());
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const Eigen::Vector3d c = tet_centroid(world, mesh.tets[t]);
        for (size_t i = 0; i < cuts.size(); ++i) sides[i] = cuts[i].side(c) > 0;
        label[t] = regions.try_emplace(sides, static_cast<int64_t>(regions.size())).first->second;
    }
    make_pieces(mesh, label, options, reference, result);
    return result;
}

void set_piece_transform(TetMesh& mesh, int piece, const RigidTransform& transform) {
    if (piece < 0 || static_cast<size_t>(piece) >= mesh.piece_transforms.size())
        throw InvalidArgumentError("piece " + std::to_string(piece) + " does not exist (the volume has " +
                                   std::to_string(mesh.piece_transforms.size()) + " pieces)");
    const Eigen::Matrix3d& r = transform.rotation;
    if (!r.allFinite() || !transform.translation.allFinite())
        throw InvalidArgumentError("piece transform: non-finite rotation or translation");
    if ((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-9 || !(r.determinant() > 0))
        throw InvalidArgumentError("piece transform: the rotation is not a rotation (R^T R != I or det R != +1)");
    mesh.piece_transforms[piece] = transform;
}

WeldResult weld_touching_pieces(TetMesh& mesh, double tolerance) {
    if (!(tolerance >= 0) || !std::isfinite(tolerance))
        throw InvalidArgumentError("weld: the tolerance must be a finite number >= 0");
    validate(mesh);
    WeldResult result;
    result.pieces_before = result.pieces_after = static_cast<int>(mesh.piece_transforms.size());
    if (mesh.tets.empty()) return result;

    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<int32_t> vertex_piece = vertex_pieces(mesh);

    // Two vertices can be one point only when they are closer than half of either one's shortest
    // edge: farther apart, merging them folds an edge, and a tolerance above the edge length would
    // pair neighbours across a crack that have partners of their own.
    std::vector<double> shortest_edge_sq(mesh.vertex_count(), std::numeric_limits<double>::infinity());
    for (const Tet& tet : mesh.tets)
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b) {
                const double length_sq = (world[tet[a]] - world[tet[b]]).squaredNorm();
                shortest_edge_sq[tet[a]] = std::min(shortest_edge_sq[tet[a]], length_sq);
                shortest_edge_sq[tet[b]] = std::min(shortest_edge_sq[tet[b]], length_sq);
            }

    // Candidate pairs: boundary vertices of different pieces within the tolerance (a kd-tree over the
    // boundary vertices; nanoflann keeps distances strictly under the radius, so one ulp more keeps
    // those equal to the tolerance, and exact copies at tolerance 0).
    const std::vector<int32_t>& boundary = connectivity.boundary_vertices;
    std::vector<Eigen::Vector3d> boundary_points(boundary.size());
    for (size_t i = 0; i < boundary.size(); ++i) boundary_points[i] = world[boundary[i]];
    PointCloud cloud{boundary_points};
    const PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    const double radius_sq = std::nextafter(tolerance * tolerance, std::numeric_limits<double>::infinity());
    struct Candidate {
        double distance_sq;
        int32_t a, b;  // vertices, a < b
    };
    std::vector<Candidate> candidates;
    std::vector<std::pair<uint32_t, double>> matches;
    for (size_t i = 0; i < boundary.size(); ++i) {
        matches.clear();
        tree.radiusSearch(boundary_points[i].data(), radius_sq, matches, nanoflann::SearchParams(32, 0, false));
        const int32_t a = boundary[i];
        for (const auto& [j, d] : matches) {
            const int32_t b = boundary[j];
            if (b > a && vertex_piece[a] != vertex_piece[b] && d <= 0.25 * std::min(shortest_edge_sq[a], shortest_edge_sq[b]))
                candidates.push_back({d, a, b});
        }
    }
    // Nearest pairs first; a pair joins two clusters unless one piece has a vertex in each (the merge
    // would collapse an edge of that piece). Uniting every pair within the tolerance instead chained
    // across cracks (a copy, a neighbour on the other side, that neighbour's copy...) into clusters
    // that could not merge, so a larger tolerance welded less; and near crack junctions two exact
    // copies a hair apart (exact fracture's split points) joined one cluster and spoilt both.
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
        return std::tie(x.distance_sq, x.a, x.b) < std::tie(y.distance_sq, y.a, y.b);
    });
    DisjointSets clusters(mesh.vertex_count());
    std::vector<int32_t> next_member(mesh.vertex_count());  // each cluster as a circular list
    std::iota(next_member.begin(), next_member.end(), 0);
    const auto share_a_piece = [&](int32_t root_a, int32_t root_b) {
        for (int32_t x = root_a;; x = next_member[x]) {
            for (int32_t y = root_b;; y = next_member[y]) {
                if (vertex_piece[x] == vertex_piece[y]) return true;
                if (next_member[y] == root_b) break;
            }
            if (next_member[x] == root_a) return false;
        }
    };
    for (const Candidate& c : candidates) {
        const int32_t root_a = clusters.find(c.a), root_b = clusters.find(c.b);
        if (root_a == root_b || share_a_piece(root_a, root_b)) continue;
        clusters.unite(root_a, root_b);
        std::swap(next_member[root_a], next_member[root_b]);  // splices the two lists into one
    }

    // Pieces touch when a boundary face of one maps onto a boundary face of another.
    std::map<std::array<int32_t, 3>, int32_t> face_piece;
    const size_t piece_count = mesh.piece_transforms.size();
    DisjointSets groups(piece_count);
    for (const BoundaryFace& face : connectivity.boundary_faces) {
        std::array<int32_t, 3> key;
        for (int k = 0; k < 3; ++k) key[k] = clusters.find(face.vertices[k]);  // the merged vertex
        std::sort(key.begin(), key.end());
        const int32_t piece = mesh.piece_ids[face.tet];
        auto [it, inserted] = face_piece.try_emplace(key, piece);
        if (!inserted && it->second != piece) groups.unite(it->second, piece);
    }

    // Merge: vertices only between pieces of one group (point or edge contact alone joins nothing);
    // every piece of a group is re-expressed in the frame of its lowest piece.
    TetMesh welded = mesh;
    std::vector<int32_t> target(mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        const int32_t m = clusters.find(static_cast<int32_t>(v));
        target[v] = vertex_piece[v] >= 0 && vertex_piece[m] >= 0 &&
                            groups.find(vertex_piece[v]) == groups.find(vertex_piece[m])
                        ? m
                        : static_cast<int32_t>(v);
    }
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        const int32_t piece = vertex_piece[v];
        if (piece < 0) continue;
        const int32_t group = groups.find(piece);
        if (group == piece) continue;
        const RigidTransform& frame = mesh.piece_transforms[group];
        welded.positions[v] = frame.rotation.transpose() * (world[v] - frame.translation);
    }
    for (size_t v = 0; v < mesh.vertex_count(); ++v)
        if (target[v] != static_cast<int32_t>(v)) ++result.vertices_merged;
    std::vector<int32_t> new_index(piece_count, -1);
    std::vector<RigidTransform> transforms;
    for (size_t p = 0; p < piece_count; ++p)
        if (groups.find(static_cast<int32_t>(p)) == static_cast<int32_t>(p)) {
            new_index[p] = static_cast<int32_t>(transforms.size());
            transforms.push_back(mesh.piece_transforms[p]);
        }
    for (size_t t = 0; t < welded.tet_count(); ++t) {
        for (int32_t& v : welded.tets[t]) v = target[v];
        welded.piece_ids[t] = new_index[groups.find(mesh.piece_ids[t])];
        if (!(signed_volume(welded, t) > 0))
            throw AlgorithmError("weld: merging vertices within " + std::to_string(tolerance) +
                                 " would flatten tet " + std::to_string(t) + "; use a smaller tolerance");
    }
    welded.piece_transforms = std::move(transforms);
    // Drops the merged-away vertices (no tet uses them any more).
    const CutResult compacted = remove_tets(welded, std::vector<uint8_t>(welded.tet_count(), 0));
    validate(welded);
    result.old_to_new_vertex.resize(mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v)
        result.old_to_new_vertex[v] = target[v] == static_cast<int32_t>(v) ? compacted.old_to_new_vertex[v] : -1;
    mesh = std::move(welded);
    result.pieces_after = static_cast<int>(mesh.piece_transforms.size());
    return result;
}

}  // namespace waxwork
