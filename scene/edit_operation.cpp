#include "scene/edit_operation.h"

#include "scene/json_fields.h"

#include "base/error.h"
#include "solver/material.h"
#include "tetops/fracture.h"
#include "tetops/refine.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <initializer_list>
#include <set>

namespace waxwork {
namespace {

using Json = nlohmann::ordered_json;

// Listed in errors about a missing or unknown "op".
constexpr const char* kOperationNames =
    "plane_cut, stroke_cut, relax, fracture, move_piece, weld, remove_fragments, paint, set_material, deform, refine";


Json relax_to_json(const RelaxSettings& r) {
    return Json{{"iterations", r.iterations}, {"step", r.step}, {"guard_deg", r.guard_deg}};
}

RelaxSettings relax_from_json(const Json& json, const std::string& context) {
    FieldReader in(json, context);
    RelaxSettings r;
    const int64_t iterations = in.integer("iterations", r.iterations);
    if (iterations < 0 || iterations > 100000) fail_json(in.field("iterations"), "must be between 0 and 100000");
    r.iterations = static_cast<int>(iterations);
    r.step = in.number("step", r.step);
    if (!(r.step > 0) || r.step > 1) fail_json(in.field("step"), "must be in (0, 1]");
    r.guard_deg = in.number("guard_deg", r.guard_deg);
    if (r.guard_deg < 0 || r.guard_deg >= 60) fail_json(in.field("guard_deg"), "must be in [0, 60) degrees");
    in.finish();
    return r;
}

RelaxSettings optional_relax(FieldReader& in) {
    return in.has("relax") ? relax_from_json(in.at("relax"), in.field("relax")) : RelaxSettings{};
}

Json points_to_json(const std::vector<Eigen::Vector3d>& points) {
    Json array = Json::array();
    for (const Eigen::Vector3d& p : points) array.push_back(vector_to_json(p));
    return array;
}

Json plane_to_json(const PlaneSurface& p) { return Json{{"normal", vector_to_json(p.normal)}, {"offset", p.offset}}; }

PlaneSurface plane_from_fields(FieldReader& in) {
    PlaneSurface p;
    p.normal = in.vector("normal");
    if (p.normal.norm() == 0) fail_json(in.field("normal"), "must not be zero");
    p.offset = in.number("offset");
    return p;
}

void stroke_to_json(const StrokeSurface& s, Json& out) {
    out["eye"] = vector_to_json(s.eye);
    out["view_direction"] = vector_to_json(s.view_direction);
    out["points"] = points_to_json(s.points);
    out["flip"] = s.flip;
}

StrokeSurface stroke_from_fields(FieldReader& in) {
    StrokeSurface s;
    s.eye = in.vector("eye");
    s.view_direction = in.vector("view_direction");
    if (s.view_direction.norm() == 0) fail_json(in.field("view_direction"), "must not be zero");
    s.points = in.points("points");
    if (s.points.size() < 2) fail_json(in.field("points"), "a stroke needs at least two points");
    s.flip = in.boolean("flip", false);
    return s;
}

Json rotation_to_json(const Eigen::Matrix3d& r) {
    Json rows = Json::array();
    for (int i = 0; i < 3; ++i) rows.push_back(Json::array({r(i, 0), r(i, 1), r(i, 2)}));
    return rows;
}

Eigen::Matrix3d rotation_from_json(const Json& json, const std::string& context) {
    if (!json.is_array() || json.size() != 3) fail_json(context, "expected three rows of three numbers");
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i) r.row(i) = vector_from_json(json[i], context + " row " + std::to_string(i));
    return r;
}

Json axis_to_json(const HandleMotion& m, const char* angle_name) {
    return Json{{"axis_point", vector_to_json(m.axis_point)}, {"axis", vector_to_json(m.axis_direction)}, {angle_name, m.angle}};
}

HandleMotion axis_motion_from_json(FieldReader& in, const char* name, const char* angle_name) {
    FieldReader axis(in.at(name), in.field(name));
    const Eigen::Vector3d point = axis.vector("axis_point");
    const Eigen::Vector3d direction = axis.vector("axis");
    if (direction.norm() == 0) fail_json(axis.field("axis"), "must not be zero");
    const double angle = axis.number(angle_name);
    axis.finish();
    return std::string(name) == "bend" ? HandleMotion::bend(point, direction, angle)
                                       : HandleMotion::twist(point, direction, angle);
}

DeformOp deform_from_fields(FieldReader& in) {
    DeformOp op;
    op.grab = in.vector("grab");
    op.radius = in.number("radius");
    if (!(op.radius > 0)) fail_json(in.field("radius"), "must be a positive number (world units)");
    const int motions = int(in.has("move")) + int(in.has("bend")) + int(in.has("twist"));
    if (motions != 1) fail_json(in.context(), "give exactly one of 'move', 'bend' and 'twist'");
    if (in.has("move")) op.motion = HandleMotion::translation(in.vector("move"));
    if (in.has("bend")) op.motion = axis_motion_from_json(in, "bend", "angle");
    if (in.has("twist")) op.motion = axis_motion_from_json(in, "twist", "angle_per_length");
    if (in.has("pins")) {
        const Json& pins = in.at("pins");
        if (!pins.is_array()) fail_json(in.field("pins"), "expected an array of {\"center\": [x, y, z], \"radius\": r}");
        for (size_t i = 0; i < pins.size(); ++i) {
            FieldReader pin(pins[i], in.field("pins") + "[" + std::to_string(i) + "]");
            PinSphere sphere{pin.vector("center"), pin.number("radius")};
            if (!(sphere.radius > 0)) fail_json(pin.field("radius"), "must be a positive number (world units)");
            pin.finish();
            op.pins.push_back(sphere);
        }
    }
    const int64_t iterations = in.integer("iterations", op.iterations);
    if (iterations < 1 || iterations > kMaxDeformIterations)
        fail_json(in.field("iterations"), "must be between 1 and " + std::to_string(kMaxDeformIterations));
    op.iterations = static_cast<int>(iterations);
    const int64_t steps = in.integer("steps", op.steps);
    if (steps < 1 || steps > kMaxDeformSteps)
        fail_json(in.field("steps"), "must be between 1 and " + std::to_string(kMaxDeformSteps));
    op.steps = static_cast<int>(steps);
    op.guard_deg = in.number("guard_deg", op.guard_deg);
    if (op.guard_deg < 0 || op.guard_deg >= 60) fail_json(in.field("guard_deg"), "must be in [0, 60) degrees");
    return op;
}

struct ToJson {
    Json operator()(const PlaneCutOp& op) const {
        Json j{{"op", "plane_cut"}, {"normal", vector_to_json(op.plane.normal)}, {"offset", op.plane.offset}};
        j["relax"] = relax_to_json(op.relax);
        j["exact"] = op.exact;
        return j;
    }
    Json operator()(const StrokeCutOp& op) const {
        Json j{{"op", "stroke_cut"}};
        stroke_to_json(op.stroke, j);
        j["relax"] = relax_to_json(op.relax);
        j["exact"] = op.exact;
        return j;
    }
    Json operator()(const RelaxOp& op) const {
        Json j{{"op", "relax"}};
        if (const auto* plane = std::get_if<PlaneSurface>(&op.surface)) {
            j["plane"] = plane_to_json(*plane);
        } else {
            Json s = Json::object();
            stroke_to_json(std::get<StrokeSurface>(op.surface), s);
            j["stroke"] = s;
        }
        j["relax"] = relax_to_json(op.relax);
        return j;
    }
    Json operator()(const FractureOp& op) const {
        Json j{{"op", "fracture"}};
        if (op.seeds.empty()) {
            j["pieces"] = op.pieces;
            j["seed"] = op.seed;
        } else {
            j["seeds"] = points_to_json(op.seeds);
        }
        j["exact"] = op.exact;
        j["min_piece_tets"] = op.min_piece_tets;
        // Written only when off: a session that keeps the default records no field for it.
        if (!op.collapse) j["collapse"] = false;
        return j;
    }
    Json operator()(const MovePieceOp& op) const {
        return Json{{"op", "move_piece"},
                    {"piece", op.piece},
                    {"rotation", rotation_to_json(op.transform.rotation)},
                    {"translation", vector_to_json(op.transform.translation)}};
    }
    Json operator()(const WeldOp& op) const { return Json{{"op", "weld"}, {"tolerance", op.tolerance}}; }
    Json operator()(const RemoveFragmentsOp& op) const {
        return Json{{"op", "remove_fragments"}, {"max_volume_fraction", op.max_volume_fraction}};
    }
    Json operator()(const PaintOp& op) const {
        return Json{{"op", "paint"},
                    {"points", points_to_json(op.points)},
                    {"material", material_to_json(op.material)},
                    {"sigma", op.sigma},
                    {"cutoff_weight", op.cutoff_weight}};
    }
    Json operator()(const SetMaterialOp& op) const {
        Json j{{"op", "set_material"}, {"material", material_to_json(op.material)}};
        if (op.piece) j["piece"] = *op.piece;
        return j;
    }
    Json operator()(const DeformOp& op) const {
        Json j{{"op", "deform"}, {"grab", vector_to_json(op.grab)}, {"radius", op.radius}};
        switch (op.motion.kind) {
        case HandleMotion::Kind::Translate: j["move"] = vector_to_json(op.motion.move); break;
        case HandleMotion::Kind::Bend: j["bend"] = axis_to_json(op.motion, "angle"); break;
        case HandleMotion::Kind::Twist: j["twist"] = axis_to_json(op.motion, "angle_per_length"); break;
        }
        if (!op.pins.empty()) {
            Json pins = Json::array();
            for (const PinSphere& pin : op.pins) pins.push_back(Json{{"center", vector_to_json(pin.center)}, {"radius", pin.radius}});
            j["pins"] = pins;
        }
        j["iterations"] = op.iterations;
        j["steps"] = op.steps;
        j["guard_deg"] = op.guard_deg;
        return j;
    }
    Json operator()(const RefineOp& op) const {
        Json j{{"op", "refine"}};
        if (op.points.empty()) {
            j["tets"] = op.tets;
        } else {
            j["points"] = points_to_json(op.points);
            j["radius"] = op.radius;
            j["edge_length"] = op.edge_length;
        }
        j["max_tets"] = op.max_tets;
        j["guard_deg"] = op.guard_deg;
        return j;
    }
};

RefineOp refine_from_fields(FieldReader& in) {
    RefineOp op;
    if (in.has("tets") == in.has("points")) fail_json(in.context(), "give exactly one of 'tets' and 'points'");
    if (in.has("points")) {
        op.points = in.points("points");
        if (op.points.empty()) fail_json(in.field("points"), "needs at least one point");
        op.radius = in.number("radius");
        if (!(op.radius > 0)) fail_json(in.field("radius"), "must be a positive number (world units)");
        op.edge_length = in.number("edge_length");
        if (!(op.edge_length > 0)) fail_json(in.field("edge_length"), "must be a positive number (model units)");
    }
    const Json& tets = in.has("tets") ? in.at("tets") : Json::array();
    if (!tets.is_array()) fail_json(in.field("tets"), "expected an array of tet indices");
    op.tets.reserve(tets.size());
    for (size_t i = 0; i < tets.size(); ++i) {
        if (!tets[i].is_number_integer() || tets[i].get<int64_t>() < 0 || tets[i].get<int64_t>() > INT32_MAX)
            fail_json(in.field("tets") + " entry " + std::to_string(i), "expected a tet index >= 0");
        op.tets.push_back(static_cast<int32_t>(tets[i].get<int64_t>()));
    }
    const int64_t max_tets = in.integer("max_tets", 0);
    if (max_tets < 0 || static_cast<uint64_t>(max_tets) > kMaxRefinedTets)
        fail_json(in.field("max_tets"), "must be between 0 (no budget) and " + std::to_string(kMaxRefinedTets));
    op.max_tets = static_cast<size_t>(max_tets);
    op.guard_deg = in.number("guard_deg", op.guard_deg);
    if (op.guard_deg < 0 || op.guard_deg >= 60) fail_json(in.field("guard_deg"), "must be in [0, 60) degrees");
    return op;
}

}  // namespace

