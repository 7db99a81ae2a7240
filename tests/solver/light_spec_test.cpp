#include "base/error.h"
#include "solver/light_spec.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace waxwork {
namespace {

std::string spec_error(const std::string& spec) {
    try {
        parse_light_spec(spec);
    } catch (const InvalidArgumentError& e) {
        return e.what();
    }
    return "no error";
}

TEST(LightSpec, AreaLightsParse) {
    const Light rect = parse_light_spec("rect:1,2,3:0,-2,0:4,0.5");
    EXPECT_EQ(rect.type, LightType::Rectangle);
    EXPECT_EQ(rect.vector, Eigen::Vector3d(1, 2, 3));
    EXPECT_TRUE(rect.axis.isApprox(Eigen::Vector3d(0, -1, 0)));
    EXPECT_TRUE(rect.tangent.isApprox(Eigen::Vector3d(1, 0, 0)));  // world +x, in the rectangle's plane
    EXPECT_EQ(rect.size, Eigen::Vector2d(4, 0.5));
    EXPECT_EQ(rect.intensity, (Rgb{1, 1, 1}));

    const Light disk = parse_light_spec("disk:0,0,5:0,0,-1:0.25:2,3,4");
    EXPECT_EQ(disk.type, LightType::Disk);
    EXPECT_TRUE(disk.axis.isApprox(Eigen::Vector3d(0, 0, -1)));
    EXPECT_EQ(disk.size.x(), 0.25);
    EXPECT_EQ(disk.intensity, (Rgb{2, 3, 4}));

    const Light sphere = parse_light_spec("sphere:-1,2.5,0:0.1:5,5,5");
    EXPECT_EQ(sphere.type, LightType::Sphere);
    EXPECT_EQ(sphere.vector, Eigen::Vector3d(-1, 2.5, 0));
    EXPECT_EQ(sphere.size.x(), 0.1);
    EXPECT_EQ(sphere.intensity, (Rgb{5, 5, 5}));

    // Whatever parses, validates.
    for (const char* spec : {"rect:1,2,3:0,-2,0:4,0.5", "rect:0,0,0:1,0,0:1,1", "disk:0,0,5:0,0,-1:0.25", "sphere:0,0,0:1"}) {
        Lighting lighting;
        lighting.lights = {parse_light_spec(spec)};
        EXPECT_NO_THROW(validate(lighting)) << spec;
    }
}

TEST(LightSpec, BadSpecsSayWhatIsWrong) {
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"rect:0,0,0:0,0,1", "expected a size W,H"},
        {"rect:0,0,0:0,0,1:1", "expected a size W,H"},
        {"rect:0,0,0:0,0,1:1,2,3", "expected a size W,H"},
        {"rect:0,0,0", "expected a normal NX,NY,NZ"},
        {"rect:0,0,0:0,0,0:1,1", "zero normal"},
        {"rect:0,0,0:0,nan,1:1,1", "non-finite normal"},
        {"rect:0,0,0:0,0,1:0,1", "width and height must be finite and positive"},
        {"rect:0,0,0:0,0,1:inf,1", "width and height must be finite and positive"},
        {"disk:0,0,0:0,0,1", "expected a radius"},
        {"disk:0,0,0:0,0,1:-1", "radius must be finite and positive"},
        {"disk:0,0:0,0,1:1", "expected a center CX,CY,CZ"},
        {"sphere:0,0,0", "expected a radius"},
        {"sphere:0,0,0:0", "radius must be finite and positive"},
        {"sphere:0,0,0:1,2", "expected a radius"},
        {"sphere:0,0,nan:1", "non-finite coordinate"},
        {"sphere:0,0,0:1:1,1", "expected an intensity R,G,B"},
        {"sphere:0,0,0:1:1,1,1:2", "expected an intensity R,G,B"},
        {"sphere:0,0,0:1:1,-1,1", "intensity must be finite and non-negative"},
        {"disk:0,0,0:0,0,1:1:", "expected an intensity R,G,B"},
        {"square:0,0,0:1", "unknown kind 'square' (dir, point, rect, disk or sphere)"},
        {"sphere", "expected dir:X,Y,Z, point:X,Y,Z, rect:"},
        // The forms that were there before keep their messages.
        {"dir:0,0,0", "zero direction"},
        {"point:1,2", "expected three numbers X,Y,Z"},
        {"dir:1,0,0:1,1", "expected an intensity R,G,B"},
    };
    for (const auto& [spec, why] : cases) {
        const std::string e = spec_error(spec);
        EXPECT_EQ(e.rfind("bad light spec '" + spec + "': " + why, 0), 0u) << e;  // begins with it
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
}

}  // namespace
}  // namespace waxwork
