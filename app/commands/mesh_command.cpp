// `waxwork mesh INPUT -o OUTPUT`: surface file -> validated surface -> tetrahedral volume file.
#include "app/commands.h"
#include "app/stderr_progress.h"
#include "app/options/help_sections.h"
#include "app/options/material_options.h"
#include "app/options/surface_meshing_options.h"
#include "base/error.h"
#include "io/surface_reader.h"
#include "io/volume_file.h"
#include "solver/material.h"
#include "solver/mesh_resolution.h"
#include "tetops/model_scale.h"
#include "tetops/tetrahedralize.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <iostream>
#include <memory>
#include <optional>

namespace waxwork {
namespace {

struct MeshCommandOptions {
    std::string input;
    std::string output;
    std::optional<double> edge;
    std::optional<size_t> max_tets;
    std::optional<double> scale;  // nullopt: chosen from the model's size
    SurfaceMeshingOptions meshing;
    MaterialOptions material;
};

void run_mesh_command(const MeshCommandOptions& o) {
    if (o.scale) validate_mm_per_unit(*o.scale, "--scale");  // before the (possibly long) surface checks
    StderrProgress progress("waxwork: " + o.input + ": ");
    const LoadedSurface loaded = load_surface_to_mesh(o.input, o.meshing, &progress);
    const Eigen::Vector3d extent = bounding_extent(loaded.surface.points);
    const ModelScale scale = choose_model_scale(o.scale, std::nullopt, extent);
    MeshingOptions options = meshing_options(o.meshing);
    options.progress = &progress;
    if (loaded.wrap) options.remesh_edge_ratio = kWrapRemeshEdgeRatio;
    // tetrahedralize() validates the explicit sizes (positive, finite, not absurdly many tets).
    if (o.edge) {
        options.sizing.edge_length = o.edge;
    } else if (o.max_tets) {
        options.sizing.target_tets = o.max_tets;
    } else {
        const TetMaterial material = chosen_material(o.material).value_or(material_preset("marble"));
        options.sizing = default_mesh_sizing(loaded.surface, material, scale.mm_per_unit);
    }
    MeshingResult result = tetrahedralize_surface_file(o.input, loaded.surface, options);
    if (const auto material = chosen_material(o.material))
        result.mesh.materials.assign(result.mesh.tet_count(), *material);
    progress.set_stage("writing " + o.output);
    write_volume(result.mesh, o.output, VolumeMetadata{scale.mm_per_unit});
    progress.finish();
    // Said once the volume is written: an error stays the one line it is.
    if (scale.source != ScaleSource::Given)
        std::cerr << "waxwork: " << o.input << ": scale: " << describe_model_scale(scale, extent) << "\n";

    const QualityReport& q = result.quality;
    nlohmann::ordered_json summary = {
        {"output", o.output},
        {"vertices", result.mesh.vertex_count()},
        {"tets", result.mesh.tet_count()},
        {"mm_per_unit", scale.mm_per_unit},
        {"scale_source", scale_source_name(scale.source)},
        {"min_dihedral_deg", q.min_dihedral_deg},
        {"max_dihedral_deg", q.max_dihedral_deg},
        {"max_radius_edge_ratio", q.max_radius_edge_ratio},
        {"tets_below_5_deg", q.tets_below_5_deg},
        {"mean_edge_length", q.mean_edge_length},
        {"repairs", loaded.repairs},
        {"milliseconds", result.milliseconds},
        {"mesher", mesher_name(result.mesher)},
        {"mesher_reason", result.mesher_reason},
    };
    if (const auto& remeshed = result.surface_remeshed)
        summary["surface_remeshed"] = {{"triangles_in", remeshed->triangles_in},
                                       {"triangles_out", remeshed->triangles_out},
                                       {"edge", remeshed->edge}};
    if (const auto& wrap = loaded.wrap)
        summary["wrap"] = {{"alpha", wrap->alpha},
                           {"offset", wrap->offset},
                           {"triangles", wrap->triangles},
                           {"hausdorff", wrap->hausdorff},
                           {"hausdorff_percent_of_diagonal", 100.0 * wrap->hausdorff / wrap->diagonal}};
    std::cout << summary.dump() << "\n";
}

}  // namespace

void add_mesh_command(CLI::App& app) {
    auto options = std::make_shared<MeshCommandOptions>();
    CLI::App* cmd = app.add_subcommand("mesh", "Fill a closed surface (OBJ, OFF, PLY, STL) with tetrahedra");
    cmd->add_option("input", options->input, "Surface file")->required()->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", options->output, "Volume file (.vtu, .msh, .mesh, .node)")->required();
    auto* edge = cmd->add_option("--edge", options->edge, "Target edge length in model units");
    auto* tets = add_max_tets_option(*cmd, options->max_tets,
                                     "About this many tets (within 20%), at most " + std::to_string(kMaxMeshTets));
    edge->excludes(tets);
    add_surface_meshing_options(*cmd, options->meshing);
    cmd->add_option("--scale", options->scale,
                    "Millimetres per model unit, stored in the volume (sizes the default mesh; default: "
                    "the bounding-box diagonal about 75 mm)");
    add_material_options(*cmd, options->material);
    cmd->footer(
        "Without --edge or --max-tets the size follows the material (default marble): tets near the surface\n"
        "resolve the diffusion length 1/sigma_tr and grow inward (see solver/mesh_resolution.h).");
    organise_help(*cmd, "waxwork mesh assets/meshes/spot.obj -o spot.vtu --max-tets 100000",
                  {{"Meshing details (docs/meshing.md)", {"--edge", "--mesher", "--min-dihedral", "--radius-edge"}},
                   {"Repairing a broken surface", {"--fill-holes", "--autorefine", "--repair", "--wrap-alpha", "--wrap-offset"}},
                   {"Custom material (per mm, instead of --material)", {"--mua", "--musp", "--eta"}}});
    cmd->callback([options] { run_mesh_command(*options); });
}

}  // namespace waxwork
