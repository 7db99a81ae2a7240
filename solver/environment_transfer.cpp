#include "solver/environment_transfer.h"

#include "base/error.h"
#include "solver/material.h"
#include "solver/sampling.h"
#include "solver/spherical_harmonics.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace waxwork {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

// A per-vertex number in [0, 1) (the finaliser of MurmurHash3): turns each vertex's pattern by its own
// angle, so neighbouring vertices sample different azimuths.
double vertex_turn(uint32_t vertex) {
    uint32_t h = vertex * 0x9e3779b9u + 0x7f4a7c15u;
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h * 0x1p-32;
}

// An orthonormal tangent frame around unit n (orthonormal_basis).
struct TangentFrame {
    Eigen::Vector3d t, b, n;
    explicit TangentFrame(const Eigen::Vector3d& normal) : n(normal) { orthonormal_basis(n, t, b); }
    // Cosine-distributed direction j of n (module comment): returns n . w through cos_theta.
    Eigen::Vector3d cosine_direction(int j, int n_samples, double turn, double& cos_theta) const {
        const double u1 = (j + 0.5) / n_samples;
        const double phi = 2 * kPi * fraction(radical_inverse(static_cast<uint32_t>(j)) + turn);
        const double sin_theta = std::sqrt(u1);
        cos_theta = std::sqrt(1.0 - u1);
        return sin_theta * std::cos(phi) * t + sin_theta * std::sin(phi) * b + cos_theta * n;
    }
};

bool visible(const Eigen::Vector3f& origin, const Eigen::Vector3d& w, const TriangleBvh& bvh, bool shadows) {
    return !shadows || !bvh.occluded(origin, w.cast<float>(), 0.0f, kInfinity);
}

std::vector<double> ray_offsets(const BoundarySurface& surface, bool shadows) {
    Lighting lighting;
    lighting.shadows = shadows;
    return shadow_ray_offsets(surface, lighting);
}

void check_surface(const BoundarySurface& surface, const TriangleBvh& bvh, bool shadows, const char* what) {
    const size_t n = surface.positions.size();
    if (surface.normals.size() != n || surface.eta.size() != n)
        throw InvalidArgumentError(std::string(what) + ": surface has " + std::to_string(n) + " positions, " +
                                   std::to_string(surface.normals.size()) + " normals and " +
                                   std::to_string(surface.eta.size()) + " eta values");
    if (shadows && bvh.triangle_count() != surface.triangles.size())
        throw InvalidArgumentError(std::string(what) + ": the shadow BVH was not built from this surface");
}

}  // namespace

void validate(const TransferSettings& settings) {
    if (settings.order < 0 || settings.order > kMaxShOrder)
        throw InvalidArgumentError("transfer order " + std::to_string(settings.order) + " is outside [0, " +
                                   std::to_string(kMaxShOrder) + "]");
    if (settings.samples < 1 || settings.samples > 1000000)
        throw InvalidArgumentError("transfer sample count " + std::to_string(settings.samples) +
                                   " is outside [1, 1000000]");
}

EnvironmentTransfer::EnvironmentTransfer(const TransferSettings& settings, size_t points)
    : settings_(settings), points_(points), coefficients_(sh_coefficient_count(settings.order)) {
    validate(settings);
    values_.assign(points * coefficients_, 0.0f);
}

Rgb EnvironmentTransfer::apply(size_t point, std::span<const Rgb> environment) const {
    Rgb q = {0, 0, 0};
    const float* t = values_.data() + point * coefficients_;
    for (int k = 0; k < coefficients_; ++k)
        for (int c = 0; c < 3; ++c) q[c] += t[k] * environment[k][c];
    // Ringing of a truncated projection can dip below zero where the environment is dark.
    for (double& c : q) c = std::max(c, 0.0);
    return q;
}

void environment_transfer_at(const Eigen::Vector3d& position, const Eigen::Vector3d& normal, double eta, double offset,
                             const TriangleBvh& bvh, const TransferSettings& settings, uint32_t vertex,
                             std::span<float> out) {
    const int count = sh_coefficient_count(settings.order);
    std::fill(out.begin(), out.begin() + count, 0.0f);
    if (normal.squaredNorm() == 0) return;
    const TangentFrame frame(normal);
    const Eigen::Vector3f origin = (position + offset * normal).cast<float>();
    const double turn = vertex_turn(vertex);
    double basis[sh_coefficient_count(kMaxShOrder)];
    double sum[sh_coefficient_count(kMaxShOrder)] = {};
    for (int j = 0; j < settings.samples; ++j) {
        double cos_theta = 0;
        const Eigen::Vector3d w = frame.cosine_direction(j, settings.samples, turn, cos_theta);
        if (!visible(origin, w, bvh, settings.shadows)) continue;
        const double f = fresnel_transmittance(cos_theta, eta);
        evaluate_sh(settings.order, w, std::span<double>(basis, count));
        for (int k = 0; k < count; ++k) sum[k] += f * basis[k];
    }
    const double weight = kPi / settings.samples;
    for (int k = 0; k < count; ++k) out[k] = static_cast<float>(sum[k] * weight);
}

EnvironmentTransfer compute_environment_transfer(const BoundarySurface& surface, const TriangleBvh& bvh,
                                                 const TransferSettings& settings) {
    EnvironmentTransfer transfer(settings, surface.positions.size());
    std::vector<int32_t> all(surface.positions.size());
    for (size_t s = 0; s < all.size(); ++s) all[s] = static_cast<int32_t>(s);
    update_environment_transfer(surface, bvh, all, transfer);
    return transfer;
}

