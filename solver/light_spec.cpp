#include "solver/light_spec.h"

#include "base/error.h"
#include "base/number_list.h"

#include <cmath>
#include <string>
#include <vector>

namespace waxwork {

Light default_key_light() {
    Light light;
    light.type = LightType::Directional;
    light.vector = Eigen::Vector3d(1, -1, -1).normalized();
    light.intensity = {1, 1, 1};
    return light;
}

Lighting default_lighting() {
    Lighting lighting;
    lighting.lights = {default_key_light()};
    lighting.ambient = {kDefaultAmbient, kDefaultAmbient, kDefaultAmbient};
    lighting.shadows = true;
    return lighting;
}

Light parse_light_spec(std::string_view spec) {
    const auto fail = [&](const std::string& why) {
        throw InvalidArgumentError("bad light spec '" + std::string(spec) + "': " + why);
    };
    const size_t colon = spec.find(':');
    if (colon == std::string_view::npos) fail("expected dir:X,Y,Z[:R,G,B] or point:X,Y,Z[:R,G,B]");
    const std::string_view kind = spec.substr(0, colon);
    Light light;
    if (kind == "dir") {
        light.type = LightType::Directional;
    } else if (kind == "point") {
        light.type = LightType::Point;
    } else {
        fail("unknown kind '" + std::string(kind) + "' (dir or point)");
    }
    std::string_view rest = spec.substr(colon + 1);
    const size_t second = rest.find(':');
    const std::string_view vector_text = rest.substr(0, second);
    std::vector<double> v;
    if (!parse_number_list(vector_text, v) || v.size() != 3) fail("expected three numbers X,Y,Z");
    light.vector = Eigen::Vector3d(v[0], v[1], v[2]);
    if (!light.vector.allFinite()) fail("non-finite coordinate");
    if (light.type == LightType::Directional && light.vector.norm() == 0) fail("zero direction");
    if (second != std::string_view::npos) {
        std::vector<double> c;
        if (!parse_number_list(rest.substr(second + 1), c) || c.size() != 3) fail("expected an intensity R,G,B");
        for (int k = 0; k < 3; ++k) {
            if (!std::isfinite(c[k]) || c[k] < 0) fail("intensity must be finite and non-negative");
            light.intensity[k] = c[k];
        }
    }
    return light;
}

}  // namespace waxwork
