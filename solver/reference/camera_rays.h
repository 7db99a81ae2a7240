// Pixel rays of a pinhole camera and the image the live renderer draws, in linear radiance on the CPU:
// what the Monte Carlo image (monte_carlo_image.h) is traced through and compared with, pixel for pixel.
// The camera is given by its view and projection matrices (render/camera.h frames them), so these
// rays pass through the same pixels as the rasteriser's.
#pragma once

#include "solver/lighting.h"
#include "solver/reference/first_hit_grid.h"
#include "solver/shading_surface.h"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace waxwork {

struct PixelCamera {
    Eigen::Vector3d eye = Eigen::Vector3d::Zero();
    Eigen::Vector3d forward = Eigen::Vector3d(0, 0, -1), right = Eigen::Vector3d(1, 0, 0), up = Eigen::Vector3d(0, 1, 0);
    // The image plane at distance 1 spans [-tan_half_width, tan_half_width] x [-tan_half_height, ...].
    double tan_half_width = 1, tan_half_height = 1;
    int width = 1, height = 1;
};

// From an OpenGL look-at view matrix (rows right, up, -forward) and a perspective projection.
// Throws InvalidArgumentError for a non-positive image size or a projection that is not perspective.
PixelCamera pixel_camera(const Eigen::Vector3d& eye, const Eigen::Matrix4d& view, const Eigen::Matrix4d& projection,
                         int width, int height);

// Unit world direction through the image point (px, py), in pixels from the top-left corner (the
// centre of pixel (i, j) is (i + 0.5, j + 0.5)).
Eigen::Vector3d pixel_direction(const PixelCamera& camera, double px, double py);

// Linear radiance per pixel, row-major, top row first.
struct RadianceImage {
    int width = 0, height = 0;
    // The mean radiance of the samples of the pixel that hit the object (zero where none did).
    std::vector<std::array<double, 3>> radiance;
    // The fraction of the pixel's samples that hit the object.
    std::vector<float> coverage;
};

// The grid of the surface's triangles (world space) that camera rays are cast against.
FirstHitGrid surface_hit_grid(const BoundarySurface& surface);

// The subsurface term of the live image, L_o = F_t(theta_o) E (solver/radiance.h, Eq. 3), through the
// pixel centres: E interpolated over the hit triangle's shading vertices, theta_o from the
// interpolated shading normal, eta from the surface's vertices, as the renderer's fragment shader
// does; no highlight, no tone mapping. `grid` is surface_hit_grid(surface); `radiance_factor` one per
// shading vertex. Coverage is 0 or 1 (one sample per pixel). Parallel over rows (TBB).
RadianceImage surface_radiance_image(const BoundarySurface& surface, const ShadingSurface& shading,
                                     const std::vector<std::array<float, 3>>& radiance_factor, const FirstHitGrid& grid,
                                     const PixelCamera& camera);

}  // namespace waxwork
