#include "solver/lighting.h"

#include "base/error.h"
#include "solver/area_light.h"
#include "solver/environment_transfer.h"
#include "solver/material.h"
#include "solver/radiance.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <numbers>
#include <string>

namespace waxwork {

namespace {

std::string light_name(size_t index, const Light& light) {
    return std::string("light ") + std::to_string(index) + " (" + light_type_name(light.type) + ")";
}

bool within_light_range(const Eigen::Vector3d& v) {
    return v.allFinite() && v.cwiseAbs().maxCoeff() <= kMaxLightValue;
}

// The checks only area lights need: their shape.
void validate_area_light(size_t index, const Light& light) {
    const auto fail = [&](const std::string& why) { throw InvalidArgumentError(light_name(index, light) + ": " + why); };
    const auto valid_length = [](double x) { return x > 0 && x <= kMaxLightValue; };
    if (light.type == LightType::Rectangle) {
        if (!valid_length(light.size.x()) || !valid_length(light.size.y()))
            fail("width and height must be positive and at most 1e100");
    } else if (!valid_length(light.size.x())) {
        fail("radius must be positive and at most 1e100");
    }
    if (light.type == LightType::Sphere) return;
    if (!within_light_range(light.axis) || light.axis.cwiseAbs().maxCoeff() == 0.0)
        fail("axis is the zero vector, has a non-finite component or one beyond 1e100");
    if (light.type == LightType::Rectangle) {
        if (!within_light_range(light.tangent) || !tangent_spans_plane(light.axis, light.tangent))
            fail("tangent is the zero vector, non-finite, or parallel to the axis");
    }
}

// Non-negative and at most kMaxLightIntensity (so finite).
bool valid_light_value(const Rgb& c) {
    for (double x : c) {
        if (!(x >= 0 && x <= kMaxLightIntensity)) return false;
    }
    return true;
}

// Shadow-ray origins sit this fraction of the local mean edge length off the surface along the normal:
// far enough that float round-off cannot make the ray hit the faces around its own vertex, close
// enough that contact shadows between touching pieces survive.
constexpr double kShadowOffset = 1e-2;

}  // namespace

const char* light_type_name(LightType type) {
    switch (type) {
    case LightType::Directional: return "directional";
    case LightType::Point: return "point";
    case LightType::Rectangle: return "rect";
    case LightType::Disk: return "disk";
    case LightType::Sphere: return "sphere";
    }
    return "unknown";
}

Eigen::Vector3d default_rect_tangent(const Eigen::Vector3d& axis) {
    const Eigen::Vector3d n = axis.stableNormalized();
    const Eigen::Vector3d along = std::abs(n.x()) > 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
    return (along - along.dot(n) * n).normalized();
}

bool tangent_spans_plane(const Eigen::Vector3d& axis, const Eigen::Vector3d& tangent) {
    // Parallel when what is left of the unit tangent after removing its part along the unit axis is
    // too short to give a direction.
    return tangent.allFinite() && tangent.cwiseAbs().maxCoeff() > 0.0 &&
           axis.stableNormalized().cross(tangent.stableNormalized()).norm() > 1e-6;
}

void validate(const Lighting& lighting) {
    for (size_t i = 0; i < lighting.lights.size(); ++i) {
        const Light& light = lighting.lights[i];
        if (light.type != LightType::Directional && light.type != LightType::Point && !is_area_light(light.type)) {
            throw InvalidArgumentError(light_name(i, light) + ": unknown light type");
        }
        if (!within_light_range(light.vector)) {
            throw InvalidArgumentError(light_name(i, light) +
                                       (light.type == LightType::Directional ? ": direction"
                                        : light.type == LightType::Point     ? ": position"
                                                                             : ": center") +
                                       " has a non-finite component or one beyond 1e100");
        }
        if (light.type == LightType::Directional && light.vector.squaredNorm() == 0.0) {
            throw InvalidArgumentError(light_name(i, light) + ": direction is the zero vector");
        }
        if (!valid_light_value(light.intensity)) {
            throw InvalidArgumentError(light_name(i, light) + ": intensity must be non-negative and at most 1e15");
        }
        if (is_area_light(light.type)) validate_area_light(i, light);
    }
    if (!valid_light_value(lighting.ambient)) {
        throw InvalidArgumentError("ambient light must be non-negative and at most 1e15");
    }
    if (lighting.environment) validate(*lighting.environment);
}

std::vector<Light> direct_lights(const Lighting& lighting) {
    std::vector<Light> lights = lighting.lights;
    if (lighting.environment && lighting.environment->sky) {
        const EnvironmentLight& environment = *lighting.environment;
        Light sun;
        sun.type = LightType::Directional;
        sun.vector = -(Eigen::AngleAxisd(environment.rotation_degrees * std::numbers::pi / 180, Eigen::Vector3d::UnitY()) *
                       sun_direction(*environment.sky));
        sun.intensity = sun_irradiance(*environment.sky);
        for (double& c : sun.intensity) c *= environment.intensity;
        lights.push_back(sun);
    }
    return lights;
}

std::vector<Eigen::Vector3d> area_weighted_normals(const std::vector<Eigen::Vector3d>& positions,
                                                   const std::vector<std::array<int32_t, 3>>& triangles) {
    std::vector<Eigen::Vector3d> normals(positions.size(), Eigen::Vector3d::Zero());
    // The cross product is twice the area times the unit normal: summing it weights by area.
    for (const auto& t : triangles) {
        const Eigen::Vector3d n = (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]);
        for (int32_t v : t) normals[v] += n;
    }
    tbb::parallel_for(size_t{0}, normals.size(), [&](size_t i) {
        const double length = normals[i].norm();
        normals[i] = length > 0 ? Eigen::Vector3d(normals[i] / length) : Eigen::Vector3d::Zero();
    });
    return normals;
}

