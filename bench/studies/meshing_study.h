// The meshing study: per surface, the default (material-graded) mesh against a plain TetGen quality
// run of the same surface (-pq1.414, no size bound) timed in the same process, the mesher Mesher::Auto
// chose and why, the tet count, the smallest dihedral angle over all tets and over the tets away from
// the surface, and a run at a tet budget (--max-tets). The reference is TetGen's coarsest quality mesh:
// the graded default should cost at most twice it (docs/meshing.md).
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace waxwork {

struct MeshingStudyRow {
    std::string model;
    size_t triangles = 0;
    std::string error;  // the surface was refused or a run failed: the rest is what finished

    // TetGen -pq1.414 on the surface, no size bound (not run over kMaxTetGenTriangles: 0).
    double reference_ms = 0;
    size_t reference_tets = 0;
    double reference_min_dihedral_deg = 0;

    // The default mesh: graded by the material rule (solver/mesh_resolution.h), Mesher::Auto.
    std::string mesher;
    std::string mesher_reason;
    double default_ms = 0;  // tetrahedralize(): checks, meshing, ordering and quality
    size_t tets = 0;
    double min_dihedral_deg = 0;
    double interior_min_dihedral_deg = 0;  // tets with no vertex on the surface
    size_t tets_below_5_deg = 0;

    // --max-tets `budget`, Mesher::Auto.
    size_t budget = 0;
    size_t budget_tets = 0;
    double budget_ms = 0;
    std::string budget_mesher;
};

struct MeshingStudyOptions {
    std::vector<std::filesystem::path> surfaces;
    std::string material = "marble";
    double mm_per_unit = 1;  // `waxwork mesh`'s default --scale
    size_t budget = 20'000;
};

// Every surface in `dir` with a surface file extension (.obj, .off, .ply, .stl), sorted by name.
std::vector<std::filesystem::path> surface_files(const std::filesystem::path& dir);

// One row per surface, in order. A surface that cannot be read or meshed gets a row with its error;
// the study goes on.
std::vector<MeshingStudyRow> run_meshing_study(const MeshingStudyOptions& options);

nlohmann::ordered_json to_json(const std::vector<MeshingStudyRow>& rows);
std::string meshing_table_markdown(const std::vector<MeshingStudyRow>& rows);

}  // namespace waxwork
