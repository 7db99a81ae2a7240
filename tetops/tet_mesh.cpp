#include "tetops/tet_mesh.h"

#include "base/error.h"
#include "base/parallel_rows.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <unordered_map>

namespace waxwork {

TetMesh join_meshes(const TetMesh& a, const TetMesh& b) {
    std::vector<Eigen::Vector3d> positions = a.positions;
    positions.insert(positions.end(), b.positions.begin(), b.positions.end());
    std::vector<Tet> tets = a.tets;
    const auto offset = static_cast<int32_t>(a.vertex_count());
    for (Tet tet : b.tets) {
        for (int32_t& v : tet) v += offset;
        tets.push_back(tet);
    }
    return make_tet_mesh(std::move(positions), std::move(tets));
}

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
    // Deterministic: the same sum in the same order whatever the threads (`info` prints it).
    return sum_rows(mesh.tets.size(), 4096, [&](size_t t) { return signed_volume(mesh, t); });
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

}  // namespace

std::string material_problem(const TetMaterial& m) {
    constexpr std::array<char, 3> kChannelNames = {'r', 'g', 'b'};
    for (int c = 0; c < 3; ++c) {
        const std::string channel = std::string(" (channel ") + kChannelNames[c] + ")";
        const double mua = m.mua[c], musp = m.musp[c];
        if (!std::isfinite(mua)) return "mu_a is not finite" + channel;
        if (!std::isfinite(musp)) return "mu_s' is not finite" + channel;
        if (mua < 0) return "mu_a = " + number_text(mua) + " is negative" + channel;
        if (musp <= 0)
            return "mu_s' = " + number_text(musp) + " must be positive (the diffusion approximation needs scattering)" +
                   channel;
        if (mua > kMaxCoefficientPerMm || musp > kMaxCoefficientPerMm)
            return "coefficient above 1e4 per mm" + channel + "; coefficients are per millimetre";
    }
    if (!std::isfinite(m.eta)) return "eta is not finite";
    if (m.eta < kMinEta || m.eta > kMaxEta)
        return "eta = " + number_text(m.eta) + " is outside [1, 3] (relative index of refraction)";
    return "";
}

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
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
        if (!mesh.positions[v].allFinite())
            log.add("coordinates", "vertex " + std::to_string(v) + " is not finite");
        else if (mesh.positions[v].cwiseAbs().maxCoeff() > kMaxCoordinate)
            log.add("coordinates", "vertex " + std::to_string(v) + " lies beyond " + kMaxCoordinateText +
                                       " (the renderer's float arithmetic would overflow)");
    }
    for (size_t i = 0; i < mesh.piece_transforms.size(); ++i) {
        const RigidTransform& x = mesh.piece_transforms[i];
        const bool orthonormal =
            (x.rotation.transpose() * x.rotation - Eigen::Matrix3d::Identity()).norm() < 1e-9 &&
            x.rotation.determinant() > 0;
        if (!x.rotation.allFinite() || !x.translation.allFinite() || !orthonormal)
            log.add("transform", "piece transform " + std::to_string(i) + " is not a finite rigid motion");
        else if (x.translation.cwiseAbs().maxCoeff() > kMaxCoordinate)
            log.add("transform", "piece transform " + std::to_string(i) + " moves beyond " + kMaxCoordinateText);
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
        // Painted volumes hold few distinct materials in long runs: each run is checked once.
        if (t < mesh.materials.size() && (t == 0 || !(mesh.materials[t] == mesh.materials[t - 1])))
            if (const std::string problem = material_problem(mesh.materials[t]); !problem.empty())
                log.add("material", "tet " + std::to_string(t) + "'s material: " + problem);
    }
    for (size_t v = 0; v < referenced.size(); ++v)
        if (!referenced[v]) log.add("unreferenced", "vertex " + std::to_string(v) + " belongs to no tet");

    if (indices_ok) {
        // A face shared by three or more tets means overlapping or non-manifold tets, and so does a
        // face whose two tets lie on the same side of it (a tet listed twice, a tet folded over its
        // neighbour): in a positively oriented tet, the face opposite vertex f has vertices
        // (f+1, f+2, f+3) mod 4 turning outward for even f and inward for odd f, and sorting them
        // flips that with the sort's parity, so the two tets of a face must disagree.
        struct FaceKey {
            std::array<int32_t, 3> v;
            bool outward = false;  // the sorted order turns outward of its tet
            int32_t tet = 0;
            bool operator<(const FaceKey& o) const { return v < o.v; }
            bool same_face(const FaceKey& o) const { return v == o.v; }
        };
        std::vector<FaceKey> faces;
        faces.reserve(4 * n_tets);
        for (size_t t = 0; t < n_tets; ++t) {
            const Tet& tet = mesh.tets[t];
            for (int f = 0; f < 4; ++f) {
                std::array<int32_t, 3> k = {tet[(f + 1) % 4], tet[(f + 2) % 4], tet[(f + 3) % 4]};
                // Parity of the sort of three values: odd when they were not in a cyclic order.
                const bool cyclic = (k[0] < k[1]) + (k[1] < k[2]) + (k[2] < k[0]) == 2;
                std::sort(k.begin(), k.end());
                faces.push_back({k, (f % 2 == 0) == cyclic, static_cast<int32_t>(t)});
            }
        }
        std::sort(faces.begin(), faces.end());
        const auto face_name = [](const FaceKey& face) {
            return "face (" + std::to_string(face.v[0]) + ", " + std::to_string(face.v[1]) + ", " +
                   std::to_string(face.v[2]) + ")";
        };
        for (size_t i = 0; i + 1 < faces.size(); ++i) {
            if (!faces[i].same_face(faces[i + 1])) continue;
            if (i + 2 < faces.size() && faces[i].same_face(faces[i + 2]))
                log.add("face", face_name(faces[i]) + " is shared by more than two tets");
            else if (faces[i].outward == faces[i + 1].outward)
                log.add("overlap", "tets " + std::to_string(std::min(faces[i].tet, faces[i + 1].tet)) + " and " +
                                       std::to_string(std::max(faces[i].tet, faces[i + 1].tet)) +
                                       " overlap: both lie on the same side of their shared " + face_name(faces[i]));
        }
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
