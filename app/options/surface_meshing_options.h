// The options shared by every command that fills a surface file with tets (`mesh`, `bench solvers`,
// `edit`):
//   --mesher auto|tetgen|cgal --min-dihedral DEG --radius-edge R --fill-holes --autorefine
//   --repair wrap [--wrap-alpha A] [--wrap-offset D]
// The size (--edge, --max-tets, the material's default sizing) stays with each command: `mesh` has
// a default, `bench solvers` asks for a tet count.
#pragma once

#include "io/surface_reader.h"
#include "tetops/tetrahedralize.h"

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

namespace CLI {
class App;
class Option;
}

namespace waxwork {

class StderrProgress;

struct SurfaceMeshingOptions {
    std::string mesher = "auto";
    double min_dihedral = 10.0;
    double radius_edge = 2.0;
    bool fill_holes = false;
    bool autorefine = false;
    std::string repair;                // "wrap": rebuild by alpha wrapping (tetops/alpha_wrap.h); "": none
    std::optional<double> wrap_alpha;  // model units; default relative to the model
    std::optional<double> wrap_offset;
};

// Registers the options on `command`.
void add_surface_meshing_options(CLI::App& command, SurfaceMeshingOptions& options);

// Registers --max-tets N (about N tets) on `command`, every command's the same way: N must be a
// positive whole number (CLI11 reads -1 into an unsigned option as 2^64 - 1).
CLI::Option* add_max_tets_option(CLI::App& command, std::optional<size_t>& max_tets, const std::string& description);

// The repairs the options ask for (without the triangle limit). Throws InvalidArgumentError naming
// --wrap-alpha or --wrap-offset when one is not a positive, finite length.
SurfaceRepairOptions surface_repair_options(const SurfaceMeshingOptions& options);

// Reads and validates the surface with the repairs the options allow (load_closed_surface); each
// repair made is reported on stderr as "waxwork: PATH: repaired: WHAT".
// `progress`, when given, shows each stage; its status line is blanked before the repairs are listed.
LoadedSurface load_surface_to_mesh(const std::string& path, const SurfaceMeshingOptions& options,
                                   StderrProgress* progress = nullptr);

// The mesher and quality bounds of the options; the caller sets the sizing. tetrahedralize() validates
// them.
MeshingOptions meshing_options(const SurfaceMeshingOptions& options);

}  // namespace waxwork
