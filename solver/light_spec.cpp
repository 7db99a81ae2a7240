#include "solver/light_spec.h"

#include "base/error.h"
#include "base/number_list.h"

#include <cmath>
#include <optional>
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
    if (colon == std::string_view::npos)
        fail("expected dir:X,Y,Z, point:X,Y,Z, rect:CX,CY,CZ:NX,NY,NZ:W,H, disk:CX,CY,CZ:NX,NY,NZ:RADIUS or "
             "sphere:CX,CY,CZ:RADIUS, each with an optional :R,G,B");
    const std::string_view kind = spec.substr(0, colon);
    Light light;
    if (kind == "dir") {
        light.type = LightType::Directional;
    } else if (kind == "point") {
        light.type = LightType::Point;
    } else if (kind == "rect") {
        light.type = LightType::Rectangle;
    } else if (kind == "disk") {
        light.type = LightType::Disk;
    } else if (kind == "sphere") {
        light.type = LightType::Sphere;
    } else {
        fail("unknown kind '" + std::string(kind) + "' (dir, point, rect, disk or sphere)");
    }
    // The text after the fields read so far; none once no colon follows the last one.
    std::optional<std::string_view> remaining = spec.substr(colon + 1);
    // The next colon-separated field as `count` numbers ("expected " + what otherwise).
    const auto next_numbers = [&](size_t count, const std::string& what) {
        if (!remaining) fail("expected " + what);
        const size_t end = remaining->find(':');
        std::vector<double> v;
        if (!parse_number_list(remaining->substr(0, end), v) || v.size() != count) fail("expected " + what);
        remaining = end == std::string_view::npos ? std::nullopt : std::optional(remaining->substr(end + 1));
        return v;
    };
    const bool area = is_area_light(light.type);
    const std::vector<double> v = next_numbers(3, area ? "a center CX,CY,CZ" : "three numbers X,Y,Z");
    light.vector = Eigen::Vector3d(v[0], v[1], v[2]);
    if (!light.vector.allFinite()) fail("non-finite coordinate");
    if (light.type == LightType::Directional && light.vector.norm() == 0) fail("zero direction");
    if (light.type == LightType::Rectangle || light.type == LightType::Disk) {
        const std::vector<double> n = next_numbers(3, "a normal NX,NY,NZ");
        light.axis = Eigen::Vector3d(n[0], n[1], n[2]);
        if (!light.axis.allFinite()) fail("non-finite normal");
        if (light.axis.cwiseAbs().maxCoeff() == 0) fail("zero normal");
        light.axis = light.axis.stableNormalized();
        light.tangent = default_rect_tangent(light.axis);
    }
    if (light.type == LightType::Rectangle) {
        const std::vector<double> size = next_numbers(2, "a size W,H");
        light.size = Eigen::Vector2d(size[0], size[1]);
        if (!(light.size.allFinite() && light.size.minCoeff() > 0)) fail("width and height must be finite and positive");
    } else if (area) {
        const double radius = next_numbers(1, "a radius")[0];
        if (!(std::isfinite(radius) && radius > 0)) fail("radius must be finite and positive");
        light.size = Eigen::Vector2d(radius, radius);
    }
    if (remaining) {
        std::vector<double> c;
        if (!parse_number_list(*remaining, c) || c.size() != 3) fail("expected an intensity R,G,B");
        for (int k = 0; k < 3; ++k) {
            if (!std::isfinite(c[k]) || c[k] < 0) fail("intensity must be finite and non-negative");
            light.intensity[k] = c[k];
        }
    }
    return light;
}

}  // namespace waxwork
