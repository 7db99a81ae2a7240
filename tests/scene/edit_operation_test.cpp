#include "base/error.h"
#include "scene/edit_operation.h"
#include "solver/material.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

namespace waxwork {
namespace {

using Json = nlohmann::ordered_json;

std::vector<EditOperation> one_of_each() {
    PlaneCutOp plane;
    plane.plane = {Eigen::Vector3d(0.3, -1.0 / 3.0, 2), 0.1234567890123};
    plane.relax = {7, 0.25, 1.0};
    StrokeCutOp stroke;
    stroke.stroke = {Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(0, 0, -1),
                     {Eigen::Vector3d(-1, 0.1, 4), Eigen::Vector3d(1, -0.2, 4)}, true};
    RelaxOp relax_plane{PlaneSurface{Eigen::Vector3d(1, 0, 0), 0.5}, RelaxSettings{3, 0.5, 0}};
    RelaxOp relax_stroke{stroke.stroke, RelaxSettings{}};
    FractureOp scattered;
    scattered.pieces = 5;
    scattered.seed = 4000000000u;
    FractureOp seeded;
    seeded.seeds = {Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0.7, 0.8, 0.9)};
    seeded.exact = false;
    seeded.min_piece_tets = 0;
    seeded.collapse = false;
    MovePieceOp move;
    move.piece = 2;
    move.transform.rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    move.transform.translation = Eigen::Vector3d(0.1, -0.2, 1e-17);
    PaintOp paint;
    paint.points = {Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(0.6, 0.5, 0.5)};
    paint.material = material_preset("ketchup");
    paint.sigma = 0.07;
    SetMaterialOp all{material_preset("skin1"), std::nullopt};
    SetMaterialOp one{material_preset("marble"), 3};
    DeformOp grab;
    grab.grab = Eigen::Vector3d(1, 0.5, 1.0 / 3.0);
    grab.radius = 0.4;
    grab.motion = HandleMotion::translation(Eigen::Vector3d(0.1, -0.2, 1e-17));
    grab.pins = {PinSphere{Eigen::Vector3d(0, 0.5, 0.5), 0.3}, PinSphere{Eigen::Vector3d(0, 0, 0), 0.1}};
    DeformOp bend = grab;
    bend.motion = HandleMotion::bend(Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(0, 0, 2), 0.7853981633974483);
    bend.pins.clear();
    bend.iterations = 3;
    bend.steps = 1;
    bend.guard_deg = 0;
    DeformOp twist = grab;
    twist.motion = HandleMotion::twist(Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(1, 0, 0), -1.0 / 3.0);
    RefineOp refine;
    refine.tets = {12, 3, 2147483647};
    refine.max_tets = 5000;
    refine.guard_deg = 0.25;
    RefineOp near;
    near.points = {Eigen::Vector3d(0.5, 0.25, 1.0 / 3.0)};
    near.radius = 0.3;
    near.edge_length = 0.05;
    return {plane,        stroke,      relax_plane, relax_stroke, scattered, seeded,
            move,         WeldOp{1e-5}, RemoveFragmentsOp{0.0025}, paint, all,   one, grab, bend, twist,
            refine,       RefineOp{},   near};
}

TEST(EditOperation, EveryKindRoundTripsThroughJsonText) {
    for (const EditOperation& op : one_of_each()) {
        const std::string text = to_json(op).dump();
        const EditOperation back = edit_operation_from_json(Json::parse(text));
        EXPECT_EQ(back.index(), op.index()) << text;
        EXPECT_TRUE(back == op) << text;
        EXPECT_EQ(to_json(back).dump(), text);
    }
}

// Fields added to an operation are written only when not at their default, so the JSON of every
// operation that keeps the default, and so every recorded session, is the same text as without them.
TEST(EditOperation, FractureWritesCollapseOnlyWhenOff) {
    FractureOp op;
    op.pieces = 3;
    op.seed = 2;
    EXPECT_EQ(to_json(op).dump(), R"({"op":"fracture","pieces":3,"seed":2,"exact":true,"min_piece_tets":8})");
    EXPECT_TRUE(std::get<FractureOp>(edit_operation_from_json(to_json(op))).collapse);
    op.collapse = false;
    EXPECT_EQ(to_json(op).dump(),
              R"({"op":"fracture","pieces":3,"seed":2,"exact":true,"min_piece_tets":8,"collapse":false})");
    EXPECT_FALSE(std::get<FractureOp>(edit_operation_from_json(to_json(op))).collapse);
}

TEST(EditOperation, DefaultsFillOmittedFields) {
    const EditOperation op = edit_operation_from_json(Json::parse(R"({"op":"plane_cut","normal":[1,0,0],"offset":0})"));
    const auto& cut = std::get<PlaneCutOp>(op);
    EXPECT_EQ(cut.relax, RelaxSettings{});
    EXPECT_FALSE(cut.exact);
    const EditOperation paint = edit_operation_from_json(
        Json::parse(R"({"op":"paint","points":[[0,0,0]],"material":"ketchup","sigma":0.1})"));
    EXPECT_EQ(std::get<PaintOp>(paint).material, material_preset("ketchup"));
}

std::string error_of(const std::string& text, const std::string& context = "") {
    try {
        edit_operation_from_json(Json::parse(text), context);
    } catch (const InvalidArgumentError& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(EditOperation, ErrorsNameTheContextAndTheField) {
    EXPECT_NE(error_of(R"({"op":"paint","points":[[0,0,0]],"material":"ketchup","sigma":-1})", "s.json: step 3")
                  .find("s.json: step 3: paint: field 'sigma'"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"op":"plane_cut","normal":[1,0],"offset":0})").find("field 'normal'"), std::string::npos);
    EXPECT_NE(error_of(R"({"op":"plane_cut","normal":[1,0,0]})").find("missing field 'offset'"), std::string::npos);
    EXPECT_NE(error_of(R"({"op":"plane_cut","normal":[1,0,0],"offset":0,"ofset":1})").find("unknown field 'ofset'"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"op":"carve"})").find("unknown op 'carve'"), std::string::npos);
    EXPECT_NE(error_of(R"({"normal":[1,0,0]})").find("missing field 'op'"), std::string::npos);
    EXPECT_NE(error_of(R"({"op":"paint","points":[[0,0,0]],"material":"unobtainium","sigma":1})")
                  .find("field 'material'"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"op":"plane_cut","normal":[1,0,0],"offset":0,"relax":{"iterations":-1}})")
                  .find("field 'relax': field 'iterations'"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"op":"move_piece","piece":0,"rotation":[[2,0,0],[0,1,0],[0,0,1]]})").find("rotation"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"op":"fracture","pieces":3,"seeds":[[0,0,0]]})").find("either"), std::string::npos);
    // The command line's limit (tetops/fracture.h), not a looser one of its own.
    EXPECT_NE(error_of(R"({"op":"fracture","pieces":1001})").find("field 'pieces': must be between 1 and 1000"),
              std::string::npos)
        << error_of(R"({"op":"fracture","pieces":1001})");
    EXPECT_NE(error_of(R"({"op":"relax","relax":{}})").find("exactly one of"), std::string::npos);
    EXPECT_NE(error_of(R"({"op":"fracture","pieces":3,"collapse":0})").find("field 'collapse': expected true or false"),
              std::string::npos);
}

