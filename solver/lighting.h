// Lights and the diffuse incoming light q at the boundary: the source term of the diffusion equation
// (the Robin boundary phi + 2 A kappa dphi/dn = 4/(1-F_dr) q, TransCut Eq. 5 / Arbree et al. 2011).
//
//   q_i = ambient + sum_lights I_l * max(0, n_i . w_il) * F_t(n_i . w_il, eta_i) * V_il   [* 1/d_il^2]
//
// w_il is the unit vector from boundary vertex i towards light l, n_i the area-weighted outward vertex
// normal, F_t the Fresnel transmittance into the medium, V_il in {0, 1} the visibility from a shadow ray
// against every boundary triangle of the volume in world space (so pieces shadow each other), and the
// 1/d^2 falloff applies to point lights. The ambient term is a constant per channel added to every
// boundary vertex (no F_t, no visibility): it stands in for the light of the environment and keeps the
// unlit side from going black.
//
// An area light l contributes the integral over the solid angle it subtends of
// L_e(w) max(0, n_i . w) F_t(n_i . w, eta_i) V_i(w) dw, estimated with kAreaLightSamples shadow rays
// (area_light.h); the point-light term above is its limit as the light shrinks.
//
// Lights inside the object: a point light inside a closed volume reaches no boundary vertex (every
// shadow ray to it crosses the surface, and on a convex part n_i . w_il < 0), so it contributes zero
// everywhere; with shadows off it lights the inner sides of faces that happen to face it. A point light
// exactly on a vertex contributes nothing to that vertex (no direction; never NaN). Likewise a
// vertex inside a sphere light, or behind the emitting side of a rectangle or disk, gets nothing
// from it.
#pragma once

#include "solver/environment_light.h"
#include "solver/ray_caster.h"
#include "solver/rgb.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace waxwork {

enum class LightType {
    Directional,  // parallel rays; `vector` is the direction in which the light travels
    Point,        // `vector` is the position (world space, model units); falloff 1/d^2
    // Area lights (area_light.h): `vector` is the centre (world space, model units), and the light
    // spreads over a shape, so shadows are soft.
    Rectangle,  // a one-sided Lambertian rectangle: `axis`, `tangent`, `size` = (width, height)
    Disk,       // a one-sided Lambertian disk: `axis`, radius `size.x()`
    Sphere,     // a sphere emitting the same radiance everywhere: radius `size.x()`
};

// "directional", "point", "rect", "disk" or "sphere": the light's name in specs, sessions and errors.
const char* light_type_name(LightType type);
// Whether the light sits somewhere (point and area lights), as opposed to a direction.
inline bool has_position(LightType type) { return type != LightType::Directional; }
inline bool is_area_light(LightType type) {
    return type == LightType::Rectangle || type == LightType::Disk || type == LightType::Sphere;
}
// Point and sphere lights shine from around their centre in every direction: one centred inside a
// closed object lights nothing (a sphere, at most where it pokes out of the surface).
inline bool radiates_from_centre(LightType type) { return type == LightType::Point || type == LightType::Sphere; }

// The intensity of an area light is its radiant intensity along its axis (for a sphere, in every
// direction), so that as its size goes to zero it lights exactly as a point light of that intensity
// at its centre:
//   rectangle, disk: I(theta) = intensity * cos(theta), theta from `axis` (a Lambertian emitter of
//                    radiance intensity / area, towards +axis only; nothing behind it);
//   sphere:          I = intensity in every direction (radiance intensity / (pi r^2) on its surface).
struct Light {
    LightType type = LightType::Directional;
    Eigen::Vector3d vector = Eigen::Vector3d(0, 0, -1);
    // Directional: irradiance on a surface facing the light. Point: radiant intensity, so the
    // irradiance at distance d facing the light is intensity / d^2 (d in model units). Area lights:
    // radiant intensity along the axis (above).
    Rgb intensity = {1, 1, 1};
    // Rectangle and disk: the normal of the emitting side (need not be unit length; not zero).
    Eigen::Vector3d axis = Eigen::Vector3d(0, 0, -1);
    // Rectangle: the direction of its width side; only its part perpendicular to `axis` counts, so it
    // must not be parallel to it (default_rect_tangent gives one).
    Eigen::Vector3d tangent = Eigen::Vector3d(1, 0, 0);
    // Rectangle: (width, height) in model units; disk and sphere: (radius, unused).
    Eigen::Vector2d size = Eigen::Vector2d(1, 1);
};

