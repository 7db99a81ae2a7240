#include "scene/environment_loading.h"

#include "io/image_io.h"

namespace waxwork {

EnvironmentLight load_environment(const EnvironmentSpec& spec, const std::filesystem::path& base) {
    EnvironmentLight environment;
    if (spec.sky) {
        environment = sky_environment_light(*spec.sky);
    } else {
        const std::filesystem::path path =
            std::filesystem::path(spec.file).is_absolute() || base.empty() ? std::filesystem::path(spec.file)
                                                                           : base / spec.file;
        const HdrImage image = read_hdr(path);
        std::vector<Rgb> pixels(static_cast<size_t>(image.width) * image.height);
        for (size_t i = 0; i < pixels.size(); ++i)
            pixels[i] = {image.rgb[3 * i], image.rgb[3 * i + 1], image.rgb[3 * i + 2]};
        environment = environment_light(
            std::make_shared<const EnvironmentMap>(image.width, image.height, std::move(pixels), path.string()));
        environment.file = spec.file;
    }
    environment.rotation_degrees = spec.rotation_degrees;
    environment.intensity = spec.intensity;
    validate(environment);
    return environment;
}

}  // namespace waxwork
