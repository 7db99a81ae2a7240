#include "bench/studies/transport_study.h"

#include "render/camera.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "solver/reference/camera_rays.h"
#include "solver/reference/monte_carlo.h"
#include "solver/reference/monte_carlo_image.h"
#include "solver/solved_scene.h"
#include "tetops/box_mesh.h"
#include "tetops/cut.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace waxwork {

namespace {

// Green: the channel the human eye weighs most (Rec. 709 luminance 0.72).
constexpr int kGreen = 1;
// The plates are this many times wider than thick (at least kPlateMinWidth mean free paths), so that
// their middle is a slab; kPlateCells cells across and kPlateLayers through.
constexpr double kPlateAspect = 8;
constexpr double kPlateMinWidth = 16;
constexpr int kPlateCells = 12;
constexpr int kPlateLayers = 3;

double transport_coefficient(const TetMaterial& m) { return m.mua[kGreen] + m.musp[kGreen]; }

Lighting study_lighting() {
    Lighting lighting;
    lighting.lights = {Light{LightType::Directional, Eigen::Vector3d(1, -1, -1), {1, 1, 1}}};
    return lighting;
}

TransportCase run_case(const TetMesh& mesh, const std::string& shape, const std::string& material_name,
                       double mm_per_unit, double size_mfp, const Eigen::Vector3d& eye_direction,
                       const TransportStudyOptions& o) {
    const TetMaterial material = material_preset(material_name);
    const std::vector<TetMaterial> materials(mesh.tet_count(), material);
    const TetConnectivity connectivity = build_connectivity(mesh);
    const Lighting lighting = study_lighting();
    DiffusionOptions diffusion;
    diffusion.mm_per_unit = mm_per_unit;
    const SolvedScene scene = solve_scene(mesh, connectivity, materials, lighting, diffusion);

    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3d& p : scene.surface.positions) box.extend(p);
    CameraSettings camera_settings;
    camera_settings.eye_direction = eye_direction;
    const CameraFrame frame = frame_camera(box, camera_settings, static_cast<double>(o.width) / o.height);
    const PixelCamera camera = pixel_camera(frame.eye, frame.view, frame.projection, o.width, o.height);
    const FirstHitGrid grid = surface_hit_grid(scene.surface);
    const RadianceImage live = surface_radiance_image(scene.surface, scene.shading, scene.radiance_factor, grid, camera);

    TransportCase result;
    result.shape = shape;
    result.material = material_name;
    result.mm_per_unit = mm_per_unit;
    result.size_mfp = size_mfp;
    result.albedo = material.musp[kGreen] / transport_coefficient(material);
    result.tets = static_cast<int64_t>(mesh.tet_count());
    result.live_ms = scene.diffusion.assembly_ms + scene.diffusion.solve_ms;

    const TriangleBvh bvh = build_shadow_bvh(scene.surface);
    const std::vector<PhotonSource> sources = photon_sources(scene.surface, bvh, lighting);
    MonteCarloOptions options;
    options.mm_per_unit = mm_per_unit;
    options.max_seconds = o.mc_seconds;
    options.seed = o.seed;
    const MonteCarloImage mc = trace_camera_image(
        mesh, connectivity, materials, scene.surface, grid, sources, camera, options, [&](const MonteCarloProgress& p) {
            result.convergence.emplace_back(p.seconds, *std::max_element(p.relative_error.begin(), p.relative_error.end()));
        });
    result.mc_seconds = mc.seconds;
    result.mc_paths = mc.paths;
    double error2 = 0, radiance2 = 0;
    for (size_t p = 0; p < mc.radiance_error.size(); ++p)
        for (int c = 0; c < 3; ++c) {
            error2 += mc.radiance_error[p][c] * mc.radiance_error[p][c];
            radiance2 += mc.image.radiance[p][c] * mc.image.radiance[p][c];
        }
    result.mc_noise = radiance2 > 0 ? std::sqrt(error2 / radiance2) : 0.0;
    result.difference =
        compare_radiance_images(live, radiance_image_exposure(live), mc.image, radiance_image_exposure(mc.image));
    if (o.progress) {
        char line[200];
        std::snprintf(line, sizeof line, "%s %s %.3g mm/unit %.3g mfp: relative L2 %.3f (scaled %.3f), noise %.3f",
                      shape.c_str(), material_name.c_str(), mm_per_unit, size_mfp, result.difference.relative_l2,
                      result.difference.scaled_relative_l2, result.mc_noise);
        o.progress(line);
    }
    return result;
}

}  // namespace

