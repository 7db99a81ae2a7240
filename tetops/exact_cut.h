// Exact cutting: tets crossed by the cutting surface are split along it, so the
// cross-section follows the surface instead of the staircase of whole tets that TransCut Sec. 5's
// remove-and-relax leaves behind.
//
// The machinery works on any scalar field sampled at the vertices (zero on the surface): every edge
// whose endpoints have strictly opposite signs gets one new vertex at the surface crossing, shared by
// all tets around that edge; vertices whose crossing lies very close to them are first moved onto the
// surface (snapping, guarded like relaxation.h) because splitting there would make slivers; each
// crossed tet is then split into tets on either side, and a guarded optimisation moves the vertices
// around poor new tets, within the surface, the walls and the flat parts of the boundary
// (split_quality.h). Guarantee: every tet the split creates or moves has a minimum dihedral angle of
// at least min(min_dihedral_guard_deg, that of the tet it comes from); the exceptions are counted
// (tets_under_guard). fracture.cpp uses the same machinery with the Voronoi cell walls as the field.
#pragma once

#include "tetops/cut.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace waxwork {

// A surface given by a scalar field in world space: positive on one side, negative on the other.
class SplitField {
public:
    virtual ~SplitField() = default;
    // For a segment a -> b whose field values va, vb have strictly opposite signs: the parameter t in
    // [0, 1] of the point a + t (b - a) where the segment meets the surface.
    virtual double crossing(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double va, double vb) const = 0;
    // The surface point nearest to `world`, when the field knows it in closed form (a plane); without it,
    // snapping moves a vertex to the nearest crossing on one of its edges (also on the surface).
    virtual std::optional<Eigen::Vector3d> project(const Eigen::Vector3d& /*world*/) const { return std::nullopt; }
};

struct SplitOptions {
    // A vertex whose crossing on one of its edges lies within this fraction of the edge from it is
    // moved onto the surface instead of splitting the edge there (which would make a sliver).
    double snap_fraction = 0.2;
    // Snapping is refused when it would leave a tet of the vertex's star under this minimum dihedral
    // angle (and worse than before), as in relaxation.h; the edges are then split instead.
    double min_dihedral_guard_deg = 0.5;
    // Field values within this absolute tolerance count as on the surface (e.g. vertices created on
    // the same surface by an earlier split, which rounding puts a few ulps off it).
    double zero_tolerance = 0;
    // A vertex on the boundary of the volume snaps only by sliding along a boundary edge, and only when
    // that edge leaves the plane of every boundary face around the vertex by at most this angle
    // (degrees): 0 keeps the shape of the volume exactly (vertices slide only within flat parts and
    // along straight creases), more trades a change of the outer surface of at most
    // sin(bend) x snap_fraction x edge length for fewer slivers where the surface is curved. With
    // bend > 0 a crossing within 1e-3 of an edge from the vertex is snapped to along that edge even
    // where nothing may slide (a corner, a crease, a bumpy relaxed cross-section): split, it would
    // leave a sliver of almost no angle.
    double boundary_bend_deg = 0;
    // Per tet: a region label (e.g. the fracture cell). Faces between tets of different labels are
    // kept in their planes like flat boundary faces (bend 0): a vertex on them snaps only by sliding
    // along an edge that stays in all of them, so earlier walls stay where they are. Null: one region.
    const std::vector<int64_t>* tet_labels = nullptr;
    // Per tet: the angle (degrees) the quality guarantee compares it with, min(guard, reference), from
    // an earlier split of the same operation (fracture: the tet's ancestor before the fracture); NaN
    // or null: the tet as it is now (split_quality.h).
    const std::vector<double>* reference_deg = nullptr;
    // After the split, vertices around new or moved tets under this angle (degrees) are optimised,
    // guarded (split_quality.h); 0 turns the pass off.
    double smooth_below_deg = 5;
    // False: tets on the positive side (about to be cut away) are not worth optimising.
    bool smooth_positive_side = true;
};

