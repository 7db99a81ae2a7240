#include "base/error.h"
#include "io/image_io.h"
#include "io/volume_file.h"
#include "scene/session.h"
#include "solver/material.h"
#include "tetops/test_meshes.h"

#include "support/cli_run.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace waxwork {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

const fs::path kSessions = fs::path(WAXWORK_ASSET_DIR) / "sessions";

TEST(Session, ExampleSessionsParseAndRoundTripThroughJson) {
    int count = 0;
    for (const auto& entry : fs::directory_iterator(kSessions)) {
        if (entry.path().extension() != ".json") continue;
        ++count;
        const Session session = read_session(entry.path());
        EXPECT_FALSE(session.steps.empty()) << entry.path();
        const Json json = session_to_json(session);
        const Session again = parse_session(json, "", "again");
        EXPECT_EQ(session_to_json(again).dump(), json.dump()) << entry.path();
    }
    EXPECT_GE(count, 3);
}

std::string session_error(const std::string& text) {
    const fs::path dir = testing::scratch_dir("errors");
    const fs::path path = dir / "bad.json";
    std::ofstream(path) << text;
    try {
        read_session(path);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(Session, CameraZoomAndPanRoundTrip) {
    // The editor records its zoom as the margin and its pan as the target offset.
    const Session session = parse_session(Json::parse(R"({"input": {"volume": "v.vtu"},
        "camera": {"eye_direction": [0, 0, 1], "margin": 0.8, "target_offset": [0.25, -0.5, 0]}, "steps": []})"),
                                          "/d", "s.json");
    EXPECT_EQ(session.camera.margin, 0.8);
    EXPECT_EQ(session.camera.target_offset, Eigen::Vector3d(0.25, -0.5, 0));
    const Session again = parse_session(session_to_json(session), "/d", "again");
    EXPECT_EQ(again.camera.target_offset, session.camera.target_offset);
    EXPECT_EQ(again.camera.margin, session.camera.margin);
    // No pan: the field is left out, so older readers and hand-written sessions stay as they were.
    Session plain = session;
    plain.camera.target_offset.setZero();
    EXPECT_FALSE(session_to_json(plain)["camera"].contains("target_offset"));
    const std::string e = [] {
        try {
            parse_session(Json::parse(R"({"input": {"volume": "v.vtu"}, "camera": {"target_offset": [0, "a", 0]},
                                          "steps": []})"), "/d", "s.json");
        } catch (const InvalidArgumentError& error) {
            return std::string(error.what());
        }
        return std::string("(no error)");
    }();
    EXPECT_NE(e.find("s.json: field 'camera': field 'target_offset'"), std::string::npos) << e;
}

TEST(Session, ErrorsNameTheFileAndTheStep) {
    const std::string head = R"({"input": {"volume": "v.vtu"}, "steps": [{"render": "a.png"}, )";
    std::string e = session_error(head + R"({"op": "paint", "points": [[0,0,0]], "material": "marble", "sigma": 0}]})");
    EXPECT_NE(e.find("bad.json: step 1: paint: field 'sigma'"), std::string::npos) << e;
    e = session_error(head + R"({"undo": 0}]})");
    EXPECT_NE(e.find("bad.json: step 1: field 'undo'"), std::string::npos) << e;
    e = session_error(head + R"({"render": "b.png", "frame": 2}]})");
    EXPECT_NE(e.find("step 1: unknown field 'frame'"), std::string::npos) << e;
    e = session_error(head + R"({"light": {"lights": [{"direction": [0,0,0]}]}}]})");
    EXPECT_NE(e.find("step 1: field 'light'"), std::string::npos) << e;
    e = session_error(R"({"input": {"volume": "v.vtu", "max_tets": 5}, "steps": []})");
    EXPECT_NE(e.find("bad.json: field 'input'"), std::string::npos) << e;
    e = session_error(R"({"input": {"volume": "v.vtu"}, "scale": 1e308, "steps": []})");  // overflowed tet volumes
    EXPECT_NE(e.find("bad.json: field 'scale': must be a length in mm per model unit"), std::string::npos) << e;
    e = session_error(R"({"input": {"volume": "v.vtu"}, "steps": [})");
    EXPECT_NE(e.find("bad.json: not valid JSON"), std::string::npos) << e;
    // Under double's rounding no solve can reach a tolerance: refused as render --tol refuses it, not
    // left to the solver's breakdown message, which blamed the mesh.
    for (const std::string tolerance : {"1e-300", "1e-16", "0", "1"}) {
        e = session_error(R"({"input": {"volume": "v.vtu"}, "tolerance": )" + tolerance + R"(, "steps": []})");
        EXPECT_NE(e.find("bad.json: field 'tolerance': must be a relative tolerance in [1e-15, 1)"), std::string::npos)
            << e;
    }
    for (const std::string name : {"../escape.png", "/tmp/escape.png", "a/../../b.vtu"}) {  // outside -o
        e = session_error(R"({"input": {"volume": "v.vtu"}, "steps": [{"render": ")" + name + R"("}]})");
        EXPECT_NE(e.find("must stay inside the output directory"), std::string::npos) << e;
    }
    // Output formats are checked when the session is read, before any step has written anything.
    e = session_error(head + R"({"render": "b.txt"}]})");
    EXPECT_NE(e.find("bad.json: step 1: field 'render': 'b.txt' must be a .png"), std::string::npos) << e;
    e = session_error(head + R"({"save": "b.obj"}]})");
    EXPECT_NE(e.find("bad.json: step 1: field 'save': 'b.obj' must name a volume format"), std::string::npos) << e;
    e = session_error(R"({"input": {"volume": "v.vtu"}, "scale": 1e400, "steps": []})");  // no double holds it
    EXPECT_NE(e.find("bad.json: not valid JSON"), std::string::npos) << e;
    EXPECT_NE(e.find("1e400"), std::string::npos) << e;
}

// An input that fails to load names the session as well as the input, whichever error type it raises: the
// input is a path relative to the session, and the user ran the session.
// A camera that cannot be oriented is refused where it is read, not at the first render; a direction
// of any magnitude is a direction.
TEST(Session, CamerasAreCheckedWhenRead) {
    std::string e = session_error(R"({"input": {"volume": "v.vtu"}, "camera": {"eye_direction": [0, 2, 0]}, "steps": []})");
    EXPECT_NE(e.find("bad.json: field 'camera': field 'eye_direction': the up vector must not be zero or parallel"),
              std::string::npos)
        << e;
    e = session_error(R"({"input": {"volume": "v.vtu"}, "steps": [{"render": "a.png"},
                          {"camera": {"up": [0, 0, -1e308], "eye_direction": [0, 0, 1]}}]})");
    EXPECT_NE(e.find("bad.json: step 1: field 'camera': field 'up': the up vector must not be zero or parallel"),
              std::string::npos)
        << e;
    const Session huge = parse_session(Json::parse(R"({"input": {"volume": "v.vtu"},
        "camera": {"eye_direction": [1e308, 0, 1e308], "up": [0, 1e-300, 0]}, "steps": []})"), "/d", "s.json");
    const Eigen::AlignedBox3d box(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1));
    CameraSettings unit = huge.camera;
    unit.eye_direction = {1, 0, 1};
    unit.up = {0, 1, 0};
    EXPECT_LT((frame_camera(box, huge.camera, 1.0).view - frame_camera(box, unit, 1.0).view).norm(), 1e-12);
}