std::vector<TransportCase> run_transport_study(const TransportStudyOptions& o) {
    std::vector<TransportCase> cases;
    const Eigen::Vector3d front(0.7, 0.5, 1.0), back(-0.7, 0.5, -1.0);
    const int n = o.cube_cells;
    for (const std::string& name : o.materials) {
        const double mu = transport_coefficient(material_preset(name));
        const TetMesh cube = make_box_mesh({n, n, n}, Eigen::Vector3d::Constant(-0.5), Eigen::Vector3d::Constant(0.5));
        for (double scale : o.cube_scales) cases.push_back(run_case(cube, "cube", name, scale, scale * mu, front, o));
        // Plates in units of one transport mean free path, thin along z: the light falls on +z.
        for (double thickness : o.plate_thicknesses) {
            const double half = 0.5 * std::max(kPlateAspect * thickness, kPlateMinWidth);
            const TetMesh plate = make_box_mesh({kPlateCells, kPlateCells, kPlateLayers}, Eigen::Vector3d(-half, -half, -thickness / 2),
                                                Eigen::Vector3d(half, half, thickness / 2));
            cases.push_back(run_case(plate, "plate, lit side", name, 1 / mu, thickness, front, o));
            cases.push_back(run_case(plate, "plate, far side", name, 1 / mu, thickness, back, o));
        }
        // A corner cut off (remove mode: the cross-section is made of tet faces), seen on the cut.
        TetMesh cut = cube;
        remove_cut_away_tets(cut, PlaneCut(Eigen::Vector3d(0.7, 0.5, 1.0), 0.15));
        cases.push_back(run_case(cut, "cut cube", name, o.cut_scale, o.cut_scale * mu, front, o));
    }
    return cases;
}

double model_error(const TransportCase& r) {
    const double scaled = r.difference.scaled_relative_l2;
    return std::sqrt(std::max(0.0, scaled * scaled - r.mc_noise * r.mc_noise));
}

nlohmann::ordered_json to_json(const TransportCase& r) {
    nlohmann::ordered_json convergence = nlohmann::ordered_json::array();
    for (const auto& [seconds, error] : r.convergence) convergence.push_back({seconds, error});
    return {{"shape", r.shape},
            {"material", r.material},
            {"mm_per_unit", r.mm_per_unit},
            {"size_mfp", r.size_mfp},
            {"albedo", r.albedo},
            {"tets", r.tets},
            {"live_ms", r.live_ms},
            {"mc_seconds", r.mc_seconds},
            {"mc_paths", r.mc_paths},
            {"mc_noise", r.mc_noise},
            {"relative_l2", r.difference.relative_l2},
            {"scaled_relative_l2", r.difference.scaled_relative_l2},
            {"mc_over_live", r.difference.scale},
            {"excess", model_error(r)},
            {"psnr_db", r.difference.psnr_db},
            {"pixels", r.difference.pixels},
            {"convergence", convergence}};
}

std::string transport_table_markdown(const std::vector<TransportCase>& cases) {
    std::string out =
        "Live image (TransCut, Eq. 3) against the Monte Carlo image, over the pixels both cover. relative L2: "
        "sqrt(sum |live - MC|^2 / sum |MC|^2) in linear radiance, all channels; scaled: the same after the one "
        "factor that fits best (MC/live), i.e. the error of the light's distribution; PSNR: the two images as "
        "shown, each at its own automatic exposure; noise: the MC image's own relative standard error; "
        "excess: sqrt(scaled^2 - noise^2), the part of the scaled error the noise does not explain. Size: "
        "the cube's side or the plate's thickness in transport mean free paths 1/(mu_a + mu_s'), green; albedo "
        "mu_s'/(mu_a + mu_s'), green.\n\n"
        "| shape | material | mm/unit | size (mfp) | albedo | relative L2 | scaled | noise | excess | MC/live | PSNR (dB) | MC s | live ms |\n"
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    char row[400];
    for (const TransportCase& r : cases) {
        std::snprintf(row, sizeof row, "| %s | %s | %.3g | %.3g | %.4f | %.3f | %.3f | %.3f | %.3f | %.3f | %.1f | %.1f | %.1f |\n",
                      r.shape.c_str(), r.material.c_str(), r.mm_per_unit, r.size_mfp, r.albedo, r.difference.relative_l2,
                      r.difference.scaled_relative_l2, r.mc_noise, model_error(r), r.difference.scale,
                      r.difference.psnr_db, r.mc_seconds, r.live_ms);
        out += row;
    }
    return out;
}

}  // namespace waxwork
