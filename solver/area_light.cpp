#include "solver/area_light.h"

#include "base/error.h"
#include "solver/material.h"
#include "solver/sampling.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace waxwork {

namespace {

constexpr double kPi = std::numbers::pi;

// Hammersley point j of n, rotated by `shift` modulo 1 (area_light.h).
Eigen::Vector2d sample_point(int j, int n, const Eigen::Vector2d& shift) {
    return {fraction((j + 0.5) / n + shift.x()), fraction(radical_inverse(static_cast<uint32_t>(j)) + shift.y())};
}

// The sum over samples of weight * cos(theta_i) F_t V, and the counts visibility comes from.
struct SampleSum {
    const Eigen::Vector3d& normal;
    double eta;
    const Eigen::Vector3f& origin;
    const TriangleBvh* bvh;
    double sum = 0;
    int in_front = 0, reached = 0;

    // Unit direction w from the point, `distance` to the sampled point on the light along it.
    void add(const Eigen::Vector3d& w, double distance, double weight) {
        const double cos_i = normal.dot(w);
        if (!(cos_i > 0)) return;
        ++in_front;
        // The ray stops just short of the light, as for a point light, so a light lying on a surface
        // does not shadow itself.
        if (bvh && bvh->occluded(origin, w.cast<float>(), 0.0f, static_cast<float>(distance * (1.0 - 1e-6)))) return;
        ++reached;
        sum += weight * cos_i * fresnel_transmittance(cos_i, eta);
    }
};

// Uniform in the cone of directions from the point to the sphere (pbrt-v4, Sphere::Sample at a
// reference point): cos(theta) uniform on [cos(theta_max), 1], pdf 1 / (2 pi (1 - cos(theta_max))).
// Returns false when the point is inside or on the sphere.
bool sample_sphere(const Light& light, const Eigen::Vector3d& position, int samples, const Eigen::Vector2d& shift,
                   SampleSum& sum, double& bound) {
    const Eigen::Vector3d to_centre = light.vector - position;
    const double d = to_centre.norm();
    const double ratio = light.size.x() / d;  // sin(theta_max)
    if (!(ratio < 1)) return false;
    const double sin2_max = ratio * ratio;
    const double cos_max = std::sqrt(1 - sin2_max);
    // 1 - cos(theta_max) without the cancellation of a nearly-1 cosine (pbrt-v4 switches to a Taylor
    // expansion below 1.5 degrees for the same reason).
    const double one_minus_cos_max = sin2_max / (1 + cos_max);
    const Eigen::Vector3d axis = to_centre / d;
    Eigen::Vector3d t, b;
    orthonormal_basis(axis, t, b);
    const double weight = 2 / ((1 + cos_max) * d * d * samples);
    for (int j = 0; j < samples; ++j) {
        const Eigen::Vector2d u = sample_point(j, samples, shift);
        const double one_minus_cos = u.x() * one_minus_cos_max;
        const double cos_theta = 1 - one_minus_cos;
        const double sin2_theta = one_minus_cos * (2 - one_minus_cos);
        const double sin_theta = std::sqrt(std::max(0.0, sin2_theta));
        const double phi = 2 * kPi * u.y();
        const Eigen::Vector3d w = sin_theta * std::cos(phi) * t + sin_theta * std::sin(phi) * b + cos_theta * axis;
        // The nearer intersection of the ray with the sphere: d cos(theta) - sqrt(r^2 - d^2 sin^2(theta)).
        const double distance = d * (cos_theta - std::sqrt(std::max(0.0, sin2_max - sin2_theta)));
        sum.add(w, distance, weight);
    }
    // pi L_e / intensity = 1 / r^2.
    bound = 1 / (light.size.x() * light.size.x());
    return true;
}

// By area over a rectangle or disk. Returns false when the point is on or behind the emitting side.
bool sample_flat(const Light& light, const Eigen::Vector3d& position, int samples, const Eigen::Vector2d& shift,
                 SampleSum& sum, double& bound) {
    const Eigen::Vector3d n = light.axis.stableNormalized();
    // The height above the emitter's plane: every point of the emitter sees the receiver at
    // cos(theta_e) = height / d, so in front of the plane means in front of all of it.
    const double height = n.dot(position - light.vector);
    if (!(height > 0)) return false;
    Eigen::Vector3d t, b;
    double area = 0;
    if (light.type == LightType::Rectangle) {
        const Eigen::Vector3d tangent = light.tangent.stableNormalized();
        t = (tangent - tangent.dot(n) * n).normalized();
        b = n.cross(t);
        area = light.size.x() * light.size.y();
    } else {
        orthonormal_basis(n, t, b);
        area = kPi * light.size.x() * light.size.x();
    }
    for (int j = 0; j < samples; ++j) {
        const Eigen::Vector2d u = sample_point(j, samples, shift);
        Eigen::Vector2d offset;
        if (light.type == LightType::Rectangle) {
            offset = {(u.x() - 0.5) * light.size.x(), (u.y() - 0.5) * light.size.y()};
        } else {
            offset = light.size.x() * concentric_disk(u.x(), u.y());
        }
        const Eigen::Vector3d to_light = light.vector + offset.x() * t + offset.y() * b - position;
        const double distance = to_light.norm();
        if (!(distance > 0)) continue;
        const double cos_e = height / distance;
        sum.add(to_light / distance, distance, cos_e / (distance * distance * samples));
    }
    // pi L_e / intensity = pi / area.
    bound = kPi / area;
    return true;
}

}  // namespace

AreaLightEstimate estimate_area_light(const Light& light, const Eigen::Vector3d& position, const Eigen::Vector3d& normal,
                                      double eta, const Eigen::Vector3f& shadow_origin, const TriangleBvh* bvh,
                                      int samples) {
    if (!is_area_light(light.type))
        throw InvalidArgumentError(std::string("estimate_area_light: a ") + light_type_name(light.type) +
                                   " light is not an area light");
    if (samples < 1) throw InvalidArgumentError("estimate_area_light: " + std::to_string(samples) + " samples");
    AreaLightEstimate estimate;
    SampleSum sum{normal, eta, shadow_origin, bvh};
    const Eigen::Vector2d shift = position_shift(position);
    double bound = 0;
    const bool lit = light.type == LightType::Sphere ? sample_sphere(light, position, samples, shift, sum, bound)
                                                     : sample_flat(light, position, samples, shift, sum, bound);
    if (!lit) return estimate;
    estimate.factor = std::min(sum.sum, bound);
    // Only when the light's size underflows in the bound and the point lies within ~1e-154 of it.
    if (!std::isfinite(estimate.factor)) estimate.factor = 0;
    estimate.visibility = sum.in_front > 0 ? static_cast<float>(sum.reached) / static_cast<float>(sum.in_front) : 1.0f;
    return estimate;
}

}  // namespace waxwork
