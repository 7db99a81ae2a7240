#include "scene/fields_csv.h"

#include "base/error.h"
#include "io/atomic_file.h"
#include "scene/vertex_radiance.h"
#include "tetops/cut.h"

#include <iomanip>
#include <vector>

namespace waxwork {

void write_fields_csv(const std::filesystem::path& path, const TetMesh& mesh, const TetConnectivity& connectivity,
                      const SolvedScene& scene, const std::vector<std::array<double, 3>>* phi_error) {
    if (phi_error && phi_error->size() != mesh.vertex_count())
        throw InvalidArgumentError("fields: " + std::to_string(phi_error->size()) + " standard errors for " +
                                   std::to_string(mesh.vertex_count()) + " vertices");
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    const std::vector<std::array<double, 3>> lo = vertex_exitant_radiance(mesh, connectivity, scene);
    write_file_atomically(path, [&](std::ostream& out) {
        out << "x,y,z,boundary,q_r,q_g,q_b,phi_r,phi_g,phi_b,lo_r,lo_g,lo_b";
        out << (phi_error ? ",phi_err_r,phi_err_g,phi_err_b\n" : "\n");
        out << std::setprecision(9);
        for (size_t v = 0; v < mesh.vertex_count(); ++v) {
            const bool boundary = connectivity.is_boundary_vertex[v] != 0;
            const Rgb& q = scene.q[v];
            const auto& phi = scene.diffusion.phi[v];
            out << world[v].x() << ',' << world[v].y() << ',' << world[v].z() << ',' << (boundary ? 1 : 0);
            for (int c = 0; c < 3; ++c) out << ',' << (boundary ? q[c] : 0.0);
            for (int c = 0; c < 3; ++c) out << ',' << phi[c];
            for (int c = 0; c < 3; ++c) out << ',' << lo[v][c];
            if (phi_error)
                for (int c = 0; c < 3; ++c) out << ',' << (*phi_error)[v][c];
            out << '\n';
        }
    });
}

}  // namespace waxwork
