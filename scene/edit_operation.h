// The edits a user (or a scripted session) makes to a volume, as plain values: each
// operation is a struct with everything needed to replay it, so the document can re-run it for redo
// and a session file can record it. Document (document.h) applies them; this header only describes
// them and converts them to and from JSON.
//
// JSON form: an object with "op" naming the kind, the other fields as below. Vectors are arrays of
// three numbers; materials are a preset name ("marble") or {"mua": [r,g,b], "musp": [r,g,b], "eta": n}
// (written in the second form, so coefficients round-trip exactly). Fields with defaults may be
// omitted; unknown fields are errors (a typo must not silently fall back to a default).
//   {"op": "plane_cut", "normal": [1,0,0], "offset": 0, "relax": {...}, "exact": false}
//   {"op": "stroke_cut", "eye": [...], "view_direction": [...], "points": [[...], ...], "flip": false,
//    "relax": {...}, "exact": false}
//   {"op": "relax", "plane": {"normal": [...], "offset": d} | "stroke": {"eye": ..., ...}, "relax": {...}}
//   {"op": "fracture", "pieces": 5, "seed": 1} or {"op": "fracture", "seeds": [[...], ...]}, "exact": true,
//    "min_piece_tets": 8, "collapse": true       ("collapse" is written only when false)
//   {"op": "move_piece", "piece": 1, "rotation": [[3x3 rows]], "translation": [...]}
//   {"op": "weld", "tolerance": 1e-6}
//   {"op": "remove_fragments", "max_volume_fraction": 0.001}
//   {"op": "paint", "points": [[...], ...], "material": ..., "sigma": 0.05, "cutoff_weight": 0.001}
//   {"op": "set_material", "material": ..., "piece": 2}          (no "piece": the whole volume)
//   {"op": "deform", "grab": [...], "radius": r, "move": [...] | "bend": {"axis_point": [...], "axis": [...],
//    "angle": radians} | "twist": {"axis_point": [...], "axis": [...], "angle_per_length": radians},
//    "pins": [{"center": [...], "radius": r}, ...], "iterations": 10, "steps": 10, "guard_deg": 0.5}
//   {"op": "refine", "tets": [t, ...] | "points": [[...], ...], "radius": r, "edge_length": h,
//    "max_tets": 0, "guard_deg": 0.5}
// with "relax": {"iterations": 10, "step": 0.1, "guard_deg": 0.5}.
#pragma once

#include "tetops/arap_deformation.h"
#include "tetops/fragments.h"
#include "tetops/tet_mesh.h"

#include <nlohmann/json_fwd.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace waxwork {

// Relaxation of the cut vertices onto the cross-section (tetops/relaxation.h).
struct RelaxSettings {
    int iterations = 10;
    double step = 0.1;       // rho
    double guard_deg = 0.5;  // minimum dihedral angle guard; 0 disables it
    friend bool operator==(const RelaxSettings&, const RelaxSettings&) = default;
};

// The plane n.x = offset; the side n.x > offset is cut away (tetops/cut.h PlaneCut).
struct PlaneSurface {
    Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
    double offset = 0;
    friend bool operator==(const PlaneSurface&, const PlaneSurface&) = default;
};

// A screen-space stroke swept along view rays (tetops/cut.h StrokeCut).
struct StrokeSurface {
    Eigen::Vector3d eye = Eigen::Vector3d::Zero();
    Eigen::Vector3d view_direction = -Eigen::Vector3d::UnitZ();
    std::vector<Eigen::Vector3d> points;  // world space
    bool flip = false;
    friend bool operator==(const StrokeSurface&, const StrokeSurface&) = default;
};

struct PlaneCutOp {
    PlaneSurface plane;
    RelaxSettings relax;
    bool exact = false;  // split tets along the plane (tetops/exact_cut.h) instead of removing whole tets
    friend bool operator==(const PlaneCutOp&, const PlaneCutOp&) = default;
};

struct StrokeCutOp {
    StrokeSurface stroke;
    RelaxSettings relax;
    bool exact = false;
    friend bool operator==(const StrokeCutOp&, const StrokeCutOp&) = default;
};

// More relaxation sweeps toward a cutting surface (the editor's "relax more" after a cut).
struct RelaxOp {
    std::variant<PlaneSurface, StrokeSurface> surface;
    RelaxSettings relax;
    friend bool operator==(const RelaxOp&, const RelaxOp&) = default;
};