void update_environment_transfer(const BoundarySurface& surface, const TriangleBvh& bvh,
                                 std::span<const int32_t> surface_vertices, EnvironmentTransfer& transfer) {
    const TransferSettings& settings = transfer.settings();
    check_surface(surface, bvh, settings.shadows, "environment transfer");
    if (transfer.size() != surface.positions.size())
        throw InvalidArgumentError("environment transfer: " + std::to_string(transfer.size()) + " vectors for " +
                                   std::to_string(surface.positions.size()) + " surface vertices");
    for (const int32_t s : surface_vertices)
        if (s < 0 || static_cast<size_t>(s) >= transfer.size())
            throw InvalidArgumentError("environment transfer: surface vertex " + std::to_string(s) + " out of range");
    const std::vector<double> offset = ray_offsets(surface, settings.shadows);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, surface_vertices.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const auto s = static_cast<size_t>(surface_vertices[i]);
            environment_transfer_at(surface.positions[s], surface.normals[s], surface.eta[s], offset[s], bvh, settings,
                                    static_cast<uint32_t>(s), transfer.at(s));
        }
    });
}

std::vector<Rgb> apply_environment_transfer(const EnvironmentTransfer& transfer, const EnvironmentLight& environment) {
    validate(environment);
    if (environment.sh_order != transfer.settings().order)
        throw InvalidArgumentError("environment transfer of order " + std::to_string(transfer.settings().order) +
                                   " for an environment projected to order " + std::to_string(environment.sh_order));
    const std::vector<Rgb> light = environment_sh(environment);
    std::vector<Rgb> q(transfer.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, q.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t s = r.begin(); s != r.end(); ++s) q[s] = transfer.apply(s, light);
    });
    return q;
}

std::vector<int32_t> vertices_seeing_box(const BoundarySurface& surface, const Eigen::AlignedBox3d& changed) {
    std::vector<int32_t> seeing;
    if (changed.isEmpty()) return seeing;
    for (size_t s = 0; s < surface.positions.size(); ++s) {
        const Eigen::Vector3d& n = surface.normals[s];
        if (n.squaredNorm() == 0) continue;
        // The box corner farthest along n decides: n . (corner - p) is linear over the box.
        Eigen::Vector3d corner;
        for (int a = 0; a < 3; ++a) corner[a] = n[a] >= 0 ? changed.max()[a] : changed.min()[a];
        if (n.dot(corner - surface.positions[s]) > 0) seeing.push_back(static_cast<int32_t>(s));
    }
    return seeing;
}

Rgb sampled_environment_light_at(const Eigen::Vector3d& position, const Eigen::Vector3d& normal, double eta,
                                 double offset, const TriangleBvh& bvh, bool shadows,
                                 const EnvironmentLight& environment, const EnvironmentSampler& sampler, int samples,
                                 uint32_t vertex) {
    Rgb q = {0, 0, 0};
    if (normal.squaredNorm() == 0 || samples < 1) return q;
    const TangentFrame frame(normal);
    const Eigen::Vector3f origin = (position + offset * normal).cast<float>();
    const double radians = environment.rotation_degrees * kPi / 180;
    const Eigen::AngleAxisd rotate(radians, Eigen::Vector3d::UnitY()), unrotate(-radians, Eigen::Vector3d::UnitY());
    const int n_env = sampler.valid() ? samples / 2 : 0;
    const int n_cos = samples - n_env;
    const double turn = vertex_turn(vertex);
    const auto add = [&](const Eigen::Vector3d& w, double cos_theta, const Eigen::Vector3d& unrotated, double pdf_env) {
        if (!visible(origin, w, bvh, shadows)) return;
        const double weight = fresnel_transmittance(cos_theta, eta) * cos_theta / (n_cos * cos_theta / kPi + n_env * pdf_env);
        const Rgb& radiance = environment.map->radiance(unrotated);
        for (int c = 0; c < 3; ++c) q[c] += radiance[c] * weight;
    };
    for (int j = 0; j < n_cos; ++j) {
        double cos_theta = 0;
        const Eigen::Vector3d w = frame.cosine_direction(j, n_cos, turn, cos_theta);
        const Eigen::Vector3d unrotated = unrotate * w;
        add(w, cos_theta, unrotated, n_env > 0 ? sampler.pdf(unrotated) : 0.0);
    }
    for (int j = 0; j < n_env; ++j) {
        double pdf = 0;
        const Eigen::Vector3d unrotated =
            sampler.sample(fraction((j + 0.5) / n_env + turn), fraction(radical_inverse(static_cast<uint32_t>(j)) + turn * 0.618), pdf);
        const Eigen::Vector3d w = rotate * unrotated;
        const double cos_theta = normal.dot(w);
        if (!(cos_theta > 0) || !(pdf > 0)) continue;
        add(w, cos_theta, unrotated, pdf);
    }
    for (double& c : q) c *= environment.intensity;
    return q;
}

std::vector<Rgb> sampled_environment_light(const BoundarySurface& surface, const TriangleBvh& bvh, bool shadows,
                                           const EnvironmentLight& environment, int samples) {
    validate(environment);
    check_surface(surface, bvh, shadows, "sampled environment light");
    const EnvironmentSampler sampler(*environment.map);
    const std::vector<double> offset = ray_offsets(surface, shadows);
    std::vector<Rgb> q(surface.positions.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, q.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t s = r.begin(); s != r.end(); ++s)
            q[s] = sampled_environment_light_at(surface.positions[s], surface.normals[s], surface.eta[s], offset[s], bvh,
                                                shadows, environment, sampler, samples, static_cast<uint32_t>(s));
    });
    return q;
}

}  // namespace waxwork
