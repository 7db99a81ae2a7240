#include "scene/fields_csv.h"

#include "io/atomic_file.h"
#include "solver/radiance.h"
#include "tetops/cut.h"

#include <iomanip>
#include <vector>

namespace waxwork {

void write_fields_csv(const std::filesystem::path& path, const TetMesh& mesh, const TetConnectivity& connectivity,
                      const SolvedScene& scene) {
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    // eta per volume vertex, from the surface (the value q and E were computed with).
    std::vector<double> eta(mesh.vertex_count(), 1.0);
    for (size_t s = 0; s < scene.surface.vertices.size(); ++s) eta[scene.surface.vertices[s]] = scene.surface.eta[s];
    write_file_atomically(path, [&](std::ostream& out) {
        out << "x,y,z,boundary,q_r,q_g,q_b,phi_r,phi_g,phi_b,lo_r,lo_g,lo_b\n";
        out << std::setprecision(9);
        for (size_t v = 0; v < mesh.vertex_count(); ++v) {
            const bool boundary = connectivity.is_boundary_vertex[v] != 0;
            const Rgb& q = scene.q[v];
            const auto& phi = scene.diffusion.phi[v];
            // lo: exitant_radiance along the vertex's (averaged) normal, from the q the solve used (at a
            // crease, its sides' light weighed by their areas; the image shades each side with its own).
            double lo[3] = {0, 0, 0};
            if (boundary)
                for (int c = 0; c < 3; ++c) lo[c] = exitant_radiance(phi[c], q[c], eta[v], 1.0);
            out << world[v].x() << ',' << world[v].y() << ',' << world[v].z() << ',' << (boundary ? 1 : 0);
            for (int c = 0; c < 3; ++c) out << ',' << (boundary ? q[c] : 0.0);
            for (int c = 0; c < 3; ++c) out << ',' << phi[c];
            for (int c = 0; c < 3; ++c) out << ',' << lo[c];
            out << '\n';
        }
    });
}

}  // namespace waxwork
