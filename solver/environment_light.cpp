#include "solver/environment_light.h"

#include "base/error.h"
#include "base/number_list.h"
#include "solver/lighting.h"
#include "solver/spherical_harmonics.h"

#include <cmath>
#include <numbers>

namespace waxwork {

EnvironmentLight environment_light(std::shared_ptr<const EnvironmentMap> map, int sh_order) {
    if (!map) throw InvalidArgumentError("environment light: no map");
    EnvironmentLight environment;
    environment.sh = std::make_shared<const std::vector<Rgb>>(map->project_to_sh(sh_order));
    environment.sh_order = sh_order;
    environment.map = std::move(map);
    return environment;
}

EnvironmentLight sky_environment_light(const SkySettings& sky, int sh_order) {
    EnvironmentLight environment = environment_light(std::make_shared<const EnvironmentMap>(make_sky_map(sky)), sh_order);
    environment.sky = sky;
    return environment;
}

void validate(const EnvironmentLight& environment) {
    if (!environment.map || !environment.sh)
        throw InvalidArgumentError("environment light: no map loaded");
    if (environment.sh->size() != static_cast<size_t>(sh_coefficient_count(environment.sh_order)))
        throw InvalidArgumentError("environment light: projection does not match its order");
    if (!std::isfinite(environment.rotation_degrees))
        throw InvalidArgumentError("environment light: rotation must be finite");
    if (!(environment.intensity >= 0 && environment.intensity <= kMaxLightIntensity))
        throw InvalidArgumentError("environment light: intensity must be non-negative and at most 1e15");
    if (environment.sky) validate(*environment.sky);
}

std::vector<Rgb> environment_sh(const EnvironmentLight& environment) {
    std::vector<Rgb> rotated = rotate_sh_about_up(*environment.sh, environment.sh_order,
                                                  environment.rotation_degrees * std::numbers::pi / 180);
    for (Rgb& coefficient : rotated)
        for (double& c : coefficient) c *= environment.intensity;
    return rotated;
}

Rgb environment_radiance(const EnvironmentLight& environment, const Eigen::Vector3d& w) {
    const Eigen::Vector3d unrotated =
        Eigen::AngleAxisd(-environment.rotation_degrees * std::numbers::pi / 180, Eigen::Vector3d::UnitY()) * w;
    Rgb radiance = environment.map->radiance(unrotated);
    for (double& c : radiance) c *= environment.intensity;
    return radiance;
}

EnvironmentSpec parse_environment_spec(std::string_view spec) {
    const auto fail = [&](const std::string& why) {
        throw InvalidArgumentError("bad environment spec '" + std::string(spec) + "': " + why);
    };
    std::vector<std::string_view> parts;
    for (size_t start = 0;;) {
        const size_t colon = spec.find(':', start);
        parts.push_back(spec.substr(start, colon == std::string_view::npos ? std::string_view::npos : colon - start));
        if (colon == std::string_view::npos) break;
        start = colon + 1;
    }
    EnvironmentSpec result;
    size_t next = 1;
    if (parts[0] == "sky") {
        if (parts.size() < 2) fail("expected sky:SUN_ELEV_DEG,SUN_AZIM_DEG[,TURBIDITY]");
        std::vector<double> values;
        if (!parse_number_list(parts[1], values) || values.size() < 2 || values.size() > 3)
            fail("expected sky:SUN_ELEV_DEG,SUN_AZIM_DEG[,TURBIDITY]");
        SkySettings sky;
        sky.sun_elevation_degrees = values[0];
        sky.sun_azimuth_degrees = values[1];
        if (values.size() == 3) sky.turbidity = values[2];
        try {
            validate(sky);
        } catch (const InvalidArgumentError& e) {
            fail(e.what());
        }
        result.sky = sky;
        next = 2;
    } else {
        if (parts[0].empty()) fail("expected FILE.hdr[:ROT_DEG[:INTENSITY]] or sky:SUN_ELEV_DEG,SUN_AZIM_DEG");
        result.file = std::string(parts[0]);
    }
    if (parts.size() > next + 2) fail("too many ':' fields");
    std::vector<double> value;
    if (parts.size() > next) {
        if (!parse_number_list(parts[next], value) || value.size() != 1 || !std::isfinite(value[0]))
            fail("the rotation must be one finite number of degrees");
        result.rotation_degrees = value[0];
    }
    if (parts.size() > next + 1) {
        if (!parse_number_list(parts[next + 1], value) || value.size() != 1 ||
            !(value[0] >= 0 && value[0] <= kMaxLightIntensity))
            fail("the intensity must be a number between 0 and 1e15");
        result.intensity = value[0];
    }
    return result;
}

}  // namespace waxwork