BoundarySurface extract_boundary_surface(const TetMesh& mesh, const TetConnectivity& connectivity,
                                         const std::vector<TetMaterial>& materials, double default_eta) {
    if (!materials.empty() && materials.size() != mesh.tet_count()) {
        throw InvalidArgumentError("extract_boundary_surface: " + std::to_string(materials.size()) +
                                   " materials for " + std::to_string(mesh.tet_count()) + " tets");
    }
    BoundarySurface surface;
    surface.vertices = connectivity.boundary_vertices;
    const size_t n = surface.vertices.size();
    std::vector<int32_t> surface_index(mesh.vertex_count(), -1);
    for (size_t s = 0; s < n; ++s) surface_index[surface.vertices[s]] = static_cast<int32_t>(s);

    surface.triangles.reserve(connectivity.boundary_faces.size());
    surface.triangle_tets.reserve(connectivity.boundary_faces.size());
    // A vertex belongs to exactly one piece (fracture duplicates shared vertices), so any of its
    // boundary faces tells which transform moves it.
    std::vector<int32_t> piece(n, 0);
    for (const BoundaryFace& face : connectivity.boundary_faces) {
        std::array<int32_t, 3> tri;
        for (int k = 0; k < 3; ++k) {
            const int32_t s = surface_index[face.vertices[k]];
            tri[k] = s;
            piece[s] = mesh.piece_ids.empty() ? 0 : mesh.piece_ids[face.tet];
        }
        surface.triangles.push_back(tri);
        surface.triangle_tets.push_back(face.tet);
    }

    surface.positions.resize(n);
    surface.eta.resize(n);
    // The same per-vertex eta as the exitant radiance (solver/radiance.h), so q and L_o agree.
    const std::vector<double> vertex_eta =
        materials.empty() ? std::vector<double>() : boundary_vertex_eta(mesh, connectivity, materials);
    tbb::parallel_for(size_t{0}, n, [&](size_t s) {
        const Eigen::Vector3d& rest = mesh.positions[surface.vertices[s]];
        if (static_cast<size_t>(piece[s]) < mesh.piece_transforms.size()) {
            const RigidTransform& transform = mesh.piece_transforms[piece[s]];
            surface.positions[s] = transform.rotation * rest + transform.translation;
        } else {
            surface.positions[s] = rest;
        }
        surface.eta[s] = materials.empty() ? default_eta : vertex_eta[surface.vertices[s]];
    });
    surface.normals = area_weighted_normals(surface.positions, surface.triangles);
    return surface;
}

