#include "render/image_background.h"

#include "base/error.h"
#include "render/surface_renderer.h"

#include <algorithm>
#include <cctype>
#include <charconv>

namespace waxwork {

namespace {

[[noreturn]] void refuse(const std::string& text) {
    throw InvalidArgumentError("background '" + text +
                               "': expected R,G,B (0-255), #RRGGBB, transparent or environment");
}

// A whole decimal or hexadecimal number within [0, max], or refuse.
int parse_number(const std::string& whole, std::string_view digits, int base, int max) {
    int value = -1;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value, base);
    if (digits.empty() || error != std::errc() || end != digits.data() + digits.size() || value < 0 || value > max)
        refuse(whole);
    return value;
}

}  // namespace

ImageBackground parse_background(const std::string& text) {
    std::string lower = text;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    ImageBackground background;
    if (lower.empty()) return background;
    if (lower == "transparent") {
        background.kind = BackgroundKind::Transparent;
        return background;
    }
    if (lower == "environment" || lower == "env") {
        background.kind = BackgroundKind::Environment;
        return background;
    }
    background.kind = BackgroundKind::Colour;
    if (lower.find(',') != std::string::npos) {
        std::string_view rest = lower;
        for (int c = 0; c < 3; ++c) {
            const size_t comma = rest.find(',');
            if ((c < 2) != (comma != std::string_view::npos)) refuse(text);
            background.colour[c] = static_cast<uint8_t>(parse_number(text, rest.substr(0, comma), 10, 255));
            rest = c < 2 ? rest.substr(comma + 1) : std::string_view();
        }
        return background;
    }
    std::string_view hex = lower;
    if (!hex.empty() && hex.front() == '#') hex.remove_prefix(1);
    if (hex.size() != 6) refuse(text);
    for (int c = 0; c < 3; ++c) background.colour[c] = static_cast<uint8_t>(parse_number(text, hex.substr(2 * c, 2), 16, 255));
    return background;
}

void apply_background(const ImageBackground& background, SurfaceRenderInput& input) {
    auto& environment = input.lighting.environment;
    switch (background.kind) {
    case BackgroundKind::Automatic:
        return;
    case BackgroundKind::Environment:
        if (!environment) throw InvalidArgumentError("the environment background needs an environment light (--env)");
        environment->background = true;
        return;
    case BackgroundKind::Colour:
    case BackgroundKind::Transparent:
        if (environment) environment->background = false;
        input.background = background.colour;
        input.transparent_background = background.kind == BackgroundKind::Transparent;
        return;
    }
}

}  // namespace waxwork