std::string operation_name(const EditOperation& op) { return to_json(op).at("op").get<std::string>(); }

Json vector_to_json(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

Eigen::Vector3d vector_from_json(const Json& json, const std::string& context) {
    if (!json.is_array() || json.size() != 3) fail_json(context, "expected an array of three numbers");
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) {
        if (!json[i].is_number() || !std::isfinite(json[i].get<double>()))
            fail_json(context, "expected an array of three finite numbers");
        v[i] = json[i].get<double>();
    }
    return v;
}

Json material_to_json(const TetMaterial& m) {
    return Json{{"mua", Json::array({m.mua[0], m.mua[1], m.mua[2]})},
                {"musp", Json::array({m.musp[0], m.musp[1], m.musp[2]})},
                {"eta", m.eta}};
}

TetMaterial material_from_json(const Json& json, const std::string& context) {
    if (json.is_string()) {
        try {
            return material_preset(json.get<std::string>());
        } catch (const Error& e) {
            fail_json(context, e.what());
        }
    }
    FieldReader in(json, context);
    if (in.has("preset")) {
        const Json& name = in.at("preset");
        if (!name.is_string()) fail_json(in.field("preset"), "expected a preset name");
        in.finish();
        return material_from_json(name, in.field("preset"));
    }
    TetMaterial m;
    const Eigen::Vector3d mua = in.vector("mua");
    const Eigen::Vector3d musp = in.vector("musp");
    for (int c = 0; c < 3; ++c) {
        m.mua[c] = mua[c];
        m.musp[c] = musp[c];
    }
    m.eta = in.number("eta");
    in.finish();
    try {
        validate_material(m, context);
    } catch (const Error& e) {
        throw InvalidArgumentError(e.what());
    }
    return m;
}

