#include "tetops/tet_mesh.h"

#include "tetops/error.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <unordered_map>

namespace waxwork {

double signed_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& d) {
    return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

double signed_volume(const TetMesh& mesh, size_t t) {
    const Tet& tet = mesh.tets[t];
    return signed_volume(mesh.positions[tet[0]], mesh.positions[tet[1]], mesh.positions[tet[2]],
                         mesh.positions[tet[3]]);
}

TetMesh make_tet_mesh(std::vector<Eigen::Vector3d> positions, std::vector<Tet> tets) {
    TetMesh mesh;
    mesh.positions = std::move(positions);
    mesh.tets = std::move(tets);
    const auto vertex_count = static_cast<int64_t>(mesh.positions.size());
    for (size_t t = 0; t < mesh.tets.size(); ++t) {
        Tet& tet = mesh.tets[t];
        for (int32_t v : tet)
            if (v < 0 || v >= vertex_count)
                throw InvalidMeshError("tet " + std::to_string(t) + " references vertex " + std::to_string(v) +
                                       " but the mesh has " + std::to_string(vertex_count) + " vertices");
        const double volume = signed_volume(mesh, t);
        if (!(volume != 0.0) || !std::isfinite(volume))
            throw InvalidMeshError("tet " + std::to_string(t) + " is degenerate (zero or non-finite volume)");
        if (volume < 0) std::swap(tet[2], tet[3]);
    }
    mesh.original_ids.resize(mesh.tets.size());
    std::iota(mesh.original_ids.begin(), mesh.original_ids.end(), 0);
    mesh.piece_ids.assign(mesh.tets.size(), 0);
    mesh.piece_transforms.assign(1, RigidTransform{});
    return mesh;
}

double total_volume(const TetMesh& mesh) {
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, mesh.tets.size()), 0.0,
        [&](const tbb::blocked_range<size_t>& r, double sum) {
            for (size_t t = r.begin(); t != r.end(); ++t) sum += signed_volume(mesh, t);
            return sum;
        },
        std::plus<>());
}

std::array<Eigen::Vector3d, 2> bounding_box(const TetMesh& mesh) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const auto& p : mesh.positions) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    if (mesh.positions.empty()) lo = hi = Eigen::Vector3d::Zero();
    return {lo, hi};
}

namespace {

// Collects violations, keeping only the first few of each kind so a badly broken mesh still gives a
// short, readable report.
class ViolationLog {
public:
    void add(const std::string& kind, const std::string& message) {
        if (++counts_[kind] <= kMaxPerKind) messages_.push_back(message);
    }
    std::vector<std::string> finish() {
        for (const auto& [kind, count] : counts_)
            if (count > kMaxPerKind)
                messages_.push_back(std::to_string(count - kMaxPerKind) + " more: " + kind);
        return std::move(messages_);
    }

private:
    static constexpr int kMaxPerKind = 3;
    std::vector<std::string> messages_;
    std::unordered_map<std::string, int> counts_;
};

bool finite_material(const TetMaterial& m) {
    for (int c = 0; c < 3; ++c)
        if (!std::isfinite(m.mua[c]) || !std::isfinite(m.musp[c]) || m.mua[c] < 0 || m.musp[c] < 0) return false;
    return std::isfinite(m.eta) && m.eta > 0;
}

}  // namespace

