#include "solver/shading_surface.h"

#include "base/error.h"
#include "tetops/connectivity.h"
#include "tetops/disjoint_sets.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>
#include <span>
#include <string>

namespace waxwork {

ShadingSurface split_at_creases(const BoundarySurface& surface, double crease_angle_degrees) {
    if (!is_crease_angle(crease_angle_degrees))
        throw InvalidArgumentError("crease angle " + number_text(crease_angle_degrees) +
                                   " degrees: must be between 0 and 180");
    const size_t n = surface.positions.size();
    if (surface.normals.size() != n)
        throw InvalidArgumentError("split_at_creases: " + std::to_string(surface.normals.size()) + " normals for " +
                                   std::to_string(n) + " vertices");
    for (size_t t = 0; t < surface.triangles.size(); ++t)
        for (const int32_t v : surface.triangles[t])
            if (v < 0 || static_cast<size_t>(v) >= n)
                throw InvalidArgumentError("split_at_creases: triangle " + std::to_string(t) + " names vertex " +
                                           std::to_string(v) + " of a surface of " + std::to_string(n));

    ShadingSurface shading;
    shading.surface_vertex.resize(n);
    std::iota(shading.surface_vertex.begin(), shading.surface_vertex.end(), 0);
    shading.normals = surface.normals;
    shading.triangles = surface.triangles;
    if (crease_angle_degrees >= 180.0) return shading;  // every pair of normals is within 180 degrees

    // Twice-area normals (the fans' normals weigh them by area) and unit ones (the angle test); a
    // degenerate triangle has a zero unit normal and joins any fan it touches.
    std::vector<Eigen::Vector3d> face_normal(surface.triangles.size()), unit_normal(surface.triangles.size());
    tbb::parallel_for(size_t{0}, surface.triangles.size(), [&](size_t t) {
        const auto& [a, b, c] = surface.triangles[t];
        face_normal[t] = (surface.positions[b] - surface.positions[a]).cross(surface.positions[c] - surface.positions[a]);
        const double length = face_normal[t].norm();
        unit_normal[t] = length > 0 ? Eigen::Vector3d(face_normal[t] / length) : Eigen::Vector3d::Zero();
    });
    // Within rounding of the angle counts as under it: the two halves of a planar quad meet at a
    // cosine of 1 - 1e-16 rather than 1, and at 0 degrees must still be one fan (1e-9 in the cosine
    // is 0.003 degrees at 0).
    const double min_cos = std::cos(crease_angle_degrees * std::numbers::pi / 180.0) - 1e-9;
    const auto smooth = [&](int32_t t, int32_t u) {
        return unit_normal[t].isZero(0.0) || unit_normal[u].isZero(0.0) ||
               unit_normal[t].dot(unit_normal[u]) >= min_cos;
    };

    // Per vertex: the fans are the classes of "shares an edge through the vertex and is smooth with".
    // Written here rather than with OpenMesh's halfedge normals because the boundary of a tet mesh can be
    // non-manifold (two tets meeting at an edge or a vertex only), which a halfedge mesh cannot hold,
    // and because the renderer needs the map from each copy back to its surface vertex.
    const CompressedRows vertex_triangles = vertex_elements(surface.triangles, n);
    // Pass 1, parallel over vertices: the fan of each triangle around each vertex (corner_fan, aligned
    // with vertex_triangles.indices), numbered by first triangle, and the fan count per vertex.
    std::vector<int32_t> corner_fan(vertex_triangles.indices.size(), 0), fan_count(n, 1);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 512), [&](const tbb::blocked_range<size_t>& range) {
        DisjointSets fans_around;  // over the triangles around one vertex, reused
        std::vector<std::array<int32_t, 2>> others;
        for (size_t v = range.begin(); v != range.end(); ++v) {
            const int32_t begin = vertex_triangles.offsets[v], count = vertex_triangles.offsets[v + 1] - begin;
            if (count < 2) continue;
            const int32_t* around = vertex_triangles.indices.data() + begin;
            // The other two corners of each triangle around v: triangles sharing one share an edge with v.
            others.resize(count);
            for (int32_t i = 0; i < count; ++i) {
                const auto& tri = surface.triangles[around[i]];
                const int k = tri[0] == static_cast<int32_t>(v) ? 0 : tri[1] == static_cast<int32_t>(v) ? 1 : 2;
                others[i] = {tri[(k + 1) % 3], tri[(k + 2) % 3]};
            }
            fans_around.reset(count);
            for (int32_t i = 0; i < count; ++i) {
                const auto& oi = others[i];
                for (int32_t j = i + 1; j < count; ++j) {
                    const auto& oj = others[j];
                    const bool share_edge = oi[0] == oj[0] || oi[0] == oj[1] || oi[1] == oj[0] || oi[1] == oj[1];
                    if (share_edge && smooth(around[i], around[j])) fans_around.unite(i, j);
                }
            }
            fan_count[v] = fans_around.label_classes(std::span<int32_t>(corner_fan.data() + begin, count));
        }
    });
    // Where each split vertex's further copies start (after the surface's vertices, in vertex order).
    std::vector<int32_t> first_copy(n, -1);
    int32_t next = static_cast<int32_t>(n);
    for (size_t v = 0; v < n; ++v) {
        if (fan_count[v] < 2) continue;
        first_copy[v] = next;
        shading.split_copies.push_back(static_cast<int32_t>(v));
        for (int32_t f = 1; f < fan_count[v]; ++f) shading.split_copies.push_back(next++);
    }
    shading.surface_vertex.resize(next);
    shading.normals.resize(next);
    // Pass 2, parallel over split vertices: their copies' normals and the triangles' corners. Each
    // corner is written by its own vertex only.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 512), [&](const tbb::blocked_range<size_t>& range) {
        std::vector<Eigen::Vector3d> fan_normal;
        for (size_t v = range.begin(); v != range.end(); ++v) {
            if (fan_count[v] < 2) continue;
            const int32_t begin = vertex_triangles.offsets[v], count = vertex_triangles.offsets[v + 1] - begin;
            const auto copy = [&](int32_t f) { return f == 0 ? static_cast<int32_t>(v) : first_copy[v] + f - 1; };
            fan_normal.assign(fan_count[v], Eigen::Vector3d::Zero());
            for (int32_t i = 0; i < count; ++i) fan_normal[corner_fan[begin + i]] += face_normal[vertex_triangles.indices[begin + i]];
            for (int32_t f = 0; f < fan_count[v]; ++f) {
                const double length = fan_normal[f].norm();
                // A fan of degenerate triangles only has no normal of its own: it keeps the vertex's.
                shading.normals[copy(f)] = length > 0 ? Eigen::Vector3d(fan_normal[f] / length) : surface.normals[v];
                shading.surface_vertex[copy(f)] = static_cast<int32_t>(v);
            }
            for (int32_t i = 0; i < count; ++i) {
                if (corner_fan[begin + i] == 0) continue;
                for (int32_t& corner : shading.triangles[vertex_triangles.indices[begin + i]])
                    if (corner == static_cast<int32_t>(v)) corner = copy(corner_fan[begin + i]);
            }
        }
    });
    std::sort(shading.split_copies.begin(), shading.split_copies.end());
    return shading;
}

