#include "base/error.h"
#include "io/image_io.h"
#include "io/volume_file.h"
#include "scene/session.h"
#include "tetops/test_meshes.h"

#include "support/cli_run.h"
#include "support/hdr_file.h"
#include "support/scratch_dir.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>

namespace waxwork {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// A cube volume and a small studio .hdr (bright along +x, dim elsewhere) in `dir`.
void write_inputs(const fs::path& dir) {
    write_volume(testing::make_cube_mesh(3), dir / "cube.vtu");
    testing::write_bytes(dir / "studio.hdr", testing::hdr_file_bytes(32, 16, [](int x, int) {
                             return x >= 22 && x < 26 ? std::array<double, 3>{20, 18, 15} : std::array<double, 3>{0.2, 0.2, 0.25};
                         }));
}

std::string parse_error(const std::string& text, const fs::path& dir) {
    try {
        parse_session(Json::parse(text), dir, "s.json");
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

TEST(SessionEnvironment, SkyAndFileEnvironmentsRoundTrip) {
    const fs::path dir = testing::scratch_dir("session_environment_round_trip");
    write_inputs(dir);
    const Session sky = parse_session(Json::parse(R"({"input": {"volume": "cube.vtu"},
        "environment": {"sky": {"sun_elevation": 30, "sun_azimuth": 45, "turbidity": 4}, "rotation": 10,
                        "intensity": 2, "background": false}, "steps": []})"),
                                      dir, "s.json");
    ASSERT_TRUE(sky.lighting.environment);
    ASSERT_TRUE(sky.lighting.environment->sky);
    EXPECT_EQ(sky.lighting.environment->sky->turbidity, 4);
    EXPECT_EQ(sky.lighting.environment->rotation_degrees, 10);
    EXPECT_EQ(sky.lighting.environment->intensity, 2);
    EXPECT_FALSE(sky.lighting.environment->background);
    EXPECT_TRUE(sky.lighting.lights.empty()) << "an environment replaces the default key light";
    EXPECT_EQ(sky.lighting.ambient, (Rgb{0, 0, 0}));
    const Session again = parse_session(session_to_json(sky), dir, "again");
    EXPECT_EQ(session_to_json(again).dump(), session_to_json(sky).dump());

    // A file environment is read relative to the session and written relative to where the session goes.
    const Session file = parse_session(Json::parse(R"({"input": {"volume": "cube.vtu"},
        "environment": {"file": "studio.hdr", "rotation": 90}, "steps": [{"light": {"environment": null}}]})"),
                                       dir, "s.json");
    ASSERT_TRUE(file.lighting.environment);
    EXPECT_EQ(file.lighting.environment->map->width(), 32);
    fs::create_directories(dir / "saved");
    write_session(dir / "saved" / "s.json", file);
    const Json written = Json::parse(testing::read_text(dir / "saved" / "s.json"));
    EXPECT_EQ(written["environment"]["file"], "../studio.hdr");
    EXPECT_TRUE(written["steps"][0]["light"]["environment"].is_null());
    const Session reread = read_session(dir / "saved" / "s.json");
    EXPECT_EQ(reread.lighting.environment->map->width(), 32);
}

TEST(SessionEnvironment, BadEnvironmentsNameTheFieldAndTheFile) {
    const fs::path dir = testing::scratch_dir("session_environment_errors");
    write_inputs(dir);
    testing::write_bytes(dir / "cut.hdr", testing::hdr_file_bytes(8, 4, [](int, int) { return std::array<double, 3>{1, 1, 1}; }).substr(0, 60));
    const std::string head = R"({"input": {"volume": "cube.vtu"}, "environment": )";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {R"({"file": "missing.hdr"})", "field 'environment': field 'file': " + (dir / "missing.hdr").string() + ": no such file"},
        {R"({"file": "cut.hdr"})", "cut.hdr: truncated"},
        {R"({"file": "cube.vtu"})", "cube.vtu: not a Radiance .hdr image"},
        {R"({"file": "studio.hdr", "sky": {"sun_elevation": 30, "sun_azimuth": 0}})", "give exactly one of 'file'"},
        {R"({"sky": {"sun_elevation": -3, "sun_azimuth": 0}})", "sun elevation must be above 0"},
        {R"({"sky": {"sun_elevation": 30}})", "missing field 'sun_azimuth'"},
        {R"({"file": "studio.hdr", "intensity": -1})", "field 'intensity': must be non-negative"},
        {R"({"file": "studio.hdr", "rotation": "x"})", "field 'rotation': expected a finite number"},
        {R"({"file": "studio.hdr", "spin": 3})", "unknown field 'spin'"},
    };
    for (const auto& [environment, expected] : cases) {
        const std::string e = parse_error(head + environment + R"(, "steps": []})", dir);
        EXPECT_NE(e.find("s.json: field 'environment'"), std::string::npos) << e;
        EXPECT_NE(e.find(expected), std::string::npos) << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
}

TEST(SessionEnvironment, LightStepsSwitchTheEnvironmentAndTheImageFollows) {
    const fs::path dir = testing::scratch_dir("session_environment_run");
    write_inputs(dir);
    const Session session = parse_session(Json::parse(R"({"input": {"volume": "cube.vtu"},
        "image": {"width": 48, "height": 36}, "environment": {"file": "studio.hdr"}, "lights": [], "ambient": [0, 0, 0],
        "steps": [{"render": "a.png"}, {"light": {"environment": {"file": "studio.hdr", "rotation": 180}}},
                  {"render": "b.png"}, {"light": {"environment": null}}, {"render": "dark.png"}]})"),
                                          dir, "s.json");
    run_session(session, dir / "out");
    const Image a = read_png(dir / "out" / "a.png"), b = read_png(dir / "out" / "b.png");
    const Image dark = read_png(dir / "out" / "dark.png");
    EXPECT_NE(a.rgba, b.rgba) << "turning the environment changes the image";
    // Without the environment nothing lights the object: the image darkens.
    const auto total = [](const Image& image) {
        double sum = 0;
        for (size_t i = 0; i < image.rgba.size(); i += 4) sum += image.rgba[i] + image.rgba[i + 1] + image.rgba[i + 2];
        return sum;
    };
    EXPECT_LT(total(dark), 0.9 * total(a));
}

}  // namespace
}  // namespace waxwork
