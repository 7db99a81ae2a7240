#include "solver/reference/camera_rays.h"

#include "base/error.h"
#include "solver/material.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

namespace waxwork {

PixelCamera pixel_camera(const Eigen::Vector3d& eye, const Eigen::Matrix4d& view, const Eigen::Matrix4d& projection,
                         int width, int height) {
    if (width <= 0 || height <= 0) throw InvalidArgumentError("camera rays: the image size must be positive");
    if (!(projection(0, 0) > 0 && projection(1, 1) > 0) || projection(3, 2) != -1)
        throw InvalidArgumentError("camera rays: the projection must be a perspective one");
    PixelCamera camera;
    camera.eye = eye;
    camera.right = view.block<1, 3>(0, 0).transpose().normalized();
    camera.up = view.block<1, 3>(1, 0).transpose().normalized();
    camera.forward = -view.block<1, 3>(2, 0).transpose().normalized();
    camera.tan_half_width = 1.0 / projection(0, 0);
    camera.tan_half_height = 1.0 / projection(1, 1);
    camera.width = width;
    camera.height = height;
    return camera;
}

Eigen::Vector3d pixel_direction(const PixelCamera& camera, double px, double py) {
    const double x = (2 * px / camera.width - 1) * camera.tan_half_width;
    const double y = (1 - 2 * py / camera.height) * camera.tan_half_height;
    return (camera.forward + x * camera.right + y * camera.up).normalized();
}

FirstHitGrid surface_hit_grid(const BoundarySurface& surface) { return FirstHitGrid(surface.positions, surface.triangles); }

RadianceImage surface_radiance_image(const BoundarySurface& surface, const ShadingSurface& shading,
                                     const std::vector<std::array<float, 3>>& radiance_factor, const FirstHitGrid& grid,
                                     const PixelCamera& camera) {
    if (radiance_factor.size() != shading.size() || shading.triangles.size() != surface.triangles.size())
        throw InvalidArgumentError("camera rays: the radiance factors do not match the shading surface");
    RadianceImage image;
    image.width = camera.width;
    image.height = camera.height;
    const size_t pixels = static_cast<size_t>(camera.width) * camera.height;
    image.radiance.assign(pixels, {0, 0, 0});
    image.coverage.assign(pixels, 0.0f);
    tbb::parallel_for(0, camera.height, [&](int row) {
        for (int column = 0; column < camera.width; ++column) {
            const Eigen::Vector3d d = pixel_direction(camera, column + 0.5, row + 0.5);
            const auto hit = grid.first_hit(camera.eye, d);
            if (!hit) continue;
            const auto& corners = shading.triangles[hit->triangle];
            const auto& surface_corners = surface.triangles[hit->triangle];
            const double w[3] = {1.0 - hit->u - hit->v, hit->u, hit->v};
            Eigen::Vector3d normal = Eigen::Vector3d::Zero();
            double eta = 0;
            std::array<double, 3> e{};
            for (int k = 0; k < 3; ++k) {
                normal += w[k] * shading.normals[corners[k]];
                eta += w[k] * surface.eta[surface_corners[k]];
                for (int c = 0; c < 3; ++c) e[c] += w[k] * radiance_factor[corners[k]][c];
            }
            const double cos_view = -normal.normalized().dot(d);
            const double transmittance = fresnel_transmittance(cos_view, eta);
            const size_t p = static_cast<size_t>(row) * camera.width + column;
            for (int c = 0; c < 3; ++c) image.radiance[p][c] = transmittance * e[c];
            image.coverage[p] = 1.0f;
        }
    });
    return image;
}

}  // namespace waxwork
