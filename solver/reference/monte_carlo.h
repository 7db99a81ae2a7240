// A Monte Carlo volumetric path tracer in the tetrahedral volume: the physical ground truth the
// diffusion solution approximates (docs/monte_carlo.md).
//
// Photons enter through the boundary triangles from the lights, refract there (Snell), walk tet to tet
// through the per-tet coefficients (tet-by-tet traversal as in Fang 2010, "Mesh-based Monte Carlo
// method using fast ray-tracing in Plucker coordinates": exact free paths in a piecewise-constant
// medium), scatter with the Henyey-Greenstein phase function (mu_s = mu_s' / (1 - g)), lose weight to
// absorption continuously along each segment, and at a boundary face are reflected (Fresnel, with
// total internal reflection) or leave. Light that leaves is not followed further (it does not re-enter
// other pieces: the diffusion model has no such inter-reflection either). The index of refraction acts
// only at the boundary; faces between tets of different eta are crossed without refraction, as in the
// diffusion model, where eta enters only the Robin boundary (Eq. 2).
//
// Units match the diffusion solve (solver/diffusion_solve.h): q is the light transmitted into the
// medium per unit area (lighting.h), a photon carries power in units of q times mm^2, and the fluence is
// the track length per volume, power times mm / mm^3: the units of q, as phi in
// phi + 2 A kappa dphi/dn = 4 q / (1 - F_dr).
#pragma once

#include "base/progress.h"
#include "solver/lighting.h"
#include "solver/rgb.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace waxwork {

// How the light of one source component enters the medium.
enum class PhotonEntry {
    Collimated,  // along `vector` (a directional light's travel direction, world space)
    FromPoint,   // from the point `vector` (world space, model units) to the entry point
    Diffuse,     // cosine-distributed about the inward normal (ambient and environment light)
};

// One component of the incident light: how it enters, and how much enters where.
struct PhotonSource {
    PhotonEntry entry = PhotonEntry::Diffuse;
    Eigen::Vector3d vector = Eigen::Vector3d::Zero();
    // Per surface vertex (BoundarySurface order): the transmitted light q this component contributes,
    // interpolated linearly over each boundary triangle.
    std::vector<Rgb> q;
};

// The incident light of `lighting` split into components: one per direct light
// (direct_lights(lighting): directional lights collimated, point lights from their position, area
// lights from their centre), each with q from incident_light with that light alone (so with its
// shadows), and one Diffuse component with the rest (ambient and environment). The components' q sum
// to incident_light(surface, bvh, lighting) (to rounding). `bvh` as for incident_light.
std::vector<PhotonSource> photon_sources(const BoundarySurface& surface, const TriangleBvh& bvh,
                                         const Lighting& lighting);

// The anisotropy the tracer uses unless told otherwise. Isotropic scattering: the materials give only
// the reduced coefficient mu_s' (Jensen et al. 2001 measured mu_s'), so g is not part of the data, and
// g = 0 is the one choice for which mu_s = mu_s' is the measured number itself; by the similarity
// relation the diffusive regime depends on mu_s' alone. It is also the cheapest (1 / (1 - g) times
// fewer scattering events than g = 0.9).
inline constexpr double kDefaultMonteCarloAnisotropy = 0.0;

struct MonteCarloOptions {
    double mm_per_unit = 1.0;
    double anisotropy = kDefaultMonteCarloAnisotropy;  // Henyey-Greenstein g in (-1, 1)
    uint64_t seed = 1;
    // Photons per batch and channel. Batches are the unit of parallel work and of the standard error
    // (independent batches), so the result depends on it.
    int batch_photons = 2000;
    // Stopping: the first of these that holds, checked after each round of batches (a round is a fixed
    // number of batches, independent of the thread count). A limit of 0 is no limit; at least one of
    // max_photons, max_seconds and target_relative_error must be set.
    int64_t max_photons = 0;              // per channel, rounded up to whole rounds
    double max_seconds = 0;               // wall clock
    double target_relative_error = 0;     // relative_error() of every channel at most this
    int min_batches = 16;                 // before the error target is trusted
    // Russian roulette (implicit capture): a photon below this fraction of its initial weight survives
    // with probability 0.1, its weight divided by it.
    double roulette_threshold = 1e-4;
    // A photon that takes more steps than this is dropped and counted (lost_photons).
    int64_t max_steps = 100'000'000;
};

// Called after each round from the calling thread; may throw to stop (cancellation).
struct MonteCarloProgress {
    int64_t photons = 0;        // per channel so far
    int64_t batches = 0;
    double seconds = 0;
    std::array<double, 3> relative_error{};
};

struct MonteCarloFluence {
    // Per volume vertex and channel: the fluence (units of q) and its standard error; zero at vertices
    // of no tet.
    std::vector<std::array<double, 3>> phi;
    std::vector<std::array<double, 3>> phi_error;
    // Per tet: the mean fluence over the tet (track length / volume).
    std::vector<std::array<double, 3>> tet_phi;
    // Per boundary face (TetConnectivity::boundary_faces order): the power that left through it per
    // mm^2 of the face (its exitance).
    std::vector<std::array<double, 3>> face_exitance;
    // Power per channel (units of q times mm^2): entered, absorbed and left; with mu_a = 0 everything
    // that entered leaves.
    std::array<double, 3> injected{};
    std::array<double, 3> absorbed{};
    std::array<double, 3> escaped{};
    std::array<double, 3> relative_error{};  // as MonteCarloProgress
    int64_t photons = 0;                     // per channel
    int64_t batches = 0;
    int64_t lost_photons = 0;                // dropped at max_steps
    double seconds = 0;
    std::string stop_reason;                 // "photons", "seconds", "error", or "no light"
};

// Throws InvalidArgumentError (starting "monte carlo: ") for g outside (-1, 1), a non-positive batch,
// negative or non-finite limits, or no limit at all.
void validate(const MonteCarloOptions& options);

// validate(options), and throws InvalidArgumentError (starting "monte carlo: ") for materials not one
// per tet or unusable, a surface that does not match the connectivity, or a source without one q per
// surface vertex. What trace_fluence and trace_camera_image check first.
void validate_trace_input(const TetMesh& mesh, const TetConnectivity& connectivity,
                          const std::vector<TetMaterial>& materials, const BoundarySurface& surface,
                          const std::vector<PhotonSource>& sources, const MonteCarloOptions& options);

// Traces the light of `sources` through the volume. `surface` is extract_boundary_surface of this mesh
// (its triangle t is connectivity.boundary_faces[t]); materials one per tet (validated). Deterministic
// for a seed: batch b uses its own random stream derived from (seed, b), and rounds are reduced in batch
// order, so the result is bit-identical on any thread count. Parallel over the batches of a round (TBB).
//
// phi at a vertex is the track length in the tets around it over their volume: the lumped-mass
// projection of the per-tet mean onto the vertices, the mass TransCut lumps (Eq. 13, V_i = sum V_t / 4).
// The standard error comes from the spread of the independent batches. relative_error per channel is
// |phi_error| / |phi| (2-norms over the boundary vertices).
//
// `progress` (optional) is called after each round; `cancel` (optional) is checked between rounds and
// stops the trace with CancelledError.
MonteCarloFluence trace_fluence(const TetMesh& mesh, const TetConnectivity& connectivity,
                                const std::vector<TetMaterial>& materials, const BoundarySurface& surface,
                                const std::vector<PhotonSource>& sources, const MonteCarloOptions& options,
                                const std::function<void(const MonteCarloProgress&)>& progress = {},
                                const Progress* cancel = nullptr);

}  // namespace waxwork