TEST(EditOperation, RefineErrorsNameTheField) {
    EXPECT_NE(error_of(R"({"op":"refine"})").find("exactly one of 'tets' and 'points'"), std::string::npos);
    EXPECT_NE(error_of(R"({"op":"refine","points":[[0,0,0]],"radius":1})").find("missing field 'edge_length'"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"op":"refine","points":[[0,0,0]],"radius":1,"edge_length":0})").find("field 'edge_length'"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"op":"refine","tets":[1,-2]})").find("field 'tets' entry 1"), std::string::npos);
    EXPECT_NE(error_of(R"({"op":"refine","tets":[1.5]})").find("field 'tets' entry 0"), std::string::npos);
    EXPECT_NE(error_of(R"({"op":"refine","tets":[],"max_tets":-3})").find("field 'max_tets'"), std::string::npos);
    EXPECT_NE(error_of(R"({"op":"refine","tets":[],"max_tets":1e30})").find("field 'max_tets'"), std::string::npos);
    EXPECT_NE(error_of(R"({"op":"refine","tets":[],"guard_deg":60})").find("field 'guard_deg'"), std::string::npos);
}

TEST(EditOperation, DeformErrorsNameTheField) {
    const std::string grab = R"("op":"deform","grab":[1,0.5,0.5],"radius":0.4,)";
    EXPECT_NE(error_of("{" + grab + R"("move":[0,1,0],"bend":{"axis_point":[0,0,0],"axis":[0,0,1],"angle":1}})")
                  .find("exactly one of 'move', 'bend' and 'twist'"),
              std::string::npos);
    EXPECT_NE(error_of("{" + grab.substr(0, grab.size() - 1) + "}").find("exactly one of"), std::string::npos);
    EXPECT_NE(error_of(R"({"op":"deform","grab":[1,0.5,0.5],"radius":0,"move":[0,1,0]})").find("field 'radius'"),
              std::string::npos);
    EXPECT_NE(error_of("{" + grab + R"("bend":{"axis_point":[0,0,0],"axis":[0,0,0],"angle":1}})")
                  .find("field 'bend': field 'axis': must not be zero"),
              std::string::npos);
    EXPECT_NE(error_of("{" + grab + R"("twist":{"axis_point":[0,0,0],"axis":[0,0,1]}})")
                  .find("missing field 'angle_per_length'"),
              std::string::npos);
    EXPECT_NE(error_of("{" + grab + R"("move":[0,1,0],"pins":[{"center":[0,0,0],"radius":-1}]})")
                  .find("field 'pins'[0]: field 'radius'"),
              std::string::npos);
    EXPECT_NE(error_of("{" + grab + R"("move":[0,1,0],"steps":100000})").find("field 'steps': must be between 1 and 1000"),
              std::string::npos);
    EXPECT_NE(error_of("{" + grab + R"("move":[0,1,0],"iterations":0})").find("field 'iterations'"), std::string::npos);
}

}  // namespace
}  // namespace waxwork