// The width direction of a rectangle whose normal is `axis` when none is given: world +x projected
// onto the rectangle's plane, or world +z when the axis is within 25.8 degrees of the x axis
// (|axis.x| > 0.9 |axis|), where +x projects too short to be a stable direction. Unit length;
// `axis` must be non-zero and finite.
Eigen::Vector3d default_rect_tangent(const Eigen::Vector3d& axis);
// Whether `tangent` gives a rectangle with normal `axis` a width direction: finite, non-zero and not
// parallel to the (non-zero, finite) axis.
bool tangent_spans_plane(const Eigen::Vector3d& axis, const Eigen::Vector3d& tangent);

// The samples each area light is integrated with at each point (area_light.h).
inline constexpr int kAreaLightSamples = 32;

struct Lighting {
    std::vector<Light> lights;
    Rgb ambient = {0, 0, 0};
    bool shadows = true;
    // Distant light from every direction (environment_light.h), integrated over each vertex's
    // hemisphere with visibility: q gains q_env (environment_transfer.h).
    std::optional<EnvironmentLight> environment;
};

// The lights evaluated with one shadow ray each: `lights`, then the sun of a built-in sky
// environment (rotated and scaled with it). The per-light visibility incident_light reports follows
// this order.
std::vector<Light> direct_lights(const Lighting& lighting);

class EnvironmentTransfer;

// The largest light-vector component: beyond it the solver's sums of squares overflow (1e100 squared,
// summed over a million vertices, is still finite; 1e308 is not), and so does the normalisation of
// directions.
constexpr double kMaxLightValue = 1e100;
// The largest light intensity or ambient: the GPU solves in float, whose sums of squares of the
// right-hand side overflow beyond about 1e18 (spot, 7,588 tets: 1e18 solves, 1e19 does not), and the
// radiance the renderer draws is float too (a session lit at 1e39 drew a black object). Light is
// relative (the exposure follows it), so no scene needs more.
constexpr double kMaxLightIntensity = 1e15;

// Throws InvalidArgumentError naming the light for non-finite components or ones beyond
// kMaxLightValue, a zero direction, or intensities / ambient negative or beyond kMaxLightIntensity;
// for an area light whose size is not positive and finite (at most kMaxLightValue), whose axis is
// zero, non-finite or beyond kMaxLightValue, or (rectangle) whose tangent is zero, non-finite or
// parallel to its axis; and for an invalid environment (environment_light.h: validate).
void validate(const Lighting& lighting);

// The boundary of a volume in world space, as the lighting and the renderer see it. Surface vertex s
// is volume vertex `vertices[s]`.
struct BoundarySurface {
    std::vector<int32_t> vertices;                 // volume vertex of each surface vertex (ascending)
    std::vector<Eigen::Vector3d> positions;        // world space (piece transform applied)
    std::vector<Eigen::Vector3d> normals;          // unit, area-weighted, outward
    // Into the surface arrays, counter-clockwise outside; triangle t is TetConnectivity::boundary_faces[t].
    std::vector<std::array<int32_t, 3>> triangles;
    std::vector<int32_t> triangle_tets;            // the tet each triangle is a face of
    std::vector<double> eta;                       // relative index of refraction per surface vertex
};

// Unit area-weighted vertex normals of a triangle surface (zero for vertices of no or only degenerate
// triangles).
std::vector<Eigen::Vector3d> area_weighted_normals(const std::vector<Eigen::Vector3d>& positions,
                                                   const std::vector<std::array<int32_t, 3>>& triangles);

// Extracts the boundary faces of the volume, moves each vertex by the rigid transform of its piece
// and computes normals. eta per vertex is boundary_vertex_eta (solver/radiance.h: area-weighted over
// its boundary faces' tets; materials one per tet), or default_eta when materials is empty.
BoundarySurface extract_boundary_surface(const TetMesh& mesh, const TetConnectivity& connectivity,
                                         const std::vector<TetMaterial>& materials, double default_eta = 1.3);