void update_split_copy_transfer(const BoundarySurface& surface, const ShadingSurface& shading, const TriangleBvh& bvh,
                                std::span<const int32_t> copies, EnvironmentTransfer& transfer, int samples) {
    if (transfer.size() != shading.split_copies.size())
        throw InvalidArgumentError("split copy transfer: " + std::to_string(transfer.size()) + " vectors for " +
                                   std::to_string(shading.split_copies.size()) + " split copies");
    for (const int32_t i : copies)
        if (i < 0 || static_cast<size_t>(i) >= shading.split_copies.size())
            throw InvalidArgumentError("split copy transfer: copy " + std::to_string(i) + " out of range");
    TransferSettings settings = transfer.settings();
    if (samples > 0) settings.samples = samples;
    Lighting lighting;
    lighting.shadows = settings.shadows;
    const std::vector<double> offset = shadow_ray_offsets(surface, lighting);
    tbb::parallel_for(size_t{0}, copies.size(), [&](size_t k) {
        const auto i = static_cast<size_t>(copies[k]);
        const int32_t copy = shading.split_copies[i];
        const int32_t s = shading.surface_vertex[copy];
        environment_transfer_at(surface.positions[s], shading.normals[copy], surface.eta[s], offset[s], bvh, settings,
                                transfer.at(i));
    });
}

