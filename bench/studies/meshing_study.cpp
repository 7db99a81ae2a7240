#include "bench/studies/meshing_study.h"

#include "io/surface_reader.h"
#include "solver/material.h"
#include "solver/mesh_resolution.h"
#include "tetops/connectivity.h"
#include "tetops/quality.h"
#include "tetops/tetgen_mesher.h"
#include "tetops/tetrahedralize.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>

namespace waxwork {
namespace {

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The smallest dihedral angle over the tets none of whose vertices is on the surface: TetGen keeps
// the input triangles, so the tets touching them keep what small input angles force, and only the
// others show what its quality bound achieves.
double interior_min_dihedral_deg(const TetMesh& mesh) {
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<double> angles = min_dihedral_angles_deg(mesh);
    double smallest = 180;
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const Tet& tet = mesh.tets[t];
        if (std::none_of(tet.begin(), tet.end(), [&](int32_t v) { return connectivity.is_boundary_vertex[v] != 0; }))
            smallest = std::min(smallest, angles[t]);
    }
    return smallest;
}

void measure_row(const std::filesystem::path& path, const MeshingStudyOptions& options, MeshingStudyRow& row) {
    const TriangleSurface surface = load_closed_surface(path).surface;
    row.triangles = surface.triangles.size();

    const TetMaterial material = material_preset(options.material);
    MeshingOptions graded;
    graded.sizing = default_mesh_sizing(surface, material, options.mm_per_unit);
    const MeshingResult result = tetrahedralize(surface, graded);
    row.mesher = mesher_name(result.mesher);
    row.mesher_reason = result.mesher_reason;
    row.default_ms = result.milliseconds;
    row.tets = result.mesh.tet_count();
    row.min_dihedral_deg = result.quality.min_dihedral_deg;
    row.interior_min_dihedral_deg = interior_min_dihedral_deg(result.mesh);
    row.tets_below_5_deg = result.quality.tets_below_5_deg;

    row.budget = options.budget;
    MeshingOptions budget;
    budget.sizing.target_tets = options.budget;
    const MeshingResult budgeted = tetrahedralize(surface, budget);
    row.budget_tets = budgeted.mesh.tet_count();
    row.budget_ms = budgeted.milliseconds;
    row.budget_mesher = mesher_name(budgeted.mesher);

    // TetGen's own quality run, as `tetgen -pq1.414` would make it (no dihedral bound, no size). Not run
    // on surfaces over TetGen's triangle limit: it runs for minutes there (docs/meshing.md, Limits).
    if (surface.triangles.size() > kMaxTetGenTriangles) return;
    TetGenSettings reference;
    reference.size = SizeField::unbounded();
    reference.max_radius_edge_ratio = 1.414;
    reference.min_dihedral_deg = 0;
    const auto start = std::chrono::steady_clock::now();
    const TetMesh plain = tetgen_tetrahedralize(surface, reference);
    row.reference_ms = milliseconds_since(start);
    row.reference_tets = plain.tet_count();
    row.reference_min_dihedral_deg = mesh_min_dihedral_deg(plain);
}

std::string format(const char* pattern, double value) {
    char text[64];
    std::snprintf(text, sizeof text, pattern, value);
    return text;
}

}  // namespace

std::vector<std::filesystem::path> surface_files(const std::filesystem::path& dir) {
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        const std::string extension = entry.path().extension().string();
        if (extension == ".obj" || extension == ".off" || extension == ".ply" || extension == ".stl")
            files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

std::vector<MeshingStudyRow> run_meshing_study(const MeshingStudyOptions& options) {
    std::vector<MeshingStudyRow> rows;
    for (const std::filesystem::path& path : options.surfaces) {
        MeshingStudyRow& row = rows.emplace_back();
        row.model = path.filename().string();
        try {
            measure_row(path, options, row);
        } catch (const std::exception& e) {
            row.error = e.what();
        }
    }
    return rows;
}

nlohmann::ordered_json to_json(const std::vector<MeshingStudyRow>& rows) {
    nlohmann::ordered_json json = nlohmann::ordered_json::array();
    for (const MeshingStudyRow& r : rows) {
        nlohmann::ordered_json row = {{"model", r.model}, {"triangles", r.triangles}};
        if (!r.error.empty()) row["error"] = r.error;
        row["reference"] = {{"switches", "pq1.414"},
                            {"ms", r.reference_ms},
                            {"tets", r.reference_tets},
                            {"min_dihedral_deg", r.reference_min_dihedral_deg}};
        row["default"] = {{"mesher", r.mesher},
                          {"mesher_reason", r.mesher_reason},
                          {"ms", r.default_ms},
                          {"tets", r.tets},
                          {"min_dihedral_deg", r.min_dihedral_deg},
                          {"interior_min_dihedral_deg", r.interior_min_dihedral_deg},
                          {"tets_below_5_deg", r.tets_below_5_deg}};
        row["budget"] = {{"max_tets", r.budget}, {"tets", r.budget_tets}, {"ms", r.budget_ms}, {"mesher", r.budget_mesher}};
        json.push_back(row);
    }
    return json;
}

std::string meshing_table_markdown(const std::vector<MeshingStudyRow>& rows) {
    std::string table =
        "| model | triangles | default: mesher | time | tets | min dihedral (interior) | under 5 deg | "
        "TetGen -pq1.414: time | tets | min dihedral | default / -pq time | --max-tets " +
        std::to_string(rows.empty() ? 0 : rows.front().budget) + ": tets (mesher, time) |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const MeshingStudyRow& r : rows) {
        if (!r.error.empty() && r.tets == 0) {
            table += "| " + r.model + " | " + std::to_string(r.triangles) + " | failed: " + r.error +
                     " |||||||||\n";
            continue;
        }
        table += "| " + r.model + " | " + std::to_string(r.triangles) + " | " + r.mesher + " | " +
                 format("%.2f s", r.default_ms / 1000) + " | " + std::to_string(r.tets) + " | " +
                 format("%.2f", r.min_dihedral_deg) + format(" (%.2f)", r.interior_min_dihedral_deg) + " | " +
                 std::to_string(r.tets_below_5_deg) + " | ";
        if (r.reference_tets > 0) {
            table += format("%.2f s", r.reference_ms / 1000) + " | " + std::to_string(r.reference_tets) + " | " +
                     format("%.2f", r.reference_min_dihedral_deg) + " | " +
                     format("%.2f", r.default_ms / r.reference_ms) + " | ";
        } else if (r.triangles > kMaxTetGenTriangles) {
            table += "not run (over TetGen's " + std::to_string(kMaxTetGenTriangles) + " triangles) | | | | ";
        } else {
            table += "failed: " + r.error + " | | | | ";
        }
        table += r.budget_tets > 0 ? std::to_string(r.budget_tets) + " (" + r.budget_mesher + ", " +
                                         format("%.2f s", r.budget_ms / 1000) + ") |\n"
                                   : "failed |\n";
    }
    return table;
}

}  // namespace waxwork