namespace {

std::vector<Eigen::Vector3f> float_points(const BoundarySurface& surface) {
    std::vector<Eigen::Vector3f> points(surface.positions.size());
    for (size_t i = 0; i < points.size(); ++i) points[i] = surface.positions[i].cast<float>();
    return points;
}

}  // namespace

TriangleBvh build_shadow_bvh(const BoundarySurface& surface) { return TriangleBvh(float_points(surface), surface.triangles); }

void refit_shadow_bvh(TriangleBvh& bvh, const BoundarySurface& surface) {
    if (bvh.triangle_count() != surface.triangles.size())
        throw InvalidArgumentError("refit_shadow_bvh: the tree has " + std::to_string(bvh.triangle_count()) +
                                   " triangles, the surface " + std::to_string(surface.triangles.size()));
    bvh.refit(float_points(surface));
}

namespace {

void check_lighting_inputs(const BoundarySurface& surface, const TriangleBvh& bvh, const Lighting& lighting) {
    validate(lighting);
    const size_t n = surface.positions.size();
    if (surface.normals.size() != n || surface.eta.size() != n) {
        throw InvalidArgumentError("incident_light: surface has " + std::to_string(n) + " positions, " +
                                   std::to_string(surface.normals.size()) + " normals and " +
                                   std::to_string(surface.eta.size()) + " eta values");
    }
    if (lighting.shadows && bvh.triangle_count() != surface.triangles.size()) {
        throw InvalidArgumentError("incident_light: the shadow BVH was not built from this surface");
    }
}

}  // namespace

std::vector<double> shadow_ray_offsets(const BoundarySurface& surface, const Lighting& lighting) {
    const size_t n = surface.positions.size();
    std::vector<double> offset(n, 0.0);
    if (!lighting.shadows) return offset;
    std::vector<int32_t> count(n, 0);
    for (const auto& t : surface.triangles) {
        for (int k = 0; k < 3; ++k) {
            const double length = (surface.positions[t[k]] - surface.positions[t[(k + 1) % 3]]).norm();
            offset[t[k]] += length;
            offset[t[(k + 1) % 3]] += length;
            ++count[t[k]];
            ++count[t[(k + 1) % 3]];
        }
    }
    for (size_t s = 0; s < n; ++s) {
        if (count[s] > 0) offset[s] *= kShadowOffset / count[s];
    }
    return offset;
}

