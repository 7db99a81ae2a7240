// The lights a scene gets when it names none, and lights written as text ("dir:1,-1,-1").
#pragma once

#include "solver/lighting.h"

#include <string_view>

namespace waxwork {

// The light `waxwork render` uses when none is given: a white key light from the upper front-left of
// a y-up model facing +z (travelling along (1, -1, -1)), so the default 3/4 camera (front right) sees
// lit faces next to faces in shade, and translucency shows in the gradient between them.
Light default_key_light();
// The ambient irradiance per channel where none is given (`render --ambient`, the editor, sessions).
inline constexpr double kDefaultAmbient = 0.02;
// The lighting of a scene that names none: default_key_light, kDefaultAmbient, shadows.
Lighting default_lighting();

// Parses "dir:X,Y,Z[:R,G,B]" (direction of travel), "point:X,Y,Z[:R,G,B]" (position in model units)
// or an area light (lighting.h): "rect:CX,CY,CZ:NX,NY,NZ:W,H[:R,G,B]" (centre, emitting normal, width
// and height; the width runs along default_rect_tangent: world +x projected onto the rectangle, or +z
// for a normal near the x axis), "disk:CX,CY,CZ:NX,NY,NZ:RADIUS[:R,G,B]" or
// "sphere:CX,CY,CZ:RADIUS[:R,G,B]". The intensity defaults to 1,1,1 (for area lights, the radiant
// intensity along the normal). Throws InvalidArgumentError("bad light spec 'SPEC': WHY") for
// anything else: unknown kind, wrong component count, trailing text, non-finite numbers, a zero
// direction or normal, a size that is not positive, or a negative intensity.
Light parse_light_spec(std::string_view spec);

}  // namespace waxwork
