// The environment transfer against the sampled integral it approximates (solver/environment_transfer.h):
// per spherical-harmonics order, the time to sample every vertex's transfer, the time to relight
// (rotate the environment and take the dot products), and the error of q_env against the sampled
// reference with multiple importance sampling. `waxwork bench --only environment` charts error
// against order (environment_order.svg) and against sampling time (environment_time.svg).
#pragma once

#include "solver/environment_light.h"
#include "solver/lighting.h"

#include <nlohmann/json.hpp>

#include <span>
#include <string>
#include <vector>

namespace waxwork {

struct TransferAccuracyRow {
    int order = 0;
    double transfer_ms = 0;      // compute_environment_transfer, every surface vertex
    double relight_ms = 0;       // apply_environment_transfer after a turn
    double relative_l2 = 0;      // || q_transfer - q_reference || / || q_reference || over vertices and channels
    double median_relative = 0;  // median over lit vertices of |q_t - q_r| / q_r (channel 1)
};

struct TransferAccuracy {
    std::string environment;
    int reference_samples = 0;
    double reference_ms = 0;
    std::vector<TransferAccuracyRow> rows;
};

// The transfer at each of `orders` (each environment projected to that order) against the sampled
// reference with `reference_samples` directions, on `surface` (its BVH `bvh`), shadows on.
TransferAccuracy study_transfer_accuracy(const BoundarySurface& surface, const TriangleBvh& bvh,
                                         const EnvironmentLight& environment, const std::string& name,
                                         std::span<const int> orders, int reference_samples);

// A studio environment for the study: a dim grey surround with one bright, warm softbox 40 by 25
// degrees up and to the right of the front: the kind of small, intense source a low order blurs.
EnvironmentLight studio_environment(int order);

nlohmann::ordered_json to_json(const TransferAccuracy& study);

}  // namespace waxwork
