// The TransCut diffusion matrix (Li et al. 2013, Sec. 3.2, Eqs. 10-14) and its consistent-mass FEM
// counterpart (Arbree et al. 2011), assembled on a tetrahedral volume for the three rgb channels.
//
// Both discretisations solve M phi = b for the fluence phi at the vertices, where M = 4 (K + C + R):
//   K  stiffness, K_ij = sum_t kappa_t V_t grad(b_i).grad(b_j) = -(1/6) sum_t kappa_t |kl| cot(theta_kl)
//      (Eq. 10 and the appendix; identical in both discretisations),
//   C  absorption: TransCut lumps it, C_ii = sum_t mu_a,t V_t / 4 (Eq. 13 writes 4 C_ii = V_i mu);
//      FEM uses the consistent element mass mu_a,t V_t (1 + delta_ij) / 20,
//   R  Robin boundary (Eq. 11): (1 / (2 A_f)) times a boundary mass. TransCut lumps it,
//      R_ii = sum_f S_f / (6 A_f) (Eq. 13 writes 4 R_ii = 2 S_i / (3A)); FEM uses the consistent face
//      mass, R_ij = sum_f S_f (1 + delta_ij) / (24 A_f),
//   b  = 4 (1 / (2A)) (4 / (1 - F_dr)) (boundary mass) q: TransCut b_i = 8 S_i q_i / (3 A (1 - F_dr))
//      (Eq. 12); FEM multiplies the consistent face mass with the vertex values of q.
// The common factor 4 is TransCut's (it multiplies Eqs. 9 and 11 by -V_i = -4|Upsilon|); keeping it
// in the FEM variant makes both matrices discretise the same continuous problem with the same scale,
// so their solutions and their matrices can be compared entry by entry.
//
// Lengths are converted to millimetres (positions times mm_per_unit) because the coefficients are per
// millimetre. A and F_dr belong to the tet that owns a boundary face, so painted eta works per face.
// Vertices that no tet references get an identity row and a zero right-hand side (phi = 0).
#pragma once

#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

enum class Discretization {
    TransCut,  // Li et al. 2013, Eqs. 10-14 (lumped mass; 4x the linear FEM matrix with lumped mass)
    Fem,       // Arbree et al. 2011: consistent mass and consistent boundary mass
};

// Two evaluations of the same stiffness coefficient (they agree to rounding on good tets).
enum class StiffnessForm {
    // Appendix of Li et al.: kappa S_i S_j (n_i . n_j) / (9 V_t), evaluated as c_i . c_j / (6 det) with
    // c_i the (unnormalised) face cross products and det = 6 V_t. The default, because it is cheaper
    // (3 cross products, 6 dots, one division; no square roots). Robustness in float was measured
    // (tests/solver/diffusion_matrix_test.cpp, StiffnessFormsInFloatOnSlivers) on caps and slivers down
    // to 0.02 degrees: from edge vectors formed before rounding both forms keep ~1e-7 relative accuracy;
    // from absolute float coordinates both lose the same ~1e-2 (the positions' rounding amplified by the
    // shape). The formula does not matter, the frame does: assembly works relative to each tet's first
    // vertex, and a GPU kernel should do the same.
    Gradient,
    // Eq. 10 as written: -(1/6) kappa |kl| cot(theta_kl), theta_kl from the unit normals of the two
    // faces at edge kl (cos = n1.n2, sin = |n1 x n2|).
    Cotangent,
};

struct AssemblyOptions {
    Discretization discretization = Discretization::TransCut;
    StiffnessForm stiffness_form = StiffnessForm::Gradient;
    double mm_per_unit = 1.0;  // model units to millimetres
};

// Geometric part of the stiffness of one tet, K_ab / kappa for the six edges in kTetEdges order:
// S_a S_b (n_a . n_b) / (9 V) = -(1/6) |kl| cot(theta_kl). Positions in millimetres, positively
// oriented tet. Templated so that its rounding in float can be measured against double.
template <typename Scalar>
std::array<Scalar, 6> tet_edge_stiffness(const Eigen::Matrix<Scalar, 3, 1>& p0, const Eigen::Matrix<Scalar, 3, 1>& p1,
                                         const Eigen::Matrix<Scalar, 3, 1>& p2, const Eigen::Matrix<Scalar, 3, 1>& p3,
                                         StiffnessForm form);

// One rgb matrix triple on a shared compressed-row pattern, plus what incremental updates need.
struct DiffusionMatrix {
    AssemblyOptions options;

    // Shared pattern: row i holds i and its one-ring (TetConnectivity::vertex_vertices), columns
    // ascending; diagonal[i] is the position of (i, i) in columns.
    std::vector<int32_t> offsets{0};
    std::vector<int32_t> columns;
    std::vector<int32_t> diagonal;
    // M for channels r, g, b (Eqs. 13-14 or the FEM variant), aligned with columns.
    std::array<std::vector<double>, 3> values;
    // The right-hand-side operator on the same pattern: b = source * q (Eq. 12, or the consistent
    // boundary mass for FEM). Channel independent (A and F_dr depend on eta only); zero off boundary rows.
    std::vector<double> source;

    size_t size() const { return diagonal.size(); }
    size_t nonzeros() const { return columns.size(); }

