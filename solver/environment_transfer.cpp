#include "solver/environment_transfer.h"

#include "base/error.h"
#include "solver/material.h"
#include "solver/sampling.h"
#include "solver/spherical_harmonics.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>
#include <string>

namespace waxwork {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

// cos(10 degrees): a deferred vertex's normal turned by at most this much since its vector was sampled,
// so the lobe it integrates is nearly the same.
constexpr double kDeferrableNormalCosine = 0.98480775301220802;

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
                             const TriangleBvh& bvh, const TransferSettings& settings, std::span<float> out) {
    const int count = sh_coefficient_count(settings.order);
    std::fill(out.begin(), out.begin() + count, 0.0f);
    if (normal.squaredNorm() == 0) return;
    const TangentFrame frame(normal);
    const Eigen::Vector3f origin = (position + offset * normal).cast<float>();
    // Turned by an angle from the position's bits, so neighbouring vertices sample different azimuths
    // and a vertex an edit leaves in place keeps its pattern.
    const double turn = position_shift(position).x();
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
                                    transfer.at(s));
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

namespace {

// The changed triangles grouped by median splits into boxes of at most kLeafTriangles, flattened
// depth first: node i's first child is i + 1 and `skip` jumps past its subtree. Hand-written rather
// than TriangleBvh, whose traversal answers ray queries, not "is any corner above this plane?".
struct PlaneQueryTree {
    static constexpr size_t kLeafTriangles = 8;
    struct Node {
        Eigen::AlignedBox3d box;
        size_t begin = 0, end = 0;  // triangles [begin, end) in order (a leaf when end - begin <= kLeafTriangles)
        size_t skip = 0;            // the node after this subtree
    };
    std::vector<WorldTriangle> triangles;
    std::vector<Node> nodes;

    explicit PlaneQueryTree(std::span<const WorldTriangle> changed) : triangles(changed.begin(), changed.end()) {
        if (!triangles.empty()) build(0, triangles.size());
    }

    void build(size_t begin, size_t end) {
        const size_t index = nodes.size();
        nodes.push_back({});
        Eigen::AlignedBox3d box;
        for (size_t t = begin; t < end; ++t)
            for (const Eigen::Vector3d& p : triangles[t]) box.extend(p);
        nodes[index].box = box;
        nodes[index].begin = begin;
        nodes[index].end = end;
        if (end - begin > kLeafTriangles) {
            int axis = 0;
            box.sizes().maxCoeff(&axis);
            const size_t middle = begin + (end - begin) / 2;
            std::nth_element(triangles.begin() + static_cast<std::ptrdiff_t>(begin),
                             triangles.begin() + static_cast<std::ptrdiff_t>(middle),
                             triangles.begin() + static_cast<std::ptrdiff_t>(end),
                             [axis](const WorldTriangle& a, const WorldTriangle& b) {
                                 return a[0][axis] + a[1][axis] + a[2][axis] < b[0][axis] + b[1][axis] + b[2][axis];
                             });
            build(begin, middle);
            build(middle, end);
        }
        nodes[index].skip = nodes.size();
    }

    // Whether a corner of some triangle lies strictly above the plane through p with normal n.
    bool any_above(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const {
        for (size_t i = 0; i < nodes.size();) {
            const Node& node = nodes[i];
            // The box corner farthest along n decides: n . (corner - p) is linear over the box.
            Eigen::Vector3d corner;
            for (int a = 0; a < 3; ++a) corner[a] = n[a] >= 0 ? node.box.max()[a] : node.box.min()[a];
            if (!(n.dot(corner - p) > 0)) {
                i = node.skip;
                continue;
            }
            if (node.end - node.begin <= kLeafTriangles) {
                for (size_t t = node.begin; t < node.end; ++t)
                    for (const Eigen::Vector3d& c : triangles[t])
                        if (n.dot(c - p) > 0) return true;
                i = node.skip;
            } else {
                ++i;
            }
        }
        return false;
    }
};

}  // namespace

std::vector<int32_t> vertices_seeing_triangles(const BoundarySurface& surface, std::span<const WorldTriangle> changed) {
    const PlaneQueryTree tree(changed);
    std::vector<uint8_t> sees(surface.positions.size(), 0);
    if (!tree.nodes.empty()) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, sees.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t s = r.begin(); s != r.end(); ++s) {
                const Eigen::Vector3d& n = surface.normals[s];
                sees[s] = n.squaredNorm() > 0 && tree.any_above(surface.positions[s], n);
            }
        });
    }
    std::vector<int32_t> seeing;
    for (size_t s = 0; s < sees.size(); ++s)
        if (sees[s]) seeing.push_back(static_cast<int32_t>(s));
    return seeing;
}

