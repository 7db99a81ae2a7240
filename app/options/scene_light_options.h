// The options that decide the light a volume shows, shared by the commands that solve it converged
// (`render`, `export --radiance`), so both light a volume the same way from the same words:
//   --material NAME | --mua R,G,B --musp R,G,B --eta N, --light SPEC...,
//   --method transcut|fem|fd|fd-cg|fvm|fvm-cg|lbm|dipole, --cell MM,
//   --env SPEC, --tol T, --backend cpu|gpu, --scale S, --ambient A, --crease-angle DEG
#pragma once

#include "app/options/material_options.h"
#include "render/volume_render.h"
#include "solver/light_spec.h"
#include "solver/lighting.h"
#include "solver/shading_surface.h"

#include "io/volume_file.h"
#include "tetops/model_scale.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace waxwork {

inline constexpr double kTransCutTolerance = 1e-2;
inline constexpr double kAlternativeTolerance = 1e-4;

struct SceneLightOptions {
    MaterialOptions material;
    std::vector<std::string> lights;
    std::string environment;  // --env: FILE.hdr[:ROT[:INTENSITY]] or sky:ELEV,AZIM[,TURBIDITY][:ROT[:INTENSITY]]
    bool hide_environment = false;  // --no-env-background: the environment lights but is not drawn
    std::string method = "transcut";
    // --tol; nullopt: the method's default. TransCut's is kTransCutTolerance = 1e-2: the resolution
    // study (`waxwork bench --only resolution`; docs/accuracy.md) finds the image at 1e-2 within 0.05%
    // of the image at 1e-3 on spot at 3 and 30 mm per unit, while 1e-1 is visibly off (1-4%); the
    // estimate bounds the true error from above, so the fluence itself is typically closer than 1e-2.
    // The seeds' alternative methods (--method fd, lbm, ...) stop on a relative change or residual,
    // which at 1e-2 leaves a relaxation far from converged: theirs is kAlternativeTolerance.
    std::optional<double> tolerance;
    // --cell: the grid methods' (fd, lbm) cell size in mm; nullopt: default_cell_mm.
    std::optional<double> cell_mm;
    std::optional<double> scale;  // nullopt: the volume's stored scale, else chosen from its size
    std::optional<double> ambient;  // nullopt: kDefaultAmbient, or 0 under an environment
    double crease_angle = kDefaultCreaseAngleDegrees;
    std::string backend = "cpu";
};

// Registers the options on `command`. With `monte_carlo`, --method also takes mc (the command traces
// the light instead of solving the diffusion; see render).
void add_scene_light_options(CLI::App& command, SceneLightOptions& options, bool monte_carlo = false);

// Throws InvalidArgumentError for a scale, tolerance, ambient or crease angle out of range. Physically
// meaningless values are refused before any work: a scale beyond validate_mm_per_unit's bounds is a
// unit error (a nanometre or a kilometre per model unit), not a scene.
void check_scene_light_options(const SceneLightOptions& options);

// The lights the options name (render's key light when there are none and no environment), the
// environment (its .hdr file read here: FileError naming it when it cannot be), and the ambient term.
Lighting chosen_lighting(const SceneLightOptions& options);

// The solve's part of render_volume's settings: material, lighting, diffusion (at `scale`) and crease
// angle; the image and view stay at their defaults. --method mc gives TransCut's settings: the
// command solves the diffusion for the surface, its light and a comparison, then traces.
VolumeRenderSettings scene_light_settings(const SceneLightOptions& options, const ModelScale& scale);

// The scale a volume is lit at: --scale, else the file's stored scale, else one chosen from its size.
ModelScale chosen_scale(const SceneLightOptions& options, const VolumeFile& file);

// Says on stderr ("waxwork: FILE: scale: ...") a scale chosen from the model's size (nothing for a
// given or stored one). Called once the output is written, so that an error stays one line.
void report_chosen_scale(const std::string& file, const ModelScale& scale, const TetMesh& mesh);

// Warnings of a solve on stderr: the GPU solve that fell back to the CPU, and the alternative method's
// (a scene outside its valid range), each naming `file`.
void report_solve_warnings(const std::string& file, const SolvedScene& scene);

// The solver's part of a command's JSON summary: iterations, and CG's estimated error for TransCut, or
// the alternative method's unknowns, setup and solve times and warnings.
void add_solve_summary(nlohmann::ordered_json& summary, const SolvedScene& scene);

}  // namespace waxwork