Json to_json(const EditOperation& op) { return std::visit(ToJson{}, op); }

EditOperation edit_operation_from_json(const Json& json, const std::string& context) {
    if (!json.is_object()) fail_json(context, "an edit operation must be a JSON object with an \"op\" field");
    if (!json.contains("op") || !json.at("op").is_string())
        fail_json(context, std::string("missing field 'op' (") + kOperationNames + ")");
    const std::string name = json.at("op").get<std::string>();
    FieldReader in(json, prefixed(context, name));
    in.ignore("op");
    EditOperation result;
    if (name == "plane_cut") {
        PlaneCutOp op;
        op.plane = plane_from_fields(in);
        op.relax = optional_relax(in);
        op.exact = in.boolean("exact", false);
        result = op;
    } else if (name == "stroke_cut") {
        StrokeCutOp op;
        op.stroke = stroke_from_fields(in);
        op.relax = optional_relax(in);
        op.exact = in.boolean("exact", false);
        result = op;
    } else if (name == "relax") {
        RelaxOp op;
        if (in.has("plane") == in.has("stroke")) fail_json(in.context(), "give exactly one of 'plane' and 'stroke'");
        if (in.has("plane")) {
            FieldReader plane(in.at("plane"), in.field("plane"));
            op.surface = plane_from_fields(plane);
            plane.finish();
        } else {
            FieldReader stroke(in.at("stroke"), in.field("stroke"));
            op.surface = stroke_from_fields(stroke);
            stroke.finish();
        }
        op.relax = optional_relax(in);
        result = op;
    } else if (name == "fracture") {
        FractureOp op;
        if (in.has("seeds")) {
            op.seeds = in.points("seeds");
            if (op.seeds.empty()) fail_json(in.field("seeds"), "needs at least one seed point");
            if (in.has("pieces") || in.has("seed")) fail_json(in.context(), "give either 'seeds' or 'pieces' and 'seed'");
        } else {
            const int64_t pieces = in.integer("pieces");
            if (pieces < 1 || pieces > kMaxFracturePieces)
                fail_json(in.field("pieces"), "must be between 1 and " + std::to_string(kMaxFracturePieces));
            op.pieces = static_cast<int>(pieces);
            const int64_t seed = in.integer("seed", 0);
            if (seed < 0 || seed > int64_t{UINT32_MAX}) fail_json(in.field("seed"), "must be in [0, 2^32)");
            op.seed = static_cast<uint32_t>(seed);
        }
        op.exact = in.boolean("exact", true);
        const int64_t min_tets = in.integer("min_piece_tets", op.min_piece_tets);
        if (min_tets < 0 || min_tets > 1000000000) fail_json(in.field("min_piece_tets"), "must be non-negative");
        op.min_piece_tets = static_cast<int>(min_tets);
        op.collapse = in.boolean("collapse", true);
        result = op;
    } else if (name == "move_piece") {
        MovePieceOp op;
        const int64_t piece = in.integer("piece");
        if (piece < 0 || piece > INT32_MAX) fail_json(in.field("piece"), "must be a piece index >= 0");
        op.piece = static_cast<int>(piece);
        if (in.has("rotation")) op.transform.rotation = rotation_from_json(in.at("rotation"), in.field("rotation"));
        if (in.has("translation")) op.transform.translation = in.vector("translation");
        const Eigen::Matrix3d& r = op.transform.rotation;
        if (!((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-6) || !(r.determinant() > 0))
            fail_json(in.field("rotation"), "must be a rotation matrix (orthonormal, determinant +1)");
        result = op;
    } else if (name == "weld") {
        WeldOp op;
        op.tolerance = in.number("tolerance", op.tolerance);
        if (op.tolerance < 0) fail_json(in.field("tolerance"), "must be non-negative");
        result = op;
    } else if (name == "remove_fragments") {
        RemoveFragmentsOp op;
        op.max_volume_fraction = in.number("max_volume_fraction", op.max_volume_fraction);
        if (!(op.max_volume_fraction >= 0 && op.max_volume_fraction < 1))
            fail_json(in.field("max_volume_fraction"), "must be in [0, 1) (a fraction of the whole volume)");
        result = op;
    } else if (name == "paint") {
        PaintOp op;
        op.points = in.points("points");
        if (op.points.empty()) fail_json(in.field("points"), "needs at least one stroke point");
        op.material = in.material("material");
        op.sigma = in.number("sigma");
        if (!(op.sigma > 0)) fail_json(in.field("sigma"), "must be a positive number (world units)");
        op.cutoff_weight = in.number("cutoff_weight", op.cutoff_weight);
        if (!(op.cutoff_weight > 0 && op.cutoff_weight < 1)) fail_json(in.field("cutoff_weight"), "must be in (0, 1)");
        result = op;
    } else if (name == "set_material") {
        SetMaterialOp op;
        op.material = in.material("material");
        if (in.has("piece")) {
            const int64_t piece = in.integer("piece");
            if (piece < 0 || piece > INT32_MAX) fail_json(in.field("piece"), "must be a piece index >= 0");
            op.piece = static_cast<int>(piece);
        }
        result = op;
    } else if (name == "deform") {
        result = deform_from_fields(in);
    } else if (name == "refine") {
        result = refine_from_fields(in);
    } else {
        fail_json(context, "unknown op '" + name + "' (" + kOperationNames + ")");
    }
    in.finish();
    return result;
}

}  // namespace waxwork