EnvironmentTransfer carry_environment_transfer(const BoundarySurface& old_surface, const EnvironmentTransfer& old_transfer,
                                               const BoundarySurface& surface, const TriangleBvh& bvh,
                                               std::span<const int32_t> new_of_old_vertex, size_t* recomputed,
                                               std::span<const int32_t> old_deferred, std::vector<int32_t>* deferred) {
    const TransferSettings& settings = old_transfer.settings();
    if (old_transfer.size() != old_surface.positions.size())
        throw InvalidArgumentError("carry_environment_transfer: " + std::to_string(old_transfer.size()) +
                                   " vectors for " + std::to_string(old_surface.positions.size()) + " old surface vertices");
    const auto new_volume_vertex = [&](int32_t old_vertex) -> int32_t {
        if (new_of_old_vertex.empty()) return old_vertex;
        return static_cast<size_t>(old_vertex) < new_of_old_vertex.size() ? new_of_old_vertex[old_vertex] : -1;
    };
    // The old surface vertex of each new volume vertex, if it had one.
    int32_t largest = -1;
    for (const int32_t v : surface.vertices) largest = std::max(largest, v);
    std::vector<int32_t> old_of_new(static_cast<size_t>(largest + 1), -1);
    for (size_t s = 0; s < old_surface.vertices.size(); ++s) {
        const int32_t v = new_volume_vertex(old_surface.vertices[s]);
        if (v >= 0 && v <= largest) old_of_new[v] = static_cast<int32_t>(s);
    }
    std::vector<int32_t> old_of_surface(surface.positions.size(), -1);
    for (size_t s = 0; s < surface.vertices.size(); ++s) old_of_surface[s] = old_of_new[surface.vertices[s]];

    // Triangles as sorted triples of new volume vertices; a triangle with a moved or removed corner is
    // changed whatever its triple.
    using Triple = std::array<int32_t, 3>;
    const auto sorted = [](Triple t) {
        std::sort(t.begin(), t.end());
        return t;
    };
    std::vector<uint8_t> moved(surface.positions.size(), 0);
    for (size_t s = 0; s < moved.size(); ++s)
        moved[s] = old_of_surface[s] < 0 || old_surface.positions[old_of_surface[s]] != surface.positions[s];
    std::vector<Triple> old_triangles, new_triangles;
    std::vector<WorldTriangle> changed;
    const auto corners = [](const BoundarySurface& on, const std::array<int32_t, 3>& t) {
        return WorldTriangle{on.positions[t[0]], on.positions[t[1]], on.positions[t[2]]};
    };
    for (const auto& t : surface.triangles) {
        if (moved[t[0]] || moved[t[1]] || moved[t[2]]) {
            changed.push_back(corners(surface, t));
        } else {
            new_triangles.push_back(sorted({surface.vertices[t[0]], surface.vertices[t[1]], surface.vertices[t[2]]}));
        }
    }
    for (const auto& t : old_surface.triangles) {
        Triple mapped;
        for (int k = 0; k < 3; ++k) mapped[k] = new_volume_vertex(old_surface.vertices[t[k]]);
        old_triangles.push_back(sorted(mapped));
    }
    std::sort(new_triangles.begin(), new_triangles.end());
    std::vector<Triple> old_sorted = old_triangles;
    std::sort(old_sorted.begin(), old_sorted.end());
    // New, unmoved triangles that were not there before.
    std::vector<Triple> added;
    std::set_difference(new_triangles.begin(), new_triangles.end(), old_sorted.begin(), old_sorted.end(),
                        std::back_inserter(added));
    std::vector<int32_t> surface_of_volume(static_cast<size_t>(largest + 1), -1);
    for (size_t s = 0; s < surface.vertices.size(); ++s) surface_of_volume[surface.vertices[s]] = static_cast<int32_t>(s);
    for (const Triple& t : added)
        changed.push_back({surface.positions[surface_of_volume[t[0]]], surface.positions[surface_of_volume[t[1]]],
                           surface.positions[surface_of_volume[t[2]]]});
    // Old triangles that are gone or moved: everything not among the new, unmoved ones.
    for (size_t i = 0; i < old_surface.triangles.size(); ++i) {
        const Triple& t = old_triangles[i];
        if (std::binary_search(new_triangles.begin(), new_triangles.end(), t)) continue;
        changed.push_back(corners(old_surface, old_surface.triangles[i]));
    }

    std::vector<uint8_t> sees(surface.positions.size(), 0);
    for (const int32_t s : vertices_seeing_triangles(surface, changed)) sees[s] = 1;
    const std::vector<double> old_offset = ray_offsets(old_surface, settings.shadows);
    const std::vector<double> offset = ray_offsets(surface, settings.shadows);
    std::vector<uint8_t> old_waiting(old_surface.positions.size(), 0);
    for (const int32_t o : old_deferred) {
        if (o < 0 || static_cast<size_t>(o) >= old_waiting.size())
            throw InvalidArgumentError("carry_environment_transfer: deferred vertex " + std::to_string(o) + " out of range");
        old_waiting[o] = 1;
    }
    if (deferred) deferred->clear();
    EnvironmentTransfer transfer(settings, surface.positions.size());
    std::vector<int32_t> again;
    for (size_t s = 0; s < surface.positions.size(); ++s) {
        const int32_t o = old_of_surface[s];
        const bool in_place = o >= 0 && !moved[s] && old_surface.normals[o] == surface.normals[s] &&
                              old_surface.eta[o] == surface.eta[s] && old_offset[o] == offset[s];
        if (in_place && !sees[s] && !old_waiting[o]) {
            const auto from = old_transfer.at(o);
            std::copy(from.begin(), from.end(), transfer.at(s).begin());
            continue;
        }
        // A vertex that was there before with the same eta and a normal turned by little (a cut's
        // relaxation, a piece moved without much turning) can stand in with its old vector for a few
        // frames; a new vertex or a turned one has nothing to stand in with.
        const bool close = o >= 0 && old_surface.eta[o] == surface.eta[s] &&
                           old_surface.normals[o].dot(surface.normals[s]) >= kDeferrableNormalCosine;
        if (deferred && close) {
            const auto from = old_transfer.at(o);
            std::copy(from.begin(), from.end(), transfer.at(s).begin());
            deferred->push_back(static_cast<int32_t>(s));
            continue;
        }
        again.push_back(static_cast<int32_t>(s));
    }
    if (deferred) {
        // Sampled now with few rays to stand in for a few frames, and first in line for the full
        // sampling: new vertices are where the user looks (a cut's face).
        TransferSettings interim = settings;
        interim.samples = std::min(settings.samples, kInterimTransferSamples);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, again.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i != r.end(); ++i) {
                const auto s = static_cast<size_t>(again[i]);
                environment_transfer_at(surface.positions[s], surface.normals[s], surface.eta[s], offset[s], bvh,
                                        interim, transfer.at(s));
            }
        });
        deferred->insert(deferred->begin(), again.begin(), again.end());
    } else {
        update_environment_transfer(surface, bvh, again, transfer);
    }
    if (recomputed) *recomputed = again.size();
    return transfer;
}

Rgb sampled_environment_light_at(const Eigen::Vector3d& position, const Eigen::Vector3d& normal, double eta,
                                 double offset, const TriangleBvh& bvh, bool shadows,
                                 const EnvironmentLight& environment, const EnvironmentSampler& sampler, int samples) {
    Rgb q = {0, 0, 0};
    if (normal.squaredNorm() == 0 || samples < 1) return q;
    const TangentFrame frame(normal);
    const Eigen::Vector3f origin = (position + offset * normal).cast<float>();
    const double radians = environment.rotation_degrees * kPi / 180;
    const Eigen::AngleAxisd rotate(radians, Eigen::Vector3d::UnitY()), unrotate(-radians, Eigen::Vector3d::UnitY());
    const int n_env = sampler.valid() ? samples / 2 : 0;
    const int n_cos = samples - n_env;
    const Eigen::Vector2d shift = position_shift(position);
    const double turn = shift.x();
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
            sampler.sample(fraction((j + 0.5) / n_env + shift.x()), fraction(radical_inverse(static_cast<uint32_t>(j)) + shift.y()), pdf);
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
                                                shadows, environment, sampler, samples);
    });
    return q;
}

}  // namespace waxwork