TEST(Session, InputErrorsNameTheSession) {
    const fs::path dir = testing::scratch_dir("input_errors");
    std::ofstream(dir / "empty.stl") << "solid x\nendsolid x\n";
    std::ofstream(dir / "open.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";  // one triangle: not closed
    const auto run_error = [&](const std::string& input) -> std::string {
        std::ofstream(dir / "s.json") << R"({"input": )" + input + R"(, "steps": []})";
        try {
            run_session(read_session(dir / "s.json"), dir / "out");
        } catch (const Error& e) {
            return e.what();
        }
        return "(no error)";
    };
    std::string e = run_error(R"({"volume": "missing.vtu"})");
    EXPECT_NE(e.find("missing.vtu: cannot open"), std::string::npos) << e;
    EXPECT_NE(e.find("s.json: input)"), std::string::npos) << e;
    e = run_error(R"({"surface": "empty.stl"})");
    EXPECT_NE(e.find("empty.stl"), std::string::npos) << e;
    EXPECT_NE(e.find("s.json: input"), std::string::npos) << e;
    e = run_error(R"({"surface": "open.obj"})");
    EXPECT_NE(e.find("open.obj"), std::string::npos) << e;
    EXPECT_NE(e.find("s.json: input"), std::string::npos) << e;
}

// The crease angle is the session's: it round-trips, a bad one names the field, and it reaches the
// rendered frames (a cube's edges shade as folded at 40 degrees and as one normal per vertex at 180).
TEST(Session, CreaseAngleRoundTripsAndReachesTheFrames) {
    const fs::path dir = testing::scratch_dir("crease");
    write_volume(testing::make_cube_mesh(4), dir / "cube.vtu");
    const auto session_with = [&](const std::string& angle) {
        return parse_session(Json::parse(R"({"input": {"volume": "cube.vtu"}, "crease_angle": )" + angle +
                                         R"(, "lights": [{"direction": [1, -1, -1]}], "ambient": [0.02, 0.02, 0.02],
                                             "image": {"width": 96, "height": 72}, "steps": [{"render": "a.png"}]})"),
                             dir, "s.json");
    };
    const Session folded = session_with("40"), round = session_with("180");
    EXPECT_EQ(folded.crease_angle_degrees, 40.0);
    EXPECT_EQ(parse_session(session_to_json(round), dir, "again").crease_angle_degrees, 180.0);
    EXPECT_EQ(parse_session(Json::parse(R"({"input": {"volume": "cube.vtu"}, "steps": []})"), dir, "s.json")
                  .crease_angle_degrees,
              kDefaultCreaseAngleDegrees);
    const std::string e = session_error(R"({"input": {"volume": "v.vtu"}, "crease_angle": 200, "steps": []})");
    EXPECT_NE(e.find("bad.json: field 'crease_angle': must be between 0 and 180 degrees"), std::string::npos) << e;

    run_session(folded, dir / "folded");
    run_session(round, dir / "round");
    const Image a = read_png(dir / "folded" / "a.png"), b = read_png(dir / "round" / "a.png");
    ASSERT_EQ(a.rgba.size(), b.rgba.size());
    EXPECT_NE(a.rgba, b.rgba);
}

