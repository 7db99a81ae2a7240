// The light an area light (rectangle, disk, sphere; lighting.h) gives one receiver point: the
// integral over the solid angle it subtends of L_e max(0, n . w) F_t(n . w, eta) V(w) dw, estimated
// with a fixed number of samples, each with a shadow ray.
//
// Sampling: the rectangle and the disk by area (the disk through the concentric map), with the
// area-to-solid-angle Jacobian cos(theta_e) / d^2; the sphere by solid angle, uniformly over the cone
// of directions to the cap the point sees (pbrt-v4 SphereLight / Sphere::Sample), so that no sample
// is wasted on the far side. With L_e = intensity / area (rectangle, disk) or intensity / (pi r^2)
// (sphere) the estimate is, per sample, intensity times
//   rectangle, disk: cos(theta_e) cos(theta_i) F_t V / d^2                 (the area cancels)
//   sphere:          2 / ((1 + cos(theta_max)) d_c^2) cos(theta_i) F_t V   (the cone's solid angle
//                    2 pi (1 - cos(theta_max)) times L_e, rewritten without the radius)
// so both tend to the point light's intensity cos(theta_i) F_t / d^2 as the light shrinks, and
// neither divides by a vanishing size.
//
// The pattern: a Hammersley set ((j + 1/2) / N, radical_inverse(j)), shifted modulo 1 by a
// Cranley-Patterson rotation drawn from a hash of the point's position. Deterministic, so an image
// does not flicker from frame to frame, a recomputation at some vertices (update_incident_light)
// equals the full one, and results reproduce; low-discrepancy, so 32 samples integrate a smooth
// unshadowed light to well under a percent; shifted per point, so the error left at the edges of
// soft shadows is fine-grained noise (which the diffusion blurs) rather than the bands a single shared
// pattern draws across the surface.
#pragma once

#include "solver/lighting.h"
#include "solver/ray_caster.h"

#include <Eigen/Core>

namespace waxwork {

struct AreaLightEstimate {
    double factor = 0;     // the light adds intensity[c] * factor to q
    float visibility = 1;  // the fraction of the samples in front of the point that reach it; 1 if none is
};

// The estimate at `position` with outward unit `normal` and relative index `eta`. Shadow rays start
// at `shadow_origin` and stop just short of the sampled point; `bvh` null means no shadows. A point
// inside or on a sphere light, or on or behind the emitting side of a rectangle or disk, gets nothing
// (factor 0, visibility 1). The estimate never exceeds the irradiance the light's radiance gives over a
// whole hemisphere (pi L_e), which bounds the area sampling's rare huge samples next to the emitter;
// it is always finite. `light` must be a valid area light (validate); InvalidArgumentError for another
// type or samples < 1.
AreaLightEstimate estimate_area_light(const Light& light, const Eigen::Vector3d& position, const Eigen::Vector3d& normal,
                                      double eta, const Eigen::Vector3f& shadow_origin, const TriangleBvh* bvh,
                                      int samples = kAreaLightSamples);

}  // namespace waxwork
