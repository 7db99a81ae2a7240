// The small lit scene the live-scene and live-solver tests share: a key light from the upper right
// and a paint dab at one point.
#pragma once

#include "scene/edit_operation.h"
#include "solver/lighting.h"
#include "solver/material.h"

#include <Eigen/Core>

namespace waxwork::testing {

inline Lighting key_lighting() {
    Lighting l;
    Light light;
    light.vector = Eigen::Vector3d(1, -0.8, -0.5).normalized();
    l.lights = {light};
    l.ambient = {0.02, 0.02, 0.02};
    return l;
}

// A one-point paint stroke of `material`, sigma 0.08 model units.
inline PaintOp paint_at(const Eigen::Vector3d& p, const char* material = "ketchup") {
    PaintOp op;
    op.points = {p};
    op.material = material_preset(material);
    op.sigma = 0.08;
    return op;
}

}  // namespace waxwork::testing
