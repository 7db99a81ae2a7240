// The environment's incident light q_env at boundary points (environment_light.h), two ways.
//
// Transfer (Sloan, Kautz and Snyder 2002, Eq. 5-7): everything in the integrand but the radiance,
// T(w) = V(x, w) F_t(n . w, eta) max(n . w, 0), is projected once per geometry onto the spherical
// harmonics of environment_sh, so that q_env = sum_k T_k L_k: rotating or rescaling the environment
// costs a dot product per vertex, and only geometry changes cast rays. The projection integrates with
// N cosine-distributed directions, T_k = (pi / N) sum_j V_j F_t(cos theta_j) Y_k(w_j), on a
// Hammersley pattern in the vertex's tangent frame (the polar coordinate stratified at the
// midpoints (j + 1/2) / N, the azimuth by the radical inverse, turned by a per-vertex angle so that
// neighbouring vertices do not alias together). On an unoccluded vertex the l = 0 coefficient then
// depends on eta alone, so a constant environment gives every vertex of a convex body the same q.
//
// Sampled (the reference): the same integral with the environment's radiance itself, by multiple
// importance sampling (Veach 1997, the balance heuristic) of the cosine and of the environment's
// luminance (EnvironmentSampler), so that a small bright source is found.
#pragma once

#include "solver/environment_light.h"
#include "solver/lighting.h"
#include "solver/ray_caster.h"

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

// The directions each transfer vector integrates with.
inline constexpr int kDefaultTransferSamples = 256;
// The directions of the sampled reference, half from each strategy.
inline constexpr int kDefaultReferenceSamples = 2048;

struct TransferSettings {
    int order = kDefaultTransferOrder;
    int samples = kDefaultTransferSamples;
    bool shadows = true;  // V from rays through the BVH; off: V = 1
};

// Throws InvalidArgumentError for an order outside [0, kMaxShOrder] or a sample count outside [1, 1e6].
void validate(const TransferSettings& settings);

// One transfer vector per point, in float (the relighting dot product reads them every frame).
class EnvironmentTransfer {
public:
    EnvironmentTransfer() = default;
    EnvironmentTransfer(const TransferSettings& settings, size_t points);

    const TransferSettings& settings() const { return settings_; }
    size_t size() const { return points_; }
    int coefficients() const { return coefficients_; }
    std::span<float> at(size_t point) { return {values_.data() + point * coefficients_, static_cast<size_t>(coefficients_)}; }
    std::span<const float> at(size_t point) const {
        return {values_.data() + point * coefficients_, static_cast<size_t>(coefficients_)};
    }
    // q_env at `point` for the environment's coefficients (environment_sh; the same order).
    Rgb apply(size_t point, std::span<const Rgb> environment) const;

private:
    TransferSettings settings_;
    size_t points_ = 0;
    int coefficients_ = 0;
    std::vector<float> values_;
};

// The transfer vector of one boundary point; `offset` lifts the ray origins off the surface along
// the normal (shadow_ray_offsets). The azimuth pattern is turned by an angle hashed from the
// position's bits, so a vertex that an edit leaves in place keeps its pattern whatever its new index.
// A zero normal gives a zero vector.
void environment_transfer_at(const Eigen::Vector3d& position, const Eigen::Vector3d& normal, double eta, double offset,
                             const TriangleBvh& bvh, const TransferSettings& settings, std::span<float> out);

// The transfer of every surface vertex (parallel with TBB). `bvh` is build_shadow_bvh(surface).
EnvironmentTransfer compute_environment_transfer(const BoundarySurface& surface, const TriangleBvh& bvh,
                                                 const TransferSettings& settings);
// Recomputes the vectors of `surface_vertices` only (after the geometry or eta changed there).
void update_environment_transfer(const BoundarySurface& surface, const TriangleBvh& bvh,
                                 std::span<const int32_t> surface_vertices, EnvironmentTransfer& transfer);

// q_env per surface vertex from a transfer and an environment.
std::vector<Rgb> apply_environment_transfer(const EnvironmentTransfer& transfer, const EnvironmentLight& environment);

// A triangle in world space, as three corners.
using WorldTriangle = std::array<Eigen::Vector3d, 3>;

// The surface vertices whose transfer can change when the triangles `changed` (removed ones at their
// old place, added ones at their new place) change: those with a corner of some changed triangle
// strictly above their tangent plane. A vertex's transfer integrates rays over the open hemisphere
// above its tangent plane only, a triangle meets that half-space only if one of its corners lies in
// it, and only rays that meet a changed triangle can change their visibility, so every other vertex
// keeps its transfer exactly. The changed triangles are grouped in a small box tree, so a vertex
// skips every group lying wholly below its plane. Vertices of zero normal are never listed.
std::vector<int32_t> vertices_seeing_triangles(const BoundarySurface& surface, std::span<const WorldTriangle> changed);

// The transfer of `surface` after an edit, from the transfer of the surface before it: a vertex keeps
// its old vector when it was on the old surface at the same position, with the same normal, eta
// and ray offset, and cannot see the changed triangles (vertices_seeing_triangles on the old
// triangles that are gone or moved and the new ones that were not there); every other vertex is
// sampled again. `new_of_old_vertex` maps old volume vertices to new ones (-1: removed); empty: the
// same numbering. The result equals compute_environment_transfer(surface, bvh, settings) bit for
// bit. `recomputed`, when given, receives the number of vertices sampled again.
//
// Deferring: when `deferred` is given, a vertex that was on the old surface with the same eta and a
// normal turned by at most 10 degrees (it stayed in place but can see a change, or a cut's relaxation
// moved it a little) keeps its old vector for now and is listed there instead of being sampled; new
// and turned vertices are sampled at once with kInterimTransferSamples rays and listed first. The
// caller samples the list later
// (update_environment_transfer), after which the result again equals a full computation. A large cut
// changes what most of the surface sees, so this is what lets an editor show it at once and refine the
// light over the next frames. `old_deferred` lists the old surface's vertices still waiting: they stay
// listed (or, without `deferred`, are sampled now).
inline constexpr int kInterimTransferSamples = 32;
EnvironmentTransfer carry_environment_transfer(const BoundarySurface& old_surface, const EnvironmentTransfer& old_transfer,
                                               const BoundarySurface& surface, const TriangleBvh& bvh,
                                               std::span<const int32_t> new_of_old_vertex,
                                               size_t* recomputed = nullptr,
                                               std::span<const int32_t> old_deferred = {},
                                               std::vector<int32_t>* deferred = nullptr);

// The sampled reference at one point, with `samples` directions (half by the cosine, half by the
// environment's luminance); `sampler` is EnvironmentSampler(*environment.map).
Rgb sampled_environment_light_at(const Eigen::Vector3d& position, const Eigen::Vector3d& normal, double eta,
                                 double offset, const TriangleBvh& bvh, bool shadows,
                                 const EnvironmentLight& environment, const EnvironmentSampler& sampler, int samples);
// The sampled reference at every surface vertex.
std::vector<Rgb> sampled_environment_light(const BoundarySurface& surface, const TriangleBvh& bvh, bool shadows,
                                           const EnvironmentLight& environment,
                                           int samples = kDefaultReferenceSamples);

}  // namespace waxwork
