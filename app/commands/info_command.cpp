// `waxwork info VOLUME [--cells CELLS.csv]`: one JSON object describing a volume.
#include "app/commands.h"
#include "app/options/help_sections.h"
#include "io/atomic_file.h"
#include "io/volume_file.h"
#include "solver/material.h"
#include "tetops/connectivity.h"
#include "tetops/model_scale.h"
#include "tetops/quality.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <iomanip>
#include <iostream>
#include <memory>
#include <set>

namespace waxwork {
namespace {

struct InfoCommandOptions {
    std::string volume;
    std::string cells;
};

// One row per tet in the volume's order. Materials are the ones rendering uses: the stored per-tet
// material, or the marble default when the volume stores none (info's JSON says which).
void write_cells_csv(const TetMesh& mesh, const std::string& path) {
    const std::vector<double> min_angles = min_dihedral_angles_deg(mesh);
    const TetMaterial fallback = material_preset("marble");
    write_file_atomically(path, [&](std::ostream& out) {
        out << "cx,cy,cz,mua_r,mua_g,mua_b,musp_r,musp_g,musp_b,eta,original_id,piece,min_dihedral_deg\n";
        out << std::setprecision(17);
        for (size_t t = 0; t < mesh.tet_count(); ++t) {
            const Tet& tet = mesh.tets[t];
            const Eigen::Vector3d c = (mesh.positions[tet[0]] + mesh.positions[tet[1]] + mesh.positions[tet[2]] +
                                       mesh.positions[tet[3]]) / 4.0;
            const TetMaterial& m = mesh.has_materials() ? mesh.materials[t] : fallback;
            out << c.x() << ',' << c.y() << ',' << c.z() << ',' << m.mua[0] << ',' << m.mua[1] << ',' << m.mua[2]
                << ',' << m.musp[0] << ',' << m.musp[1] << ',' << m.musp[2] << ',' << m.eta << ','
                << mesh.original_ids[t] << ',' << mesh.piece_ids[t] << ',' << min_angles[t] << '\n';
        }
    });
}

void run_info_command(const InfoCommandOptions& o) {
    const VolumeFile file = read_volume_file(o.volume);
    const TetMesh& mesh = file.mesh;
    const TetConnectivity connectivity = build_connectivity(mesh);
    const QualityReport q = measure_quality(mesh);
    const auto [lo, hi] = bounding_box(mesh);
    const std::set<int32_t> pieces(mesh.piece_ids.begin(), mesh.piece_ids.end());
    nlohmann::ordered_json info = {
        {"file", o.volume},
        {"vertices", mesh.vertex_count()},
        {"tets", mesh.tet_count()},
        {"edges", connectivity.edges.size()},
        {"boundary_faces", connectivity.boundary_faces.size()},
        {"boundary_vertices", connectivity.boundary_vertices.size()},
        {"components", connectivity.component_count},
        {"pieces", pieces.size()},
        {"materials_stored", mesh.has_materials()},
        {"min_dihedral_deg", q.min_dihedral_deg},
        {"max_dihedral_deg", q.max_dihedral_deg},
        {"max_radius_edge_ratio", q.max_radius_edge_ratio},
        {"mean_radius_edge_ratio", q.mean_radius_edge_ratio},
        {"tets_below_5_deg", q.tets_below_5_deg},
        {"min_edge_length", q.min_edge_length},
        {"max_edge_length", q.max_edge_length},
        {"mean_edge_length", q.mean_edge_length},
        {"volume", total_volume(mesh)},
        {"bbox", {{"min", {lo.x(), lo.y(), lo.z()}}, {"max", {hi.x(), hi.y(), hi.z()}}}},
    };
    // The scale the file stores, and the size it gives (null: none stored; render picks one).
    info["mm_per_unit"] = file.metadata.mm_per_unit ? nlohmann::ordered_json(*file.metadata.mm_per_unit) : nullptr;
    if (file.metadata.mm_per_unit) info["size_mm"] = size_in_mm(hi - lo, *file.metadata.mm_per_unit);
    if (!o.cells.empty()) write_cells_csv(mesh, o.cells);
    std::cout << info.dump(2) << "\n";
}

}  // namespace

void add_info_command(CLI::App& app) {
    auto options = std::make_shared<InfoCommandOptions>();
    CLI::App* cmd = app.add_subcommand("info", "Print a JSON summary of a volume (counts, quality, volume, bbox)");
    cmd->add_option("volume", options->volume, "Volume file (.vtu, .msh, .mesh, .node/.ele)")->required();
    cmd->add_option("--cells", options->cells, "Also write one CSV row per tet to this file");
    organise_help(*cmd, "waxwork info spot.vtu", {});
    cmd->callback([options] { run_info_command(*options); });
}

}  // namespace waxwork