// A session that names no lights is lit as `waxwork render` lights a volume (key light, ambient,
// shadows) rather than rendered black; an explicit empty list is no light, and an "ambient" alone
// keeps the key light.
TEST(Session, WithoutLightsItIsLitAsRenderLightsIt) {
    const fs::path dir = testing::scratch_dir("default_lights");
    write_volume(testing::make_cube_mesh(4), dir / "cube.vtu");
    const auto parse = [&](const std::string& fields) {
        return parse_session(Json::parse(R"({"input": {"volume": "cube.vtu"}, )" + fields +
                                         R"("image": {"width": 64, "height": 48}, "steps": [{"render": "a.png"}]})"),
                             dir, "s.json");
    };
    const Lighting expected = default_lighting();
    const Session plain = parse("");
    ASSERT_EQ(plain.lighting.lights.size(), 1u);
    EXPECT_EQ(plain.lighting.lights[0].vector, expected.lights[0].vector);
    EXPECT_EQ(plain.lighting.ambient, expected.ambient);
    EXPECT_TRUE(plain.lighting.shadows);
    EXPECT_TRUE(parse(R"("lights": [], )").lighting.lights.empty());
    const Session ambient_only = parse(R"("ambient": [0, 0, 0], )");
    EXPECT_EQ(ambient_only.lighting.lights.size(), 1u);
    EXPECT_EQ(ambient_only.lighting.ambient, (Rgb{0, 0, 0}));

    // The frame shows the object: brighter than the background somewhere.
    run_session(plain, dir / "out");
    const Image image = read_png(dir / "out" / "a.png");
    const auto brightness = [&](int x, int y) { return image.pixel(x, y)[0] + image.pixel(x, y)[1] + image.pixel(x, y)[2]; };
    int brightest = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) brightest = std::max(brightest, brightness(x, y));
    EXPECT_GT(brightest, brightness(0, 0) + 100);
}

