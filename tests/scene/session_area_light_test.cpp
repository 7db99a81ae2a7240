#include "base/error.h"
#include "scene/session.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace waxwork {
namespace {

using Json = nlohmann::ordered_json;

Session parse(const std::string& lights) {
    return parse_session(Json::parse(R"({"input": {"volume": "cube.vtu"}, "lights": )" + lights + R"(, "steps": []})"), "",
                         "s.json");
}

std::string parse_error(const std::string& lights) {
    try {
        parse(lights);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

TEST(SessionAreaLights, AreaLightsReadAndRoundTrip) {
    const Session session = parse(R"([
        {"rect": {"center": [0, 2, 0], "normal": [0, -2, 0], "tangent": [0, 0, 1], "size": [1.5, 0.5]}, "intensity": [2, 2, 2]},
        {"rect": {"center": [0, 2, 0], "normal": [0, -1, 0], "size": [1, 1]}},
        {"disk": {"center": [1, 2, 3], "normal": [0, 0, -1], "radius": 0.25}},
        {"sphere": {"center": [-1, 0, 4], "radius": 0.1}, "intensity": [1, 0.5, 0.25]},
        {"direction": [1, -1, -1]}, {"position": [0, 3, 0]}])");
    const std::vector<Light>& lights = session.lighting.lights;
    ASSERT_EQ(lights.size(), 6u);
    EXPECT_EQ(lights[0].type, LightType::Rectangle);
    EXPECT_EQ(lights[0].vector, Eigen::Vector3d(0, 2, 0));
    EXPECT_EQ(lights[0].axis, Eigen::Vector3d(0, -2, 0));
    EXPECT_EQ(lights[0].tangent, Eigen::Vector3d(0, 0, 1));
    EXPECT_EQ(lights[0].size, Eigen::Vector2d(1.5, 0.5));
    EXPECT_EQ(lights[0].intensity, (Rgb{2, 2, 2}));
    EXPECT_EQ(lights[1].tangent, default_rect_tangent(lights[1].axis));  // none given
    EXPECT_EQ(lights[2].type, LightType::Disk);
    EXPECT_EQ(lights[2].axis, Eigen::Vector3d(0, 0, -1));
    EXPECT_EQ(lights[2].size.x(), 0.25);
    EXPECT_EQ(lights[3].type, LightType::Sphere);
    EXPECT_EQ(lights[3].vector, Eigen::Vector3d(-1, 0, 4));
    EXPECT_EQ(lights[3].size.x(), 0.1);
    EXPECT_EQ(lights[3].intensity, (Rgb{1, 0.5, 0.25}));
    EXPECT_EQ(lights[4].type, LightType::Directional);
    EXPECT_EQ(lights[5].type, LightType::Point);

    const Json json = session_to_json(session);
    const Json& written = json["lights"];
    EXPECT_EQ(written[1]["rect"]["tangent"], Json::array({1.0, 0.0, 0.0}));  // the default, written out
    EXPECT_FALSE(written[3]["sphere"].contains("normal"));
    EXPECT_EQ(written[4].begin().key(), "direction");  // the directional and point schema as before
    EXPECT_EQ(written[5].begin().key(), "position");
    const Session again = parse_session(json, "", "again");
    EXPECT_EQ(session_to_json(again).dump(), json.dump());
    for (size_t l = 0; l < lights.size(); ++l) {
        EXPECT_EQ(again.lighting.lights[l].type, lights[l].type);
        EXPECT_EQ(again.lighting.lights[l].vector, lights[l].vector);
        EXPECT_EQ(again.lighting.lights[l].size, lights[l].size);
    }
}

TEST(SessionAreaLights, BadAreaLightsNameTheField) {
    const std::vector<std::pair<std::string, std::string>> cases = {
        {R"({"rect": {"center": [0, 2, 0], "normal": [0, 0, 0], "size": [1, 1]}})", "field 'rect': field 'normal': must not be zero"},
        {R"({"rect": {"center": [0, 2, 0], "normal": [0, 1, 0], "tangent": [0, -3, 0], "size": [1, 1]}})",
         "field 'rect': field 'tangent': must not be zero or parallel to the normal"},
        {R"({"rect": {"center": [0, 2, 0], "normal": [0, 1, 0], "size": [1]}})", "field 'rect': field 'size': expected [width, height]"},
        {R"({"rect": {"center": [0, 2, 0], "normal": [0, 1, 0], "size": [1, -1]}})", "field 'size': width and height must be finite and positive"},
        {R"({"rect": {"center": [0, 2, 0], "normal": [0, 1, 0]}})", "field 'rect': missing field 'size'"},
        {R"({"rect": {"center": [0, 2, 0], "normal": [0, 1, 0], "size": [1, 1], "radius": 2}})", "field 'rect': unknown field 'radius'"},
        {R"({"disk": {"center": [0, 2, 0], "normal": [0, 1, 0], "radius": 0}})", "field 'disk': field 'radius': must be positive"},
        {R"({"disk": {"center": [0, 2, 0], "radius": 1}})", "field 'disk': missing field 'normal'"},
        {R"({"disk": {"center": [0, 2], "normal": [0, 1, 0], "radius": 1}})", "field 'disk': field 'center'"},
        {R"({"sphere": {"center": [0, 2, 0], "radius": "big"}})", "field 'sphere': field 'radius': expected a finite number"},
        {R"({"sphere": {"center": [0, 2, 0], "radius": 1, "normal": [0, 1, 0]}})", "field 'sphere': unknown field 'normal'"},
        {R"({"sphere": [0, 2, 0]})", "field 'sphere': expected a JSON object"},
        {R"({"sphere": {"center": [0, 2, 0], "radius": 1}, "position": [0, 1, 0]})", "give exactly one of 'direction'"},
        {R"({"sphere": {"center": [0, 2, 0], "radius": 1}, "intensity": [1, -1, 1]})", "field 'intensity': must be non-negative"},
        {R"({"sphere": {"center": [0, 2, 0], "radius": 1e200}})", "light 0 (sphere): radius must be positive and at most 1e100"},
    };
    for (const auto& [light, expected] : cases) {
        const std::string e = parse_error("[" + light + "]");
        EXPECT_EQ(e.rfind("s.json: ", 0), 0u) << e;  // names the session
        EXPECT_NE(e.find(expected), std::string::npos) << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
}

}  // namespace
}  // namespace waxwork
