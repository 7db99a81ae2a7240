// The tetrahedral volume: the central data structure of Waxwork.
//
// Plain arrays, one entry per vertex or per tet, so every algorithm can run over them in parallel and
// every file format can store them exactly. Derived data (edges, one-rings, boundary, components) lives
// in TetConnectivity (connectivity.h) and is rebuilt after edits.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace waxwork {

using Tet = std::array<int32_t, 4>;

// Scattering coefficients of one tet, per rgb channel, in 1/mm (see solver/material.h for meaning).
// Stored with the geometry so that painted volumes save and reload; tetops interprets them no further
// than material_problem's range check.
struct TetMaterial {
    std::array<double, 3> mua{};   // absorption coefficient mu_a
    std::array<double, 3> musp{};  // reduced scattering coefficient mu_s'
    double eta = 1.0;              // relative index of refraction

    friend bool operator==(const TetMaterial&, const TetMaterial&) = default;
};

// The materials the diffusion model can solve: finite coefficients per millimetre with mu_a >= 0 and
// 0 < mu_s' (the diffusion approximation needs scattering), both at most kMaxCoefficientPerMm (larger
// values are a unit error: per metre instead of per millimetre), and eta in [kMinEta, kMaxEta], where
// the fit of the diffuse Fresnel reflectance (solver/material.h) holds. Stored materials must be in
// this range (a TetMesh invariant), so whatever a reader accepts or a save writes can be rendered.
inline constexpr double kMaxCoefficientPerMm = 1e4;
inline constexpr double kMinEta = 1.0;
inline constexpr double kMaxEta = 3.0;

// The largest coordinate magnitude of a model (surface or volume), in model units. The renderer and
// the shadow rays work in float: a ray-triangle test multiplies up to three coordinate differences,
// which stays far inside float's range (3.4e38) below (2e12)^3. At the smallest scale (1e-6 mm per
// unit) 1e12 units are a kilometre, beyond any object diffusion can light.
inline constexpr double kMaxCoordinate = 1e12;
inline constexpr const char* kMaxCoordinateText = "1e12";  // for messages

// What is wrong with `material` ("" when it is in the range above), e.g.
// "mu_s' = 0 must be positive (the diffusion approximation needs scattering) (channel r)".
std::string material_problem(const TetMaterial& material);

// Rigid motion of one piece: x_world = rotation * x_rest + translation.
struct RigidTransform {
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    Eigen::Vector3d translation = Eigen::Vector3d::Zero();

    friend bool operator==(const RigidTransform& a, const RigidTransform& b) {
        return a.rotation == b.rotation && a.translation == b.translation;
    }
};

struct TetMesh {
    // Vertex positions in model units, in the rest frame of their piece.
    std::vector<Eigen::Vector3d> positions;
    // Tets as four vertex indices, positively oriented: (p1-p0) . ((p2-p0) x (p3-p0)) > 0.
    std::vector<Tet> tets;
    // One material per tet, or empty when the volume stores none (the renderer then picks one).
    std::vector<TetMaterial> materials;
    // Per tet: its index in the mesh before any edit; the tets an exact cut or fracture splits keep
    // their parent's, and cuts (and the fracture's collapse of swallowed walls) can leave an id with no
    // tet. Saved with the volume and listed by `info --cells`, so a tet can be traced to its ancestor.
    std::vector<int32_t> original_ids;
    // Per tet: the piece it belongs to, an index into piece_transforms.
    std::vector<int32_t> piece_ids;
    // One rigid transform per piece.
    std::vector<RigidTransform> piece_transforms;

    size_t vertex_count() const { return positions.size(); }
    size_t tet_count() const { return tets.size(); }
    bool has_materials() const { return !materials.empty(); }

    friend bool operator==(const TetMesh&, const TetMesh&) = default;
};

// A mesh from bare geometry: original ids 0..n-1, everything in piece 0 with the identity transform,
// no materials. Reorients negatively oriented tets; throws InvalidMeshError on degenerate ones.
TetMesh make_tet_mesh(std::vector<Eigen::Vector3d> positions, std::vector<Tet> tets);

// Two meshes as one volume: b's vertices and tets after a's (b's indices shifted), nothing shared, so
// touching faces stay two boundary faces (a crack of zero width, as a fracture leaves its pieces in
// the rest frame). Bare geometry as make_tet_mesh gives it: piece 0, no materials.
TetMesh join_meshes(const TetMesh& a, const TetMesh& b);
// Signed volume of tet t (positive for a correctly oriented tet).
double signed_volume(const TetMesh& mesh, size_t t);
double signed_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& d);

// Total volume (sum of tet volumes).
double total_volume(const TetMesh& mesh);

// Axis-aligned bounding box of the vertices: {min, max}.
std::array<Eigen::Vector3d, 2> bounding_box(const TetMesh& mesh);

// Every broken invariant, described in one line each; empty when the mesh is valid. Checks array
// sizes, index ranges, finite coordinates, positive orientation, distinct vertices per tet, piece ids,
// unreferenced vertices, materials in the model's range (material_problem), and that no face is
// shared by more than two tets.
std::vector<std::string> find_invariant_violations(const TetMesh& mesh);

// Throws InvalidMeshError listing the first violations when find_invariant_violations is non-empty.
void validate(const TetMesh& mesh);

}  // namespace waxwork