// The scale is the session's, else the one its input volume stores, else the model's default; a save
// step stores the scale the session ran at, so the volume reopens at it.
TEST(Session, ScaleComesFromTheSessionElseTheVolumeElseTheModel) {
    const fs::path dir = testing::scratch_dir("scale");
    const TetMesh cube = testing::make_cube_mesh(3);
    write_volume(cube, dir / "stored.vtu", VolumeMetadata{12.0});
    write_volume(cube, dir / "plain.vtu");
    const auto run = [&](const std::string& input, const std::string& scale, const std::string& out) {
        const Session session = parse_session(Json::parse(R"({"input": {"volume": ")" + input + R"("}, )" + scale +
                                                          R"("image": {"width": 32, "height": 24},
                                                              "steps": [{"save": "saved.vtu"}]})"),
                                              dir, "s.json");
        EXPECT_EQ(session_to_json(session).contains("scale"), !scale.empty());
        return run_session(session, dir / out).scale;
    };
    const ModelScale stored = run("stored.vtu", "", "stored");
    EXPECT_EQ(stored.mm_per_unit, 12.0);
    EXPECT_EQ(stored.source, ScaleSource::Stored);
    const ModelScale given = run("stored.vtu", R"("scale": 7, )", "given");
    EXPECT_EQ(given.mm_per_unit, 7.0);
    EXPECT_EQ(given.source, ScaleSource::Given);
    const ModelScale model = run("plain.vtu", "", "model");
    EXPECT_EQ(model.mm_per_unit, default_mm_per_unit(bounding_extent(cube.positions).norm()));
    EXPECT_EQ(model.source, ScaleSource::ModelSize);
    for (const auto& [out, expected] : std::vector<std::pair<std::string, double>>{
             {"stored", 12.0}, {"given", 7.0}, {"model", model.mm_per_unit}}) {
        EXPECT_EQ(read_volume_file(dir / out / "saved.vtu").metadata.mm_per_unit, expected) << out;
        const Json metrics = Json::parse(testing::read_text(dir / out / "metrics.json"));
        EXPECT_EQ(metrics["mm_per_unit"], expected) << out;
    }
    EXPECT_EQ(Json::parse(testing::read_text(dir / "stored" / "metrics.json"))["scale_source"], "stored");
}

// Outputs in sub-folders of the output directory get their folders.
TEST(Session, OutputsInSubfoldersCreateThem) {
    const fs::path dir = testing::scratch_dir("subfolders");
    write_volume(testing::make_cube_mesh(3), dir / "cube.vtu");
    const Session session = parse_session(
        Json::parse(R"({"input": {"volume": "cube.vtu"}, "image": {"width": 32, "height": 24},
                        "steps": [{"render": "frames/a.png"}, {"save": "volumes/deep/b.vtu"}]})"),
        dir, "s.json");
    run_session(session, dir / "out");
    EXPECT_TRUE(fs::exists(dir / "out" / "frames" / "a.png"));
    EXPECT_EQ(read_volume(dir / "out" / "volumes" / "deep" / "b.vtu").tet_count(), testing::make_cube_mesh(3).tet_count());
}

TEST(Session, RunErrorsNameTheStep) {
    const fs::path dir = testing::scratch_dir("run_errors");
    write_volume(testing::make_cube_mesh(3), dir / "cube.vtu");
    std::ofstream(dir / "s.json") << R"({"input": {"volume": "cube.vtu"}, "steps": [{"save": "a.vtu"}, {"undo": 1}]})";
    try {
        run_session(read_session(dir / "s.json"), dir / "out");
        FAIL() << "no error";
    } catch (const InvalidArgumentError& e) {
        EXPECT_NE(std::string(e.what()).find("s.json: step 1 (undo): nothing left to undo"), std::string::npos)
            << e.what();
    }
}