// Voronoi fracture (tetops/fracture.h): `pieces` seeds scattered with `seed`, or the explicit `seeds`.
struct FractureOp {
    int pieces = 0;
    uint32_t seed = 0;
    std::vector<Eigen::Vector3d> seeds;  // world space; when non-empty, pieces/seed are ignored
    bool exact = true;
    int min_piece_tets = 8;
    // FractureOptions::collapse_swallowed_walls; false only to compare (`waxwork fracture --no-collapse`).
    bool collapse = true;
    friend bool operator==(const FractureOp&, const FractureOp&) = default;
};

struct MovePieceOp {
    int piece = 0;
    RigidTransform transform;
    friend bool operator==(const MovePieceOp&, const MovePieceOp&) = default;
};

struct WeldOp {
    double tolerance = 1e-6;
    friend bool operator==(const WeldOp&, const WeldOp&) = default;
};

// Drops the face-connected parts smaller than a fraction of the volume (tetops/fragments.h): the
// specks a cut of a concave shape can leave floating.
struct RemoveFragmentsOp {
    double max_volume_fraction = kDefaultFragmentFraction;
    friend bool operator==(const RemoveFragmentsOp&, const RemoveFragmentsOp&) = default;
};

// Gaussian brush stroke (tetops/paint.h).
struct PaintOp {
    std::vector<Eigen::Vector3d> points;  // world space
    TetMaterial material;
    double sigma = 0;
    double cutoff_weight = 1e-3;
    friend bool operator==(const PaintOp&, const PaintOp&) = default;
};

// Replaces the material of every tet, or of one piece's tets.
struct SetMaterialOp {
    TetMaterial material;
    std::optional<int> piece;
    friend bool operator==(const SetMaterialOp&, const SetMaterialOp&) = default;
};

// Bounds on a deform's work (a hostile session must not run for hours).
inline constexpr int kMaxDeformIterations = 1000;
inline constexpr int kMaxDeformSteps = 1000;

// Drags one body as rigidly as possible (tetops/arap_deformation.h): the handle of falloff radius
// `radius` at `grab` follows `motion` (Grab, Bend or Twist; world space) while the pins hold, in
// `steps` guarded steps of `iterations` local/global iterations each, as the editor's drag frames run it.
struct DeformOp {
    Eigen::Vector3d grab = Eigen::Vector3d::Zero();
    double radius = 0;
    HandleMotion motion;
    std::vector<PinSphere> pins;
    int iterations = 10;
    int steps = 10;
    double guard_deg = 0.5;  // no tet ends under this minimum dihedral angle (or under its own, if lower)
    friend bool operator==(const DeformOp&, const DeformOp&) = default;
};

// Conforming longest-edge bisection (tetops/refine.h) within a budget of `max_tets` (0: none), of
// either the listed tets (indices into the mesh the op applies to, in priority order: refine_tets) or,
// when `points` is given, the tets within `radius` of them until their longest edge is at most
// `edge_length` (refine_near_points: what `paint --refine` asks under a stroke).
struct RefineOp {
    std::vector<int32_t> tets;
    std::vector<Eigen::Vector3d> points;  // world space
    double radius = 0;
    double edge_length = 0;
    size_t max_tets = 0;
    double guard_deg = 0.5;
    friend bool operator==(const RefineOp&, const RefineOp&) = default;
};

using EditOperation = std::variant<PlaneCutOp, StrokeCutOp, RelaxOp, FractureOp, MovePieceOp, WeldOp,
                                   RemoveFragmentsOp, PaintOp, SetMaterialOp, DeformOp, RefineOp>;

// The "op" name of an operation ("plane_cut", "paint", ...).
std::string operation_name(const EditOperation& op);

nlohmann::ordered_json to_json(const EditOperation& op);

// Throws InvalidArgumentError naming the field (and `context`, e.g. "session.json: step 3", when
// given): "step 3: paint: field 'sigma': must be a positive number".
EditOperation edit_operation_from_json(const nlohmann::ordered_json& json, const std::string& context = "");

// Material JSON (preset name or coefficients), shared with session files.
nlohmann::ordered_json material_to_json(const TetMaterial& material);
TetMaterial material_from_json(const nlohmann::ordered_json& json, const std::string& context);

// Three numbers; `context` names the field in errors.
Eigen::Vector3d vector_from_json(const nlohmann::ordered_json& json, const std::string& context);
nlohmann::ordered_json vector_to_json(const Eigen::Vector3d& v);

}  // namespace waxwork
