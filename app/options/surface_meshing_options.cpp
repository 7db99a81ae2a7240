#include "app/options/surface_meshing_options.h"

#include "app/stderr_progress.h"
#include "base/error.h"

#include <CLI/CLI.hpp>

#include <iostream>

namespace waxwork {

CLI::Option* add_max_tets_option(CLI::App& command, std::optional<size_t>& max_tets, const std::string& description) {
    const CLI::Validator positive_count(
        [](std::string& text) -> std::string {
            const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
            return digits && text.find_first_not_of('0') != std::string::npos ? "" : "must be a positive whole number of tets";
        },
        "COUNT");
    return command.add_option("--max-tets", max_tets, description)->check(positive_count);
}

void add_surface_meshing_options(CLI::App& command, SurfaceMeshingOptions& options) {
    command
        .add_option("--mesher", options.mesher,
                    "auto (TetGen, on the surface remeshed where its triangles do not fit the size or "
                    "--max-tets), tetgen (keeps the surface's triangles) or cgal (remeshes it)")
        ->check(CLI::IsMember({"auto", "tetgen", "cgal"}))
        ->capture_default_str();
    command.add_option("--min-dihedral", options.min_dihedral, "Minimum dihedral angle in degrees: TetGen's bound (away from the input's triangles), "
                       "the target of CGAL's sliver perturber and exuder")
        ->capture_default_str();
    command.add_option("--radius-edge", options.radius_edge, "Radius-edge ratio bound")->capture_default_str();
    auto* fill_holes = command.add_flag("--fill-holes", options.fill_holes, "Opt-in repair: close holes in an open surface");
    auto* autorefine = command.add_flag("--autorefine", options.autorefine, "Opt-in repair: remove self-intersections");
    auto* repair = command
                       .add_option("--repair", options.repair,
                                   "wrap: rebuild any surface (soup, holes, non-manifold, self-intersecting) as the "
                                   "closed surface CGAL's alpha wrap lays around it, instead of the other repairs")
                       ->check(CLI::IsMember({"wrap"}))
                       ->excludes(fill_holes)
                       ->excludes(autorefine);
    command
        .add_option("--wrap-alpha", options.wrap_alpha,
                    "--repair wrap: cavities and gaps narrower than about this are closed over (model units; "
                    "default 1/100 of the bounding-box diagonal, or wide enough to close the input's holes, "
                    "up to 1/10)")
        ->needs(repair);
    command
        .add_option("--wrap-offset", options.wrap_offset,
                    "--repair wrap: distance of the wrap from the input (model units; default alpha/30)")
        ->needs(repair);
}

SurfaceRepairOptions surface_repair_options(const SurfaceMeshingOptions& options) {
    SurfaceRepairOptions repair;
    repair.fill_holes = options.fill_holes;
    repair.autorefine = options.autorefine;
    if (options.repair == "wrap") {
        repair.wrap = WrapOptions{.alpha = options.wrap_alpha, .offset = options.wrap_offset};
        validate_wrap_options(*repair.wrap, 0.0);  // sign and finiteness now; the size floor once read
    }
    return repair;
}

LoadedSurface load_surface_to_mesh(const std::string& path, const SurfaceMeshingOptions& options,
                                   StderrProgress* progress) {
    SurfaceRepairOptions repair = surface_repair_options(options);
    repair.max_triangles = kMaxSurfaceTriangles;  // refused before the checks, which take long too
    LoadedSurface loaded = load_closed_surface(path, repair, progress);
    if (progress) progress->finish();
    for (const std::string& line : loaded.repairs) std::cerr << "waxwork: " << path << ": repaired: " << line << "\n";
    return loaded;
}

MeshingOptions meshing_options(const SurfaceMeshingOptions& options) {
    MeshingOptions meshing;
    meshing.mesher = options.mesher == "cgal"     ? Mesher::Cgal
                     : options.mesher == "tetgen" ? Mesher::TetGen
                                                  : Mesher::Auto;
    meshing.min_dihedral_deg = options.min_dihedral;
    meshing.max_radius_edge_ratio = options.radius_edge;
    return meshing;
}

}  // namespace waxwork