    // --- Cached per topology and geometry (rebuilt by assemble_diffusion_matrix only). ---
    // Per entry of TetConnectivity::vertex_tets: where the row of that vertex stores its three tet
    // neighbours (ascending local index), and its local index in the tet.
    struct TetIncidence {
        std::array<int32_t, 3> slots;
        int32_t local;
    };
    std::vector<TetIncidence> tet_incidences;
    // Per tet: K_ab / kappa for its six edges (mm) and its volume (mm^3).
    struct TetGeometry {
        std::array<double, 6> edge_stiffness;
        double volume;
    };
    std::vector<TetGeometry> tet_geometry;
    // Per vertex, the boundary faces around it (indices into TetConnectivity::boundary_faces) and,
    // per incidence, the slots of the face's two other vertices in that vertex's row.
    std::vector<int32_t> vertex_face_offsets{0};
    std::vector<int32_t> vertex_faces;
    std::vector<std::array<int32_t, 2>> vertex_face_slots;
    std::vector<double> boundary_face_area;  // mm^2
    // Per tet, derived from its material: kappa and mu_a per channel, 1/A and 1/(A (1 - F_dr)).
    struct TetCoefficients {
        std::array<double, 3> kappa;
        std::array<double, 3> mua;
        double inv_a;
        double inv_a_one_minus_fdr;
    };
    std::vector<TetCoefficients> tet_coefficients;
};

// The topology-only part: options, pattern (offsets, columns, diagonal), tet_incidences and the
// boundary-face incidences (vertex_face_offsets/faces/slots). No geometry, coefficients or values:
// what a device assembly (gpu_assembly.h) needs from the host after a topology change. Throws
// InvalidArgumentError on a bad mm_per_unit or a connectivity that does not match the mesh.
DiffusionMatrix assemble_diffusion_pattern(const TetMesh& mesh, const TetConnectivity& connectivity,
                                           const AssemblyOptions& options = {});

// A tet's material as the assembly uses it: kappa and mu_a per channel, 1/A and 1/(A (1 - F_dr)).
DiffusionMatrix::TetCoefficients tet_diffusion_coefficients(const TetMaterial& material);

// Validates the materials of `which` (all when empty) in parallel; InvalidArgumentError names the
// lowest bad tet, so the message does not depend on scheduling.
void validate_tet_materials(const std::vector<TetMaterial>& materials, std::span<const int32_t> which = {});

// Builds pattern, geometry and values. materials: one per tet (validated: InvalidArgumentError names
// the first bad tet). Throws InvalidArgumentError on a non-positive or non-finite mm_per_unit or
// mismatched sizes, InvalidMeshError on a tet of non-positive volume.
DiffusionMatrix assemble_diffusion_matrix(const TetMesh& mesh, const TetConnectivity& connectivity,
                                          const std::vector<TetMaterial>& materials,
                                          const AssemblyOptions& options = {});

// Recomputes all values (three channels) and the source from new materials on the cached pattern and
// geometry: what a frame pays when materials change wholesale.
void assemble_diffusion_values(DiffusionMatrix& matrix, const TetConnectivity& connectivity,
                               const std::vector<TetMaterial>& materials);

// After the materials of `changed_tets` change (geometry and topology unchanged), rewrites exactly the
// rows of their vertices, in time proportional to those rows. Returns the rewritten rows, ascending.
// The result equals a full reassembly with the new materials.
std::vector<int32_t> update_diffusion_matrix(DiffusionMatrix& matrix, const TetMesh& mesh,
                                             const TetConnectivity& connectivity,
                                             const std::vector<TetMaterial>& materials,
                                             std::span<const int32_t> changed_tets);

// After vertices move with topology and materials unchanged (a deformation, a relaxation), recomputes
// the geometry of the tets and boundary faces around `moved_vertices` and rewrites exactly the rows of
// those tets' vertices, keeping the pattern. Returns the rewritten rows, ascending. The result equals
// a full reassembly on the new positions. Throws InvalidMeshError, leaving the matrix unchanged, when a
// tet around a moved vertex has non-positive volume.
std::vector<int32_t> update_diffusion_geometry(DiffusionMatrix& matrix, const TetMesh& mesh,
                                               const TetConnectivity& connectivity,
                                               std::span<const int32_t> moved_vertices);

// b = source * q for one channel (q per vertex; only boundary rows are non-zero).
void diffusion_right_hand_side(const DiffusionMatrix& matrix, const std::vector<std::array<double, 3>>& q,
                               int channel, std::span<double> b);

// Light that one corner of a boundary face receives apart from its vertex's q. Where the boundary folds
// (a crease, shading_surface.h) each face should integrate the light of its own side, while
// b = source * q above has one q per vertex; the corners where the two differ carry the difference.
struct CornerLight {
    int32_t face;                       // into TetConnectivity::boundary_faces (boundary_face_area)
    int32_t tet;                        // the tet the face belongs to (its 1 / (A (1 - F_dr)))
    std::array<int32_t, 3> vertices;    // the face's vertices, this corner first
    std::array<double, 3> delta;        // rgb: the corner's light minus q of its vertex
};

// b += the corners' share of Eq. 12 for one channel: the face's own source entries times delta, so that
// b = source * q plus this is sum_f sum_{j in f} s^f_ij q_j^f with q_j^f the light of j's corner in f.
// TransCut lumps s^f (8 S_f / (3 A (1 - F_dr)) on the corner's own row); FEM's consistent face mass
// also gives each of the face's other two rows half the corner's weight. The coefficients are read
// from the matrix when this runs, so corners stay valid across painting. `rows`, when not empty, is a
// per-vertex mask: only rows with a non-zero entry are added to (a partial refresh of b). Throws
// InvalidArgumentError for a corner outside the matrix or a bad channel or size.
void add_corner_light(const DiffusionMatrix& matrix, std::span<const CornerLight> corners, int channel,
                      std::span<double> b, std::span<const uint8_t> rows = {});

// Lumped volume per vertex (sum over its tets of V_t / 4, mm^3): the weights of vertex-based L2 norms.
std::vector<double> lumped_vertex_volumes(const DiffusionMatrix& matrix, const TetConnectivity& connectivity);

}  // namespace waxwork