TEST(Session, RecordedHistoryReplaysToTheSameVolumeBitForBit) {
    const fs::path dir = testing::scratch_dir("record");
    write_volume(testing::make_cube_mesh(6), dir / "cube.vtu");
    Session setup;
    setup.name = "setup";
    setup.input.volume = dir / "cube.vtu";
    setup.material = material_preset("marble");
    setup.scale = 10;

    Document doc(read_volume(setup.input.volume), setup.material);
    PaintOp paint;
    paint.points = {Eigen::Vector3d(0.3, 0.4, 0.5), Eigen::Vector3d(0.35, 0.45, 0.5)};
    paint.material = material_preset("ketchup");
    paint.sigma = 0.1;
    PlaneCutOp cut;
    cut.plane = {Eigen::Vector3d(1, 0.1, -0.2), 0.6};
    doc.apply(paint);
    DeformOp pull;  // positions move: the replay must reproduce them bit for bit too
    pull.grab = Eigen::Vector3d(1, 0.5, 0.5);
    pull.radius = 0.4;
    pull.motion = HandleMotion::translation(Eigen::Vector3d(0.1, 0.05, 0));
    pull.pins = {PinSphere{Eigen::Vector3d(0, 0.5, 0.5), 0.3}};
    pull.steps = 2;
    doc.apply(pull);
    doc.apply(cut);
    doc.apply(SetMaterialOp{material_preset("skin1"), 0});
    doc.undo();  // not part of the record
    StrokeCutOp stroke;
    // Seen from the eye, the stroke's surface crosses the cube near x = 0.3.
    stroke.stroke = {Eigen::Vector3d(0.5, 0.5, 5), Eigen::Vector3d(0, 0, -1),
                     {Eigen::Vector3d(0.45, -1, 4), Eigen::Vector3d(0.47, 2, 4)}, true};
    const size_t tets_before_stroke = doc.mesh().tet_count();
    doc.apply(stroke);
    EXPECT_GT(doc.mesh().tet_count(), 0u);
    EXPECT_LT(doc.mesh().tet_count(), tets_before_stroke);
    paint.points = {Eigen::Vector3d(0.5, 0.5, 0.5)};
    doc.apply(paint);

    write_session(dir / "recorded.json", record_session(setup, doc, {SaveStep{"replayed.vtu"}}));
    const Session replay = read_session(dir / "recorded.json");
    EXPECT_EQ(replay.steps.size(), 6u);
    const SessionResult result = run_session(replay, dir / "out");
    EXPECT_TRUE(result.mesh == doc.mesh());
    EXPECT_TRUE(read_volume(dir / "out" / "replayed.vtu") == doc.mesh());
    // Metrics: one entry per step with the sizes after it.
    std::ifstream metrics_file(dir / "out" / "metrics.json");
    const Json metrics = Json::parse(metrics_file);
    ASSERT_EQ(metrics.at("steps").size(), replay.steps.size());
    EXPECT_EQ(metrics.at("steps").back().at("tets").get<size_t>(), doc.mesh().tet_count());
    EXPECT_EQ(metrics.at("steps").front().at("name"), "paint");
}

TEST(Session, UndoAndRedoStepsReplay) {
    const fs::path dir = testing::scratch_dir("undo");
    const TetMesh cube = testing::make_cube_mesh(4);
    write_volume(cube, dir / "cube.vtu");
    std::ofstream(dir / "s.json") << R"({"input": {"volume": "cube.vtu"}, "scale": 10, "steps": [
        {"op": "plane_cut", "normal": [1, 0, 0], "offset": 0.5},
        {"op": "paint", "points": [[0.2, 0.2, 0.2]], "material": "ketchup", "sigma": 0.1},
        {"undo": 2}, {"save": "start.vtu"}, {"redo": 1}, {"save": "cut.vtu"}]})";
    const SessionResult result = run_session(read_session(dir / "s.json"), dir / "out");
    Document expected(cube, material_preset("marble"));
    EXPECT_TRUE(read_volume(dir / "out" / "start.vtu") == expected.mesh());
    PlaneCutOp cut;
    cut.plane = {Eigen::Vector3d(1, 0, 0), 0.5};
    expected.apply(cut);
    EXPECT_TRUE(result.mesh == expected.mesh());
}

}  // namespace
}  // namespace waxwork
