// The live image's absolute brightness against radiative transport where diffusion holds: a thick,
// high-albedo slab lit straight down and seen straight down. The live image is Eq. 3 from the solved
// phi (solver/radiance.h, with the boundary's 1 / eta^2); the reference is the camera-ray Monte Carlo
// image of the same volume and light (solver/reference/monte_carlo_image.h). Without the 1 / eta^2 the
// live image is eta^2 too bright (2.25 at eta 1.5), which this test tells apart from agreement.
#include "solver/lighting.h"
#include "solver/reference/camera_rays.h"
#include "solver/reference/monte_carlo.h"
#include "solver/reference/monte_carlo_image.h"
#include "solver/solved_scene.h"
#include "tetops/box_mesh.h"
#include "tetops/connectivity.h"

#include "monte_carlo_volume.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace waxwork {
namespace {

// The mean radiance (green) over the pixels the image covers fully, and its standard error.
struct Mean {
    double value = 0, error = 0;
};
Mean mean_green(const RadianceImage& image, const std::vector<std::array<double, 3>>& errors) {
    Mean m;
    double error2 = 0;
    int n = 0;
    for (size_t p = 0; p < image.radiance.size(); ++p) {
        if (image.coverage[p] < 1) continue;
        m.value += image.radiance[p][1];
        if (!errors.empty()) error2 += errors[p][1] * errors[p][1];
        ++n;
    }
    if (n == 0) return m;
    m.value /= n;
    m.error = std::sqrt(error2) / n;
    return m;
}

TEST(LiveAgainstTransport, ThickHighAlbedoSlabHasTheTracedBrightness) {
    // 400 x 400 x 40 mm: the centre is 200 mm (about 35 diffusion lengths, 1 / sqrt(3 mu_a mu_t'))
    // from the sides, and the light decays within a few of the 1 mm layers under the top.
    const TetMesh mesh = make_box_mesh({8, 8, 40}, Eigen::Vector3d(-200, -200, -40), Eigen::Vector3d(200, 200, 0));
    const TetConnectivity connectivity = build_connectivity(mesh);
    Lighting lighting;
    lighting.lights = {Light{LightType::Directional, Eigen::Vector3d(0, 0, -1), {1, 1, 1}}};
    DiffusionOptions diffusion;
    diffusion.mm_per_unit = 1;
    diffusion.relative_tolerance = 1e-6;
    for (double eta : {1.3, 1.5}) {
        // Reduced albedo 0.99: the edge of the regime where the study trusts diffusion.
        const std::vector<TetMaterial> materials(mesh.tet_count(), test::uniform_material(0.01, 1.0, eta));
        const SolvedScene scene = solve_scene(mesh, connectivity, materials, lighting, diffusion);
        PixelCamera camera;
        camera.eye = Eigen::Vector3d(0, 0, 100);
        camera.forward = Eigen::Vector3d(0, 0, -1);
        camera.right = Eigen::Vector3d(1, 0, 0);
        camera.up = Eigen::Vector3d(0, 1, 0);
        camera.tan_half_width = camera.tan_half_height = 0.05;  // a 10 mm patch at the centre
        camera.width = camera.height = 4;
        const FirstHitGrid grid = surface_hit_grid(scene.surface);
        const RadianceImage live = surface_radiance_image(scene.surface, scene.shading, scene.radiance_factor, grid, camera);
        const TriangleBvh bvh = build_shadow_bvh(scene.surface);
        MonteCarloOptions options;
        options.max_photons = 8000;
        const MonteCarloImage mc = trace_camera_image(mesh, connectivity, materials, scene.surface, grid,
                                                      photon_sources(scene.surface, bvh, lighting), camera, options);
        const Mean traced = mean_green(mc.image, mc.radiance_error), shown = mean_green(live, {});
        const double ratio = shown.value / traced.value, error = traced.error / traced.value;
        std::printf("eta %.1f: live %.5f, traced %.5f (standard error %.3f): live / traced %.3f\n", eta, shown.value,
                    traced.value, error, ratio);
        EXPECT_LT(error, 0.04);
        // Diffusion misses the single scattering and is approximate at the boundary: within 15 %,
        // where a missing 1 / eta^2 would be 69 % (eta 1.3) or 125 % (1.5) too bright.
        EXPECT_NEAR(ratio, 1.0, 0.15) << "eta " << eta;
    }
}

}  // namespace
}  // namespace waxwork