struct SplitReport {
    // Per tet after the split: 1 when it lies on the positive side (all its vertices >= 0).
    std::vector<uint8_t> positive;
    // Per tet appended by the split (index tets_before + i): the tet it was cut from.
    std::vector<int32_t> appended_parents;
    // Per vertex appended by the split: the edge (vertex indices before the split) it was made on and
    // the crossing parameter along it.
    std::vector<VertexOrigin> appended_vertex_origins;
    size_t tets_split = 0;
    size_t vertices_snapped = 0;
    size_t vertices_smoothed = 0;
    // Per tet after the split: its reference angle (SplitOptions::reference_deg, carried to the
    // children; NaN for tets the split did not touch).
    std::vector<double> reference_deg;
    // Tets under min(min_dihedral_guard_deg, reference) after the split, counted from the mesh: the
    // exceptions to the guarantee (a case split that no guarded move could repair).
    size_t tets_under_guard = 0;
};

// Splits `mesh` along the zero set of the field sampled in `values` (one per vertex; updated: snapped
// and new vertices get 0). `world` holds the world position of every vertex and is kept in step
// (positions stay in their piece's rest frame). A split tet is replaced by its first child and the
// others are appended; children keep the parent's material, original id and piece. Faces between
// neighbouring tets are split the same way on both sides (diagonals through the lowest vertex index),
// so the result is conforming. Throws AlgorithmError if a child would not be positively oriented.
SplitReport split_along_field(TetMesh& mesh, std::vector<Eigen::Vector3d>& world, std::vector<double>& values,
                              const SplitField& field, const SplitOptions& options = {});

// A CuttingSurface as a field: side() values, closed-form crossings and projection for PlaneCut,
// step_to_surface (bisection) for other surfaces.
class CuttingSurfaceField final : public SplitField {
public:
    explicit CuttingSurfaceField(const CuttingSurface& surface);
    double crossing(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double va, double vb) const override;
    std::optional<Eigen::Vector3d> project(const Eigen::Vector3d& world) const override;

private:
    const CuttingSurface& surface_;
    const PlaneCut* plane_;  // non-null when the surface is a plane
};

struct ExactCutOptions {
    // Boundary vertices slide onto the cut where the surface bends by up to 20 degrees around them:
    // on spot (100K tets) this lifts the worst dihedral angle from 0.01 to 0.15 degrees for a relative
    // volume change of 5e-6 (bench/editing_bench.cpp); 0 keeps the outer surface exactly.
    SplitOptions split = [] {
        SplitOptions o;
        o.boundary_bend_deg = 20;
        return o;
    }();
};

struct ExactCutResult {
    size_t tets_split = 0;
    size_t vertices_snapped = 0;
    size_t vertices_added = 0;
    size_t tets_removed = 0;     // counted after splitting (cut-away children included)
    size_t vertices_removed = 0;
    size_t vertices_smoothed = 0;  // moved by the guarded optimisation after the split
    double min_dihedral_deg = 0;  // of the whole mesh afterwards (0 if empty)
    // Tets left whose minimum dihedral angle is under min(guard, that of the tet before the cut they
    // come from): every other tet the cut created or moved meets that bound (split_quality.h).
    size_t tets_under_guard = 0;
    // Per tet after the cut: the tet before the cut it is (part of).
    std::vector<int32_t> new_to_old_tet;
    // Per vertex after the cut: VertexOrigin::vertex(v) for a vertex v of the mesh before, or the edge
    // ab of the mesh before on which it was created and where along it.
    std::vector<VertexOrigin> vertex_origins;
};

// Splits every tet crossed by `surface` along it and removes the cut-away side (side() > 0). The
// cross-section is made of faces whose vertices lie on the surface (exactly up to rounding for a
// plane, to bisection precision for other surfaces). No relaxation is needed afterwards. On spot at
// 486,745 tets, the plane x = 0 leaves a worst dihedral angle of 1.29 degrees (0.24 with the split
// alone) and no tet under the guard.
ExactCutResult cut_exact(TetMesh& mesh, const CuttingSurface& surface, const ExactCutOptions& options = {});

}  // namespace waxwork
