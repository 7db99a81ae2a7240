#include "solver/reference/monte_carlo_medium.h"

#include "solver/sampling.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace waxwork {

namespace {

uint64_t splitmix64(uint64_t& state) {
    uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

}  // namespace

MonteCarloRandom::MonteCarloRandom(uint64_t seed, uint64_t stream) {
    uint64_t state = seed ^ (0xd1b54a32d192ed03ull * (stream + 1));
    for (auto& word : s_) word = splitmix64(state);
}

Eigen::Vector3d sample_henyey_greenstein(const Eigen::Vector3d& d, double g, MonteCarloRandom& random) {
    const double xi = random.uniform();
    double cos_theta;
    if (std::abs(g) < 1e-6) {
        cos_theta = 2 * xi - 1;
    } else {
        const double f = (1 - g * g) / (1 - g + 2 * g * xi);
        cos_theta = std::clamp((1 + g * g - f * f) / (2 * g), -1.0, 1.0);
    }
    const double sin_theta = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
    const double phi = 2 * std::numbers::pi * random.uniform();
    Eigen::Vector3d t, b;
    orthonormal_basis(d, t, b);
    return (sin_theta * std::cos(phi) * t + sin_theta * std::sin(phi) * b + cos_theta * d).normalized();
}

double henyey_greenstein(double cos_theta, double g) {
    const double denominator = 1 + g * g - 2 * g * cos_theta;
    return (1 - g * g) / (4 * std::numbers::pi * denominator * std::sqrt(denominator));
}

Eigen::Vector3d refract_in(const Eigen::Vector3d& d, const Eigen::Vector3d& n, double eta) {
    const double cos_i = -d.dot(n);
    const double inv = 1.0 / eta;
    const double sin_t2 = inv * inv * std::max(0.0, 1 - cos_i * cos_i);
    const double cos_t = std::sqrt(std::max(0.0, 1 - sin_t2));
    return (inv * d + (inv * cos_i - cos_t) * n).normalized();
}

MonteCarloMedium build_monte_carlo_medium(const TetMesh& mesh, const TetConnectivity& connectivity,
                                          const std::vector<TetMaterial>& materials, double scale, double g) {
    MonteCarloMedium m;
    const size_t n = mesh.tet_count();
    m.planes.resize(n);
    m.volume.resize(n);
    m.mua.resize(n);
    m.mus.resize(n);
    m.eta.resize(n);
    m.boundary_face.assign(n, {-1, -1, -1, -1});
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t t = r.begin(); t != r.end(); ++t) {
            const Tet& tet = mesh.tets[t];
            std::array<Eigen::Vector3d, 4> p;
            for (int k = 0; k < 4; ++k) p[k] = mesh.positions[tet[k]] * scale;
            for (int k = 0; k < 4; ++k) {
                const auto& f = kTetFaces[k];
                const Eigen::Vector3d normal = (p[f[1]] - p[f[0]]).cross(p[f[2]] - p[f[0]]).normalized();
                m.planes[t].normal[k] = normal;
                m.planes[t].offset[k] = normal.dot(p[f[0]]);
            }
            m.volume[t] = (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0;
            for (int c = 0; c < 3; ++c) {
                m.mua[t][c] = materials[t].mua[c];
                m.mus[t][c] = materials[t].musp[c] / (1 - g);
            }
            m.eta[t] = materials[t].eta;
        }
    });
    for (size_t f = 0; f < connectivity.boundary_faces.size(); ++f) {
        const BoundaryFace& face = connectivity.boundary_faces[f];
        m.boundary_face[face.tet][face.local_face] = static_cast<int32_t>(f);
    }
    return m;
}

TetExit tet_exit(const MonteCarloMedium::TetPlanes& planes, const Eigen::Vector3d& x, const Eigen::Vector3d& d,
                 int skip) {
    TetExit exit{-1, std::numeric_limits<double>::infinity()};
    for (int k = 0; k < 4; ++k) {
        if (k == skip) continue;
        const double denom = planes.normal[k].dot(d);
        if (!(denom > 0)) continue;
        const double dist = std::max(0.0, (planes.offset[k] - planes.normal[k].dot(x)) / denom);
        if (dist < exit.distance) exit = {k, dist};
    }
    return exit;
}

int shared_face(const TetConnectivity& connectivity, int32_t next, int32_t tet) {
    const auto& back = connectivity.tet_neighbors[next];
    return static_cast<int>(std::find(back.begin(), back.end(), tet) - back.begin());
}

}  // namespace waxwork
