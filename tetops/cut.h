// Cutting a tetrahedral volume (TransCut, Sec. 5 "Cutting Interaction"): every tet whose four vertices
// lie on the cut-away side of a cutting surface is deleted, vertices left without a tet go with them,
// and the surviving tets keep their materials, original ids and pieces. The remaining vertices on the
// cut-away side are then moved onto the cross-section by relaxation.h.
//
// The surface is an abstraction so the same removal and relaxation serve a plane (the command line)
// and a stroke swept along view rays (the editor): both only need a side test and, for relaxation, the
// point where a straight step meets the surface.
#pragma once

#include "tetops/tet_mesh.h"
#include "tetops/vertex_map.h"  // inverse_vertex_map, for the maps of CutResult

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace waxwork {

// A surface splitting world space into a cut-away side and a kept side.
class CuttingSurface {
public:
    virtual ~CuttingSurface() = default;

    // Positive on the cut-away side, negative on the kept side, zero on the surface. For the plane it
    // is the signed distance; other surfaces need only get the sign right and be continuous across
    // the surface.
    virtual double side(const Eigen::Vector3d& world_point) const = 0;

    // Strictly on the cut-away side: a point on the surface is kept, so a tet touching the surface
    // with one vertex survives.
    bool cuts_away(const Eigen::Vector3d& world_point) const { return side(world_point) > 0; }

    // For a step from `from` (cut-away side or on the surface) to `to`: the largest t in [0, 1] such
    // that from + t (to - from) is not on the kept side (side() >= 0). 1 when `to` is not on the kept
    // side. The default bisects side(); surfaces with a closed form override it.
    virtual double step_to_surface(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const;
};

// What is wrong with the plane n.x = D ("" when nothing is): a non-finite number or a zero normal.
std::string plane_problem(const Eigen::Vector3d& normal, double offset);

// The plane n.x = D; the side n.x > D is cut away. The normal need not be unit length (it is
// normalised, so side() is the signed Euclidean distance).
class PlaneCut final : public CuttingSurface {
public:
    // Throws InvalidArgumentError for a zero or non-finite normal or a non-finite offset.
    PlaneCut(const Eigen::Vector3d& normal, double offset);

    double side(const Eigen::Vector3d& world_point) const override;
    double step_to_surface(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const override;

    const Eigen::Vector3d& unit_normal() const { return normal_; }
    double offset() const { return offset_; }  // along the unit normal

private:
    Eigen::Vector3d normal_;
    double offset_;
};

// A screen-space stroke swept along the view rays of a perspective camera (TransCut Sec. 5): a fan of
// planar panels through the eye, one per stroke segment. Stroke points are given in world space (e.g.
// unprojected onto the near plane); the side test projects a point through the eye onto the screen
// plane (through the first stroke point, perpendicular to the view direction) and uses the nearest
// segment there, the end segments extended to infinity. The cut-away side is the left of the stroke
// direction as the viewer sees it (paper: "the left side of the stroke"), or the right with `flip`.
// Points behind the eye are never cut away.
class StrokeCut final : public CuttingSurface {
public:
    // Throws InvalidArgumentError for fewer than two distinct points, non-finite input, a zero view
    // direction, or stroke points not in front of the eye.
    StrokeCut(const Eigen::Vector3d& eye, const Eigen::Vector3d& view_direction,
              std::vector<Eigen::Vector3d> stroke_points, bool flip = false);

    double side(const Eigen::Vector3d& world_point) const override;

private:
    Eigen::Vector3d eye_;
    Eigen::Vector3d view_;  // unit
    double screen_depth_;   // distance of the screen plane from the eye along view_
    std::vector<Eigen::Vector3d> points_;  // stroke points projected onto the screen plane
    double sign_;           // +1: left is cut away, -1: right
};

// Where a vertex of an edited mesh comes from (an exact cut, a fracture): the point (1 - t) x_a + t x_b
// of edge ab on which it was made, t in [0, 1] (the crossing parameter of the split); a == b and t = 0
// for a vertex kept from, or copied from, vertex a. Per-vertex data carried across the edit are
// interpolated the same way (the editor's warm start).
struct VertexOrigin {
    int32_t a = -1;
    int32_t b = -1;
    double t = 0;

    static VertexOrigin vertex(int32_t v) { return {v, v, 0.0}; }
    bool is_vertex() const { return a == b; }
    friend bool operator==(const VertexOrigin&, const VertexOrigin&) = default;
};

struct CutResult {
    size_t tets_removed = 0;
    size_t vertices_removed = 0;
    // Per vertex of the mesh before the cut: its index after, or -1 when it was removed
    // (inverse_vertex_map reads it the other way).
    std::vector<int32_t> old_to_new_vertex;
    // Per tet after the cut: its index before (so per-tet arrays held elsewhere can follow).
    std::vector<int32_t> new_to_old_tet;
};

// World position of every vertex: rotation * x + translation of its piece. Throws InvalidMeshError
// when a vertex is shared by tets of different pieces. A vertex with no tet keeps its rest position.
std::vector<Eigen::Vector3d> world_positions(const TetMesh& mesh);

// Removes every tet whose four vertices are strictly on the cut-away side (tested in world space),
// then every vertex left without a tet, compacting indices in their original order. Per-tet arrays
// follow their tets; original ids are kept as they were; piece transforms are untouched (a piece may
// become empty). Cutting everything away leaves a valid empty mesh.
CutResult remove_cut_away_tets(TetMesh& mesh, const CuttingSurface& surface);

// For the callers that must not leave an empty volume (the editor, sessions, `waxwork cut`): throws
// InvalidArgumentError when a cut of a mesh of `tets_before` tets left `after` without any, so the
// caller keeps its mesh unchanged. An empty volume can be neither lit nor rendered, and cutting on
// the wrong side is an easy slip of a plane's sign or a stroke's direction.
void require_tets_left_by_cut(const TetMesh& after, size_t tets_before);

// Removes the tets flagged in `remove` (one flag per tet) and the vertices left without a tet, with
// the same compaction and bookkeeping as remove_cut_away_tets (which is this with a side test).
// Throws InvalidArgumentError when the flag count differs from the tet count.
CutResult remove_tets(TetMesh& mesh, const std::vector<uint8_t>& remove);

}  // namespace waxwork