// The triangles of `surface` in float, for shadow rays; build once per geometry change and pass it to
// incident_light while only the lights change.
TriangleBvh build_shadow_bvh(const BoundarySurface& surface);
// The same tree for the same triangles at the surface's new positions (TriangleBvh::refit): what a
// deformation needs. `bvh` must have been built from a surface with these triangles, in this order.
void refit_shadow_bvh(TriangleBvh& bvh, const BoundarySurface& surface);

// q per surface vertex and channel. `bvh` must have been built from `surface` (only used with
// lighting.shadows). Parallel over vertices (TBB). With an environment, q_env comes from `transfer`
// when given (compute_environment_transfer of this surface, at the environment's order), else from
// a transfer computed here.
// `visibility`, when given, receives V_il from the shadow rays already cast for q, vertex-major
// (visibility[s * lights + l]): 0 where light l is occluded at surface vertex s, else 1 (also where the
// vertex faces away from the light; for an area light, the fraction of its samples in front of the
// vertex that reach it, in [0, 1], and 1 when none is in front, which the renderer's n.l test handles, so that interpolation
// across a triangle does not darken the terminator). The renderer multiplies each light's specular
// highlight by it, so highlights vanish in shadow as the diffuse light q does.
std::vector<Rgb> incident_light(const BoundarySurface& surface, const TriangleBvh& bvh, const Lighting& lighting,
                                std::vector<float>* visibility = nullptr, const EnvironmentTransfer* transfer = nullptr);
// Recomputes q (per surface vertex, as above) at `surface_vertices` only, e.g. after their eta
// changed (painting): equal to the full computation at those vertices, other entries untouched.
// With an environment, `transfer` as for incident_light (already updated at those vertices).
void update_incident_light(const BoundarySurface& surface, const TriangleBvh& bvh, const Lighting& lighting,
                           std::span<const int32_t> surface_vertices, std::vector<Rgb>& q,
                           const EnvironmentTransfer* transfer = nullptr);
// Same, building the BVH when lighting.shadows is set.
std::vector<Rgb> incident_light(const BoundarySurface& surface, const Lighting& lighting,
                                std::vector<float>* visibility = nullptr);

// q per volume vertex (zero at interior vertices), with one averaged normal per vertex: the form
// solve_diffusion takes, and the fixed systems the solver benchmarks and tests solve. The scenes
// Waxwork renders and edits integrate the light per crease fan instead (shading_surface.h:
// source_light), which differs only at vertices where the surface folds by more than the crease angle.
std::vector<Rgb> incident_light(const TetMesh& mesh, const TetConnectivity& connectivity,
                                const std::vector<TetMaterial>& materials, const Lighting& lighting);

// q at one point of the surface with outward unit `normal` and relative index `eta`; the shadow ray
// starts `shadow_offset` along the normal. `visibility`, when not null, receives V_il for each light
// (direct_lights(lighting).size() entries). incident_light is this at every surface vertex (with the
// environment's transfer computed here, for this one point); `lighting` must be valid (validate).
// `environment_transfer`, when not empty, is the point's transfer vector (environment_transfer_at),
// used instead of sampling one here.
Rgb incident_light_at(const Eigen::Vector3d& position, const Eigen::Vector3d& normal, double eta, double shadow_offset,
                      const TriangleBvh& bvh, const Lighting& lighting, float* visibility = nullptr,
                      std::span<const float> environment_transfer = {});

// The shadow-ray offset per surface vertex: kShadowOffset times its mean incident edge length (zero
// without shadows), clear of the triangles the vertex lies on.
std::vector<double> shadow_ray_offsets(const BoundarySurface& surface, const Lighting& lighting);

// Scatters per-surface-vertex values to volume vertices (zero elsewhere).
std::vector<Rgb> to_volume_vertices(const BoundarySurface& surface, const std::vector<Rgb>& values,
                                    size_t volume_vertex_count);

}  // namespace waxwork
