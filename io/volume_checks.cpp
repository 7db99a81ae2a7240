#include "io/volume_checks.h"

#include "base/error.h"

#include <cstdint>

namespace waxwork {

void check_volume(const TetMesh& mesh, const std::string& file) {
    const std::vector<std::string> violations = find_invariant_violations(mesh);
    if (violations.empty()) return;
    constexpr size_t kShown = 3;
    std::string problem = "invalid volume: " + violations.front();
    for (size_t i = 1; i < violations.size() && i < kShown; ++i) problem += "; " + violations[i];
    if (violations.size() > kShown) {
        problem += " (and " + std::to_string(violations.size() - kShown) + " more problems)";
    }
    throw FileError(file, problem);
}

TetMesh mesh_from_foreign_geometry(std::vector<Eigen::Vector3d> positions, std::vector<Tet> tets,
                                   const std::string& file) {
    std::vector<int32_t> new_index(positions.size(), -1);
    for (const Tet& tet : tets)
        for (int32_t v : tet) new_index[static_cast<size_t>(v)] = 0;
    int32_t kept = 0;
    for (size_t v = 0; v < positions.size(); ++v) {
        if (new_index[v] < 0) continue;
        new_index[v] = kept;
        positions[static_cast<size_t>(kept)] = positions[v];
        ++kept;
    }
    positions.resize(static_cast<size_t>(kept));
    for (size_t t = 0; t < tets.size(); ++t) {
        Tet& tet = tets[t];
        for (int32_t& v : tet) v = new_index[static_cast<size_t>(v)];
        if (tet[0] == tet[1] || tet[0] == tet[2] || tet[0] == tet[3] || tet[1] == tet[2] || tet[1] == tet[3] ||
            tet[2] == tet[3]) {
            throw FileError(file, "tet " + std::to_string(t + 1) + " (in file order) repeats a vertex");
        }
        const double volume = signed_volume(positions[tet[0]], positions[tet[1]], positions[tet[2]],
                                            positions[tet[3]]);
        if (!(volume != 0.0)) {
            throw FileError(file, "tet " + std::to_string(t + 1) + " (in file order) has zero volume");
        }
        if (volume < 0) std::swap(tet[2], tet[3]);
    }
    TetMesh mesh;
    try {
        mesh = make_tet_mesh(std::move(positions), std::move(tets));
    } catch (const InvalidMeshError& error) {
        throw FileError(file, std::string("invalid volume: ") + error.what());
    }
    check_volume(mesh, file);
    return mesh;
}

}  // namespace waxwork
