// What a picture shows behind the model: the views' grey, a colour, nothing (transparent, for
// compositing), or the environment that lights it. `waxwork render`, `waxwork turntable` and sessions
// read it from the same words.
#pragma once

#include "render/srgb.h"

#include <array>
#include <cstdint>
#include <string>

namespace waxwork {

struct SurfaceRenderInput;

enum class BackgroundKind {
    Automatic,    // the environment when one lights the scene and is set to be drawn, else kViewBackground
    Colour,       // `colour`, also in front of an environment
    Transparent,  // alpha 0 where the model is not: its coverage as alpha
    Environment,  // the environment map (there must be one)
};

struct ImageBackground {
    BackgroundKind kind = BackgroundKind::Automatic;
    std::array<uint8_t, 3> colour = kViewBackground;  // 8-bit sRGB
};

// "R,G,B" (integers 0-255), "#RRGGBB" or "RRGGBB" (hex), "transparent", "environment" (or "env"), or
// "" (Automatic). Throws InvalidArgumentError saying what is accepted.
ImageBackground parse_background(const std::string& text);

// Sets the input's background colour, transparency and whether its environment is drawn. Throws
// InvalidArgumentError for Environment when the input has no environment.
void apply_background(const ImageBackground& background, SurfaceRenderInput& input);

}  // namespace waxwork
