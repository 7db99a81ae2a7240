#include "render/ground_plane.h"

#include "render/camera.h"
#include "render/surface_renderer.h"
#include "solver/environment_light.h"
#include "solver/ray_caster.h"

#include <Eigen/Geometry>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <numbers>

namespace waxwork {

namespace {

constexpr int kResolution = 256;
constexpr int kOcclusionRays = 16;
// Shadow rays per light and texel, spread over a cone of this half-angle (radians): a light of some
// size (the sun is 0.27 degrees across; a studio lamp more) gives a penumbra, and a soft edge does not
// show the texels as steps.
constexpr int kShadowRays = 4;
constexpr double kShadowCone = 0.03;
// In bounding radii: the texture reaches the shadows a low light casts nearby; the plane drawn
// reaches far enough that its edge, faded out, lies well behind the model.
constexpr float kTextureExtent = 3.0f;
constexpr float kPlaneExtent = 8.0f;

// Cosine-distributed directions about +y (Malley's method on a Fibonacci spiral): each carries the
// same share of a uniform sky's irradiance, so the unoccluded fraction is the fill's visibility.
std::array<Eigen::Vector3f, kOcclusionRays> occlusion_directions() {
    std::array<Eigen::Vector3f, kOcclusionRays> directions;
    const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
    for (int k = 0; k < kOcclusionRays; ++k) {
        const double r = std::sqrt((k + 0.5) / kOcclusionRays), phi = golden * k;
        directions[k] = Eigen::Vector3f(static_cast<float>(r * std::cos(phi)), static_cast<float>(std::sqrt(1 - r * r)),
                                        static_cast<float>(r * std::sin(phi)));
    }
    return directions;
}

}  // namespace

GroundPlane ground_plane(const SurfaceRenderInput& input) {
    GroundPlane plane;
    Eigen::AlignedBox3f box;
    for (const Eigen::Vector3f& p : input.positions) box.extend(p);
    if (box.isEmpty() || input.triangles.empty()) return plane;
    const float radius = std::max(static_cast<float>(bounding_radius(box.cast<double>())), 1e-6f);
    plane.height = box.min().y();
    plane.centre = Eigen::Vector2f(box.center().x(), box.center().z());
    plane.extent = kPlaneExtent * radius;
    plane.texture_extent = kTextureExtent * radius;
    plane.resolution = kResolution;
    plane.irradiance.assign(3 * static_cast<size_t>(kResolution) * kResolution, 0.0f);

    const TriangleBvh bvh(input.positions, input.triangles);
    const Lighting& lighting = input.lighting;
    // The fill: the ambient term plus a uniform sky of the environment's mean radiance, the band-0
    // spherical harmonic L00 times Y00 = 1 / (2 sqrt(pi)); a uniform sky gives irradiance pi L.
    std::array<double, 3> fill = lighting.ambient;
    if (lighting.environment) {
        const std::vector<Rgb> sh = environment_sh(*lighting.environment);
        for (int c = 0; c < 3; ++c) fill[c] += std::numbers::pi * sh[0][c] * 0.5 / std::sqrt(std::numbers::pi);
    }
    const auto directions = occlusion_directions();
    const float lift = 1e-4f * radius;  // rays start just above the plane, which the model may touch
    const float texel = 2 * plane.texture_extent / kResolution;
    tbb::parallel_for(0, kResolution, [&](int row) {
        for (int column = 0; column < kResolution; ++column) {
            const Eigen::Vector3f p(plane.centre.x() - plane.texture_extent + (column + 0.5f) * texel, plane.height + lift,
                                    plane.centre.y() - plane.texture_extent + (row + 0.5f) * texel);
            std::array<double, 3> e{};
            for (const Light& light : lighting.lights) {
                Eigen::Vector3d to_light;
                double scale = 1, t_max = 0;
                if (has_position(light.type)) {
                    to_light = light.vector - p.cast<double>();
                    const double d2 = to_light.squaredNorm();
                    if (!(d2 > 0)) continue;
                    scale = 1 / d2;
                    t_max = 1;
                } else {
                    to_light = -light.vector.normalized();
                    t_max = 4 * plane.extent;
                }
                const double cosine = to_light.normalized().y();
                if (!(cosine > 0)) continue;
                double visible = 1;
                if (lighting.shadows) {
                    // Four directions on a ring around the light's, turned per texel so that
                    // neighbouring texels sample the penumbra differently.
                    const Eigen::Vector3d u = to_light.unitOrthogonal(), v = to_light.normalized().cross(u);
                    int open_rays = 0;
                    for (int k = 0; k < kShadowRays; ++k) {
                        const double angle = 2 * std::numbers::pi * (k + 0.5 * ((row + column) % 2)) / kShadowRays;
                        const Eigen::Vector3d d =
                            to_light + kShadowCone * to_light.norm() * (std::cos(angle) * u + std::sin(angle) * v);
                        open_rays += !bvh.occluded(p, d.cast<float>(), 0.0f, static_cast<float>(t_max));
                    }
                    visible = static_cast<double>(open_rays) / kShadowRays;
                }
                for (int c = 0; c < 3; ++c) e[c] += light.intensity[c] * cosine * scale * visible;
            }
            int open = 0;
            for (const Eigen::Vector3f& d : directions) open += !bvh.occluded(p, d, 0.0f, 2 * radius);
            const double visible = static_cast<double>(open) / kOcclusionRays;
            float* out = plane.irradiance.data() + 3 * (static_cast<size_t>(row) * kResolution + column);
            for (int c = 0; c < 3; ++c) out[c] = static_cast<float>(e[c] + fill[c] * visible);
        }
    });
    return plane;
}

}  // namespace waxwork
