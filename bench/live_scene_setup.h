// The scene both live-editor benchmarks run (live_scene_bench.cpp, live_solver_bench.cpp): spot
// scaled to 100 mm (as in the README's performance table), tolerance 1e-3, and a key light that
// turns around the vertical axis.
#pragma once

#include "editor/live_scene.h"
#include "solver/lighting.h"
#include "tetops/tet_mesh.h"

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

namespace waxwork::bench {

inline LiveSceneOptions live_scene_options(const TetMesh& mesh) {
    const auto box = bounding_box(mesh);
    LiveSceneOptions o;
    o.mm_per_unit = 100.0 / (box[1] - box[0]).maxCoeff();  // spot 100 mm long
    o.relative_tolerance = 1e-3;
    return o;
}

// The key light after turning by `degrees` (direction of travel), with a little ambient light.
inline Lighting turning_light(double degrees) {
    const double a = degrees * std::numbers::pi / 180;
    Lighting l;
    Light light;
    light.vector = Eigen::Vector3d(std::cos(a), -0.8, std::sin(a)).normalized();
    l.lights = {light};
    l.ambient = {0.02, 0.02, 0.02};
    return l;
}

}  // namespace waxwork::bench