namespace {

// ambient plus the direct lights (no environment) at one point.
Rgb direct_light_at(const Eigen::Vector3d& position, const Eigen::Vector3d& normal, double eta, double shadow_offset,
                    const TriangleBvh& bvh, const Lighting& lighting, std::span<const Light> lights, float* visibility) {
    Rgb sum = lighting.ambient;
    const Eigen::Vector3f origin = (position + shadow_offset * normal).cast<float>();
    for (size_t l = 0; l < lights.size(); ++l) {
        const Light& light = lights[l];
        if (visibility) visibility[l] = 1.0f;
        if (is_area_light(light.type)) {
            const AreaLightEstimate area =
                estimate_area_light(light, position, normal, eta, origin, lighting.shadows ? &bvh : nullptr);
            if (visibility) visibility[l] = area.visibility;
            for (int c = 0; c < 3; ++c) sum[c] += light.intensity[c] * area.factor;
            continue;
        }
        Eigen::Vector3d to_light;
        double scale = 1.0;
        double distance = std::numeric_limits<double>::infinity();
        if (light.type == LightType::Directional) {
            to_light = -light.vector.normalized();
        } else {
            to_light = light.vector - position;
            distance = to_light.norm();
            if (!(distance > 0)) continue;  // light on the vertex: no direction
            to_light /= distance;
            scale = 1.0 / (distance * distance);
        }
        const double cos_theta = normal.dot(to_light);
        if (!(cos_theta > 0)) continue;
        if (lighting.shadows) {
            // The ray stops just short of a point light so that a light lying on a surface
            // does not shadow itself.
            const float t_max = std::isinf(distance) ? std::numeric_limits<float>::infinity()
                                                     : static_cast<float>(distance * (1.0 - 1e-6));
            if (bvh.occluded(origin, to_light.cast<float>(), 0.0f, t_max)) {
                if (visibility) visibility[l] = 0.0f;
                continue;
            }
        }
        const double factor = scale * cos_theta * fresnel_transmittance(cos_theta, eta);
        for (int c = 0; c < 3; ++c) sum[c] += light.intensity[c] * factor;
    }
    return sum;
}

void add(Rgb& sum, const Rgb& value) {
    for (int c = 0; c < 3; ++c) sum[c] += value[c];
}

TransferSettings transfer_settings(const Lighting& lighting) {
    TransferSettings settings;
    settings.order = lighting.environment->sh_order;
    settings.shadows = lighting.shadows;
    return settings;
}

// The transfer incident_light uses: the caller's, checked, or one computed for the surface.
const EnvironmentTransfer& environment_transfer(const BoundarySurface& surface, const TriangleBvh& bvh,
                                                const Lighting& lighting, const EnvironmentTransfer* given,
                                                std::optional<EnvironmentTransfer>& computed) {
    if (given) {
        if (given->size() != surface.positions.size() || given->settings().order != lighting.environment->sh_order)
            throw InvalidArgumentError("incident_light: the environment transfer was not computed for this surface and order");
        return *given;
    }
    computed = compute_environment_transfer(surface, bvh, transfer_settings(lighting));
    return *computed;
}

}  // namespace

Rgb incident_light_at(const Eigen::Vector3d& position, const Eigen::Vector3d& normal, double eta,
                      double shadow_offset, const TriangleBvh& bvh, const Lighting& lighting, float* visibility,
                      std::span<const float> environment_transfer) {
    const std::vector<Light> lights = direct_lights(lighting);
    Rgb sum = direct_light_at(position, normal, eta, shadow_offset, bvh, lighting, lights, visibility);
    if (lighting.environment) {
        EnvironmentTransfer transfer(transfer_settings(lighting), 1);
        if (environment_transfer.empty()) {
            environment_transfer_at(position, normal, eta, shadow_offset, bvh, transfer.settings(), transfer.at(0));
        } else {
            if (environment_transfer.size() != static_cast<size_t>(transfer.coefficients()))
                throw InvalidArgumentError("incident_light_at: a transfer of " + std::to_string(environment_transfer.size()) +
                                           " coefficients for an environment of order " +
                                           std::to_string(lighting.environment->sh_order));
            std::copy(environment_transfer.begin(), environment_transfer.end(), transfer.at(0).begin());
        }
        add(sum, transfer.apply(0, environment_sh(*lighting.environment)));
    }
    return sum;
}

