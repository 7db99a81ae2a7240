// The scene the live-editor benchmarks run (live_scene_bench.cpp, live_solver_bench.cpp,
// environment_bench.cpp, deform_bench.cpp): spot scaled to 100 mm (as in docs/performance.md),
// tolerance 1e-3, and a key light that turns around the vertical axis; the sizes their frames and
// edits are measured at.
#pragma once

#include "scene/edit_operation.h"
#include "scene/live_scene.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "tetops/tet_mesh.h"

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <numbers>

namespace waxwork::bench {

// The frame goals are at about 100K tets, the edit goals at about 500K.
inline constexpr size_t kFrameTets = 100'000;
inline constexpr size_t kEditTets = 500'000;
// CG iterations per channel and frame: what fits a 30 fps frame at 100K tets with the lighting update.
inline constexpr int kFrameIterations = 8;

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

// A slanted plane cut (normal (1, 0.3, 0.2)) through the middle of the bounding box, with 10
// relaxation sweeps of the cut vertices.
inline PlaneCutOp middle_cut(const TetMesh& mesh) {
    const auto box = bounding_box(mesh);
    PlaneCutOp op;
    op.plane.normal = Eigen::Vector3d(1.0, 0.3, 0.2).normalized();
    op.plane.offset = op.plane.normal.dot(0.5 * (box[0] + box[1]));
    op.relax.iterations = 10;
    return op;
}

// Frame f of `frames` of a paint stroke along spot's body near the top of its back: one ketchup dab
// per frame, sigma 1% of the diagonal of the bounding box `box`.
inline PaintOp body_stroke_dab(const std::array<Eigen::Vector3d, 2>& box, int f, int frames) {
    const Eigen::Vector3d centre = 0.5 * (box[0] + box[1]);
    const double diagonal = (box[1] - box[0]).norm();
    PaintOp op;
    op.points = {centre + Eigen::Vector3d(0, 0.25 * diagonal * 0.3, (f / double(frames) - 0.5) * 0.5 * diagonal)};
    op.material = material_preset("ketchup");
    op.sigma = 0.01 * diagonal;
    return op;
}

}  // namespace waxwork::bench