EnvironmentTransfer split_copy_transfer(const BoundarySurface& surface, const ShadingSurface& shading,
                                        const TriangleBvh& bvh, const TransferSettings& settings) {
    EnvironmentTransfer transfer(settings, shading.split_copies.size());
    std::vector<int32_t> all(shading.split_copies.size());
    std::iota(all.begin(), all.end(), 0);
    update_split_copy_transfer(surface, shading, bvh, all, transfer);
    return transfer;
}

ShadingLight shading_light(const BoundarySurface& surface, const ShadingSurface& shading, const TriangleBvh& bvh,
                           const Lighting& lighting, const std::vector<Rgb>& surface_q,
                           const std::vector<float>& surface_visibility, const EnvironmentTransfer* copy_transfer) {
    validate(lighting);
    const size_t n = surface.positions.size(), lights = direct_lights(lighting).size();
    if (surface_q.size() != n || shading.normals.size() != shading.size() || shading.size() < n)
        throw InvalidArgumentError("shading_light: " + std::to_string(surface_q.size()) + " light values and " +
                                   std::to_string(shading.size()) + " shading vertices for a surface of " +
                                   std::to_string(n) + " vertices");
    if (!surface_visibility.empty() && surface_visibility.size() != n * lights)
        throw InvalidArgumentError("shading_light: " + std::to_string(surface_visibility.size()) +
                                   " visibility values for " + std::to_string(n) + " vertices and " +
                                   std::to_string(lights) + " lights");
    if (lighting.shadows && bvh.triangle_count() != surface.triangles.size())
        throw InvalidArgumentError("shading_light: the shadow BVH was not built from this surface");

    ShadingLight light;
    light.q.resize(shading.size());
    std::copy(surface_q.begin(), surface_q.end(), light.q.begin());
    if (!surface_visibility.empty()) {
        light.visibility.assign(shading.size() * lights, 1.0f);
        std::copy(surface_visibility.begin(), surface_visibility.end(), light.visibility.begin());
    }
    if (shading.split_copies.empty()) return light;
    const std::vector<double> offset = shadow_ray_offsets(surface, lighting);
    std::optional<EnvironmentTransfer> computed;
    if (lighting.environment && !copy_transfer) {
        TransferSettings settings;
        settings.order = lighting.environment->sh_order;
        settings.shadows = lighting.shadows;
        computed = split_copy_transfer(surface, shading, bvh, settings);
        copy_transfer = &*computed;
    }
    if (copy_transfer && copy_transfer->size() != shading.split_copies.size())
        throw InvalidArgumentError("shading_light: a transfer of " + std::to_string(copy_transfer->size()) +
                                   " vectors for " + std::to_string(shading.split_copies.size()) + " split copies");
    tbb::parallel_for(size_t{0}, shading.split_copies.size(), [&](size_t i) {
        const int32_t copy = shading.split_copies[i];
        const int32_t s = shading.surface_vertex[copy];
        float* visibility = light.visibility.empty() ? nullptr : light.visibility.data() + copy * lights;
        light.q[copy] = incident_light_at(surface.positions[s], shading.normals[copy], surface.eta[s], offset[s], bvh,
                                          lighting, visibility,
                                          copy_transfer ? copy_transfer->at(i) : std::span<const float>());
    });
    return light;
}