std::vector<Rgb> incident_light(const BoundarySurface& surface, const TriangleBvh& bvh, const Lighting& lighting,
                                std::vector<float>* visibility, const EnvironmentTransfer* transfer) {
    check_lighting_inputs(surface, bvh, lighting);
    const size_t n = surface.positions.size();
    const std::vector<Light> lights = direct_lights(lighting);
    const std::vector<double> offset = shadow_ray_offsets(surface, lighting);
    std::vector<Rgb> q(n);
    if (visibility) visibility->assign(n * lights.size(), 1.0f);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t s = range.begin(); s != range.end(); ++s) {
            float* v = visibility ? visibility->data() + s * lights.size() : nullptr;
            q[s] = direct_light_at(surface.positions[s], surface.normals[s], surface.eta[s], offset[s], bvh, lighting,
                                   lights, v);
        }
    });
    if (lighting.environment) {
        std::optional<EnvironmentTransfer> computed;
        const std::vector<Rgb> q_env = apply_environment_transfer(
            environment_transfer(surface, bvh, lighting, transfer, computed), *lighting.environment);
        for (size_t s = 0; s < n; ++s) add(q[s], q_env[s]);
    }
    return q;
}

void update_incident_light(const BoundarySurface& surface, const TriangleBvh& bvh, const Lighting& lighting,
                           std::span<const int32_t> surface_vertices, std::vector<Rgb>& q,
                           const EnvironmentTransfer* transfer) {
    check_lighting_inputs(surface, bvh, lighting);
    if (q.size() != surface.positions.size())
        throw InvalidArgumentError("update_incident_light: q has " + std::to_string(q.size()) + " values for " +
                                   std::to_string(surface.positions.size()) + " surface vertices");
    for (const int32_t s : surface_vertices)
        if (s < 0 || static_cast<size_t>(s) >= q.size())
            throw InvalidArgumentError("update_incident_light: surface vertex " + std::to_string(s) + " out of range");
    const std::vector<Light> lights = direct_lights(lighting);
    const std::vector<double> offset = shadow_ray_offsets(surface, lighting);
    std::optional<EnvironmentTransfer> computed;
    std::vector<Rgb> environment;
    const EnvironmentTransfer* used = nullptr;
    if (lighting.environment) {
        if (transfer) {
            used = &environment_transfer(surface, bvh, lighting, transfer, computed);
        } else {
            computed.emplace(transfer_settings(lighting), surface.positions.size());
            update_environment_transfer(surface, bvh, surface_vertices, *computed);
            used = &*computed;
        }
        environment = environment_sh(*lighting.environment);
    }
    tbb::parallel_for(tbb::blocked_range<size_t>(0, surface_vertices.size(), 64),
                      [&](const tbb::blocked_range<size_t>& range) {
                          for (size_t i = range.begin(); i != range.end(); ++i) {
                              const size_t s = static_cast<size_t>(surface_vertices[i]);
                              q[s] = direct_light_at(surface.positions[s], surface.normals[s], surface.eta[s], offset[s],
                                                     bvh, lighting, lights, nullptr);
                              if (used) add(q[s], used->apply(s, environment));
                          }
                      });
}

std::vector<Rgb> incident_light(const BoundarySurface& surface, const Lighting& lighting,
                                std::vector<float>* visibility) {
    validate(lighting);
    const TriangleBvh bvh = lighting.shadows ? build_shadow_bvh(surface) : TriangleBvh();
    return incident_light(surface, bvh, lighting, visibility);
}

std::vector<Rgb> incident_light(const TetMesh& mesh, const TetConnectivity& connectivity,
                                const std::vector<TetMaterial>& materials, const Lighting& lighting) {
    const BoundarySurface surface = extract_boundary_surface(mesh, connectivity, materials);
    return to_volume_vertices(surface, incident_light(surface, lighting), mesh.vertex_count());
}

std::vector<Rgb> to_volume_vertices(const BoundarySurface& surface, const std::vector<Rgb>& values,
                                    size_t volume_vertex_count) {
    if (values.size() != surface.vertices.size()) {
        throw InvalidArgumentError("to_volume_vertices: " + std::to_string(values.size()) + " values for " +
                                   std::to_string(surface.vertices.size()) + " surface vertices");
    }
    std::vector<Rgb> result(volume_vertex_count, Rgb{0, 0, 0});
    for (size_t s = 0; s < values.size(); ++s) result[surface.vertices[s]] = values[s];
    return result;
}

}  // namespace waxwork