std::vector<std::string> find_invariant_violations(const TetMesh& mesh) {
    ViolationLog log;
    const size_t n_tets = mesh.tets.size();
    const auto n_vertices = static_cast<int64_t>(mesh.positions.size());
    if (mesh.original_ids.size() != n_tets)
        log.add("size", "original_ids has " + std::to_string(mesh.original_ids.size()) + " entries for " +
                            std::to_string(n_tets) + " tets");
    if (mesh.piece_ids.size() != n_tets)
        log.add("size", "piece_ids has " + std::to_string(mesh.piece_ids.size()) + " entries for " +
                            std::to_string(n_tets) + " tets");
    if (!mesh.materials.empty() && mesh.materials.size() != n_tets)
        log.add("size", "materials has " + std::to_string(mesh.materials.size()) + " entries for " +
                            std::to_string(n_tets) + " tets");
    for (size_t v = 0; v < mesh.positions.size(); ++v)
        if (!mesh.positions[v].allFinite()) log.add("coordinates", "vertex " + std::to_string(v) + " is not finite");
    for (size_t i = 0; i < mesh.piece_transforms.size(); ++i) {
        const RigidTransform& x = mesh.piece_transforms[i];
        const bool orthonormal =
            (x.rotation.transpose() * x.rotation - Eigen::Matrix3d::Identity()).norm() < 1e-9 &&
            x.rotation.determinant() > 0;
        if (!x.rotation.allFinite() || !x.translation.allFinite() || !orthonormal)
            log.add("transform", "piece transform " + std::to_string(i) + " is not a finite rigid motion");
    }

    std::vector<uint8_t> referenced(mesh.positions.size(), 0);
    bool indices_ok = true;
    for (size_t t = 0; t < n_tets; ++t) {
        const Tet& tet = mesh.tets[t];
        bool in_range = true;
        for (int32_t v : tet)
            if (v < 0 || v >= n_vertices) in_range = false;
        if (!in_range) {
            indices_ok = false;
            log.add("index", "tet " + std::to_string(t) + " has a vertex index out of range");
            continue;
        }
        for (int32_t v : tet) referenced[v] = 1;
        if (tet[0] == tet[1] || tet[0] == tet[2] || tet[0] == tet[3] || tet[1] == tet[2] || tet[1] == tet[3] ||
            tet[2] == tet[3])
            log.add("repeated", "tet " + std::to_string(t) + " repeats a vertex");
        else if (!(signed_volume(mesh, t) > 0))
            log.add("orientation", "tet " + std::to_string(t) + " is not positively oriented (volume " +
                                       std::to_string(signed_volume(mesh, t)) + ")");
        if (t < mesh.piece_ids.size() &&
            (mesh.piece_ids[t] < 0 || static_cast<size_t>(mesh.piece_ids[t]) >= mesh.piece_transforms.size()))
            log.add("piece", "tet " + std::to_string(t) + " has piece id " + std::to_string(mesh.piece_ids[t]) +
                                 " without a transform");
        if (t < mesh.materials.size() && !finite_material(mesh.materials[t]))
            log.add("material", "tet " + std::to_string(t) + " has a non-finite or negative material");
    }
    for (size_t v = 0; v < referenced.size(); ++v)
        if (!referenced[v]) log.add("unreferenced", "vertex " + std::to_string(v) + " belongs to no tet");

    if (indices_ok) {
        // A face shared by three or more tets means overlapping or non-manifold tets.
        struct FaceKey {
            std::array<int32_t, 3> v;
            bool operator<(const FaceKey& o) const { return v < o.v; }
            bool operator==(const FaceKey& o) const { return v == o.v; }
        };
        std::vector<FaceKey> faces;
        faces.reserve(4 * n_tets);
        for (const Tet& tet : mesh.tets)
            for (int f = 0; f < 4; ++f) {
                std::array<int32_t, 3> k = {tet[(f + 1) % 4], tet[(f + 2) % 4], tet[(f + 3) % 4]};
                std::sort(k.begin(), k.end());
                faces.push_back({k});
            }
        std::sort(faces.begin(), faces.end());
        for (size_t i = 0; i + 2 < faces.size(); ++i)
            if (faces[i] == faces[i + 2])
                log.add("face", "face (" + std::to_string(faces[i].v[0]) + ", " + std::to_string(faces[i].v[1]) +
                                    ", " + std::to_string(faces[i].v[2]) + ") is shared by more than two tets");
    }
    return log.finish();
}

void validate(const TetMesh& mesh) {
    const std::vector<std::string> violations = find_invariant_violations(mesh);
    if (violations.empty()) return;
    std::ostringstream message;
    message << "invalid tet mesh: " << violations.front();
    if (violations.size() > 1) message << " (and " << violations.size() - 1 << " more problems)";
    throw InvalidMeshError(message.str());
}

}  // namespace waxwork
