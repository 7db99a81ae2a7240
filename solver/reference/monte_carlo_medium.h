// What the Monte Carlo tracers share (monte_carlo.h traces photons from the lights, monte_carlo_image.h
// from the camera): their random streams, the Henyey-Greenstein phase function, refraction into the
// medium, and the volume as a walk sees it (per-tet face planes and coefficients, in millimetres, in
// each piece's rest frame).
#pragma once

#include "solver/material.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace waxwork {

// xoshiro256** (Blackman and Vigna 2018), seeded through splitmix64 from (seed, stream) so that
// streams are independent of each other and of the schedule that runs them.
class MonteCarloRandom {
public:
    MonteCarloRandom(uint64_t seed, uint64_t stream);
    uint64_t next() {
        const uint64_t result = rotl(s_[1] * 5, 7) * 9;
        const uint64_t t = s_[1] << 17;
        s_[2] ^= s_[0];
        s_[3] ^= s_[1];
        s_[1] ^= s_[2];
        s_[0] ^= s_[3];
        s_[2] ^= t;
        s_[3] = rotl(s_[3], 45);
        return result;
    }
    // In [0, 1).
    double uniform() { return (next() >> 11) * 0x1p-53; }
    // In (0, 1]: safe under log.
    double open_uniform() { return ((next() >> 11) + 1) * 0x1p-53; }

private:
    static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
    std::array<uint64_t, 4> s_{};
};

// Unit direction from the Henyey-Greenstein phase function with anisotropy g about `d`.
Eigen::Vector3d sample_henyey_greenstein(const Eigen::Vector3d& d, double g, MonteCarloRandom& random);
// Its density per steradian for the cosine between the travel directions before and after.
double henyey_greenstein(double cos_theta, double g);

// Snell refraction of `d` (unit, travelling into the surface: d . n < 0) from index 1 into relative
// index eta through a surface with outward unit normal n.
Eigen::Vector3d refract_in(const Eigen::Vector3d& d, const Eigen::Vector3d& n, double eta);

struct MonteCarloMedium {
    struct TetPlanes {
        std::array<Eigen::Vector3d, 4> normal;  // outward unit normal of face k (opposite vertex k)
        std::array<double, 4> offset;           // normal . x on the face
    };
    std::vector<TetPlanes> planes;
    std::vector<double> volume;                  // mm^3
    std::vector<std::array<double, 3>> mua, mus;
    std::vector<double> eta;
    std::vector<std::array<int32_t, 4>> boundary_face;  // per tet and local face: boundary face or -1
};

// mm per model unit `scale`; mu_s = mu_s' / (1 - g). Parallel over tets (TBB).
MonteCarloMedium build_monte_carlo_medium(const TetMesh& mesh, const TetConnectivity& connectivity,
                                          const std::vector<TetMaterial>& materials, double scale, double g);

// The face of tet `planes` a ray from x along unit d leaves through (never `skip`), and how far away;
// -1 when no face lies ahead (only from a degenerate direction).
struct TetExit {
    int face = -1;
    double distance = 0;
};
TetExit tet_exit(const MonteCarloMedium::TetPlanes& planes, const Eigen::Vector3d& x, const Eigen::Vector3d& d,
                 int skip);

// The local face of `next` shared with `tet`.
int shared_face(const TetConnectivity& connectivity, int32_t next, int32_t tet);

}  // namespace waxwork