std::vector<Rgb> source_light(const BoundarySurface& surface, const ShadingSurface& shading,
                              const std::vector<Rgb>& shading_q) {
    const size_t n = surface.positions.size();
    if (shading_q.size() != shading.size() || shading.size() < n || shading.triangles.size() != surface.triangles.size())
        throw InvalidArgumentError("source_light: " + std::to_string(shading_q.size()) + " light values, " +
                                   std::to_string(shading.size()) + " shading vertices and " +
                                   std::to_string(shading.triangles.size()) + " shading triangles for a surface of " +
                                   std::to_string(n) + " vertices and " + std::to_string(surface.triangles.size()) +
                                   " triangles");
    std::vector<Rgb> q(shading_q.begin(), shading_q.begin() + static_cast<std::ptrdiff_t>(n));
    if (shading.split_copies.empty()) return q;

    // The fans' areas (the lumped S_f / 3 per corner; the 1/3 cancels in the mean). Only copies of
    // split vertices are read, so only triangles with such a corner are measured: along creases.
    std::vector<uint8_t> split(shading.size(), 0);
    for (const int32_t copy : shading.split_copies) split[static_cast<size_t>(copy)] = 1;
    std::vector<double> fan_area(shading.size(), 0.0);
    for (size_t t = 0; t < shading.triangles.size(); ++t) {
        const auto& corners = shading.triangles[t];
        if (!split[static_cast<size_t>(corners[0])] && !split[static_cast<size_t>(corners[1])] &&
            !split[static_cast<size_t>(corners[2])])
            continue;
        const auto& [a, b, c] = surface.triangles[t];
        const double area =
            0.5 * (surface.positions[b] - surface.positions[a]).cross(surface.positions[c] - surface.positions[a]).norm();
        for (const int32_t copy : corners) fan_area[static_cast<size_t>(copy)] += area;
    }
    // Every copy of a split vertex is listed, the first one being the vertex itself (< n).
    std::vector<Rgb> weighted(n, Rgb{0, 0, 0});
    std::vector<double> area(n, 0.0);
    for (const int32_t copy : shading.split_copies) {
        const auto s = static_cast<size_t>(shading.surface_vertex[copy]);
        const double w = fan_area[static_cast<size_t>(copy)];
        for (int ch = 0; ch < 3; ++ch) weighted[s][ch] += w * shading_q[static_cast<size_t>(copy)][ch];
        area[s] += w;
    }
    for (const int32_t copy : shading.split_copies) {
        if (static_cast<size_t>(copy) >= n) continue;  // each split vertex once, at its first copy
        const auto s = static_cast<size_t>(copy);
        if (area[s] > 0)  // else only degenerate triangles: no area to weigh by, keep the first copy's q
            for (int ch = 0; ch < 3; ++ch) q[s][ch] = weighted[s][ch] / area[s];
    }
    return q;
}

std::vector<CornerLight> corner_light(const BoundarySurface& surface, const ShadingSurface& shading,
                                      const std::vector<Rgb>& shading_q, const std::vector<Rgb>& q) {
    const size_t n = surface.positions.size();
    if (shading_q.size() != shading.size() || q.size() != n || shading.triangles.size() != surface.triangles.size() ||
        surface.triangle_tets.size() != surface.triangles.size())
        throw InvalidArgumentError("corner_light: " + std::to_string(shading_q.size()) + " shading and " +
                                   std::to_string(q.size()) + " vertex light values, " +
                                   std::to_string(shading.size()) + " shading vertices and " +
                                   std::to_string(shading.triangles.size()) + " shading triangles for a surface of " +
                                   std::to_string(n) + " vertices and " + std::to_string(surface.triangles.size()) +
                                   " triangles");
    std::vector<CornerLight> corners;
    if (shading.split_copies.empty()) return corners;
    std::vector<uint8_t> split(shading.size(), 0);
    for (const int32_t copy : shading.split_copies) split[static_cast<size_t>(copy)] = 1;
    for (size_t t = 0; t < shading.triangles.size(); ++t) {
        for (int k = 0; k < 3; ++k) {
            const auto copy = static_cast<size_t>(shading.triangles[t][k]);
            if (!split[copy]) continue;
            const auto& tri = surface.triangles[t];
            const auto s = static_cast<size_t>(tri[k]);
            CornerLight corner;
            for (int c = 0; c < 3; ++c) corner.delta[c] = shading_q[copy][c] - q[s][c];
            if (corner.delta == Rgb{0, 0, 0}) continue;
            corner.face = static_cast<int32_t>(t);
            corner.tet = surface.triangle_tets[t];
            for (int j = 0; j < 3; ++j) corner.vertices[j] = surface.vertices[tri[(k + j) % 3]];
            corners.push_back(corner);
        }
    }
    return corners;
}

}  // namespace waxwork
