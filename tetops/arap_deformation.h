// As-rigid-as-possible deformation of the tet volume (Sorkine and Alexa 2007, "As-Rigid-As-Possible
// Surface Modeling", in its volumetric form), for dragging a region of one body with others pinned.
//
// Energy. The paper's Eq. 3 sums, per vertex i, w_ij ||(p'_i - p'_j) - R_i (p_i - p_j)||^2 over the
// one-ring with one rotation per vertex. We use one rotation per tet instead:
//     E(x) = sum_t vol_t ||F_t(x) - R_t||_F^2,
// F_t the (constant) deformation gradient of tet t. Expanding it gives the same global matrix as the
// paper's Eq. 9 with the 3D cotangent weights (w_ij = 1/6 sum over the tets around edge ij of
// l_kl cot theta_kl, the stiffness matrix of linear tets), so the global step is the paper's; but the
// local step (Eq. 5-6: R = V U^T of the SVD of the covariance) works on one tet's F_t rather than on a
// one-ring's covariance, which in 3D mixes negative cotangent weights (obtuse dihedral angles) into
// the covariance and can make the fitted rotation meaningless. Per tet, E = 0 exactly when every tet
// moves rigidly, which is what "a tet keeps its shape" means for the tests and the guard. The cost is
// one 3x3 polar decomposition per tet (about 4 tets per vertex) per iteration, run in parallel.
//
// Slivers. The energy integrates over volume, so a sliver (tiny volume) costs almost nothing to
// distort and the global step leaves the strain there: in a volume that cuts and relaxation have left
// with tets near the 0.5 degree guard, those tets are the ones a step would push under it, and the guard
// then shortens every step of the drag. Each tet's term is weighted by w_t = vol_t max(1, 10 deg /
// theta_t), theta_t its minimum dihedral angle at rest: well-shaped tets keep the paper's weights,
// slivers become stiffer in proportion to how thin they are (docs/deformation.md measures the
// difference). E below is this weighted sum.
inline constexpr double kStiffSliverAngleDeg = 10;

// Local/global iterations (paper Sec. 3): with the positions fixed, each R_t is the rotation nearest
// F_t (Eq. 6 and the remark after it: the SVD's U V^T with the reflection fixed; computed as the
// polar factor by Newton's iteration where det F_t > 0, by Jacobi SVD elsewhere); with the
// rotations fixed, the positions solve K x = sum_t vol_t R_t B_t^T, K fixed for a fixed set of
// constrained vertices (Eq. 9: constrained vertices move to the right-hand side). K is factored once
// per constraint set (sparse Cholesky, ArapFactor), so a drag frame costs only polar decompositions
// and triangular solves. Each frame starts from the previous frame's positions (warm start), so a few
// iterations per frame keep up with a drag.
#pragma once

#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace waxwork {

class Progress;

// How K is factored and the global step's triangular solves run. The three coordinates share K, so
// a solve has three right-hand sides. Without CHOLMOD in the build every choice is Eigen's.
enum class ArapFactor {
    // CHOLMOD's supernodal factorisation (dense BLAS kernels per supernode), then converted to a
    // simplicial LL^T without the explicit zeros of relaxed amalgamation: its solves take the three
    // columns in one pass over L with no BLAS call, where the supernodal solves make two small BLAS
    // calls (triangular solve, product) per supernode and per direction.
    CholmodSimplicialSolves,
    // CHOLMOD's supernodal factor and solves.
    CholmodSupernodal,
    // Eigen's SimplicialLLT (its own AMD ordering, up-looking factorisation, one pass per column).
    EigenSimplicialLLT,
};

// The local step's arithmetic. Float runs Newton's polar iteration in single precision on four tets
// at once (vectorised) and is meant for previews: its rotations are orthogonal to float precision, so
// the energy and positions differ slightly from the double ones (the tests bound it); anything
// committed or replayed uses Double.
enum class ArapRotations { Double, Float };

struct ArapOptions {
    ArapFactor factor = ArapFactor::CholmodSimplicialSolves;
    ArapRotations rotations = ArapRotations::Double;
};

// The energy after an ARAP solve, and what ran.
struct ArapSolveReport {
    int iterations = 0;
    double energy = 0;  // E(x) above for the returned positions, in (model units)^3
};

// State that persists while dragging one body: the rest shape, the per-tet gradient operators, the
// factorisation for the current constrained vertices, and the current positions (the warm start).
// Positions are indexed like the mesh's vertices; only vertices of the body's tets ever move.
class ArapDeformer {
public:
    // `body_tets`: the tets deformed (indices into mesh.tets, typically one connected body of one
    // piece: select_deform_body). Positions are in the piece's rest frame. Throws InvalidArgumentError
    // for an empty body, an index out of range or a tet with non-positive volume.
    ArapDeformer(const TetMesh& mesh, std::vector<int32_t> body_tets, ArapOptions options = {});
    ~ArapDeformer();
    ArapDeformer(ArapDeformer&&) noexcept;
    ArapDeformer& operator=(ArapDeformer&&) noexcept;

    // The vertices held at targets (handle and pinned), each a vertex of the body. Refactors only when
    // the set differs from the current one (order matters for solve's targets, not for the factor).
    // Throws InvalidArgumentError when a vertex is not in the body or no body vertex is left free,
    // and when the set is empty (the body could then drift and K is singular).
    void set_constrained(std::vector<int32_t> constrained);
    const std::vector<int32_t>& constrained() const { return constrained_; }
    // Times set_constrained actually refactored (for tests and benchmarks).
    int factorizations() const { return factorizations_; }

    // `iterations` local/global steps from the current positions with constrained()[i] held at
    // targets[i]; the current positions become the result. Throws InvalidArgumentError when the
    // sizes differ, a target is not finite or iterations < 1, and when no constraint is set.
    ArapSolveReport solve(std::span<const Eigen::Vector3d> targets, int iterations);

    // The current positions (all mesh vertices; vertices outside the body stay at rest).
    const std::vector<Eigen::Vector3d>& positions() const { return positions_; }
    // Replaces the warm start (e.g. with positions a guarded line search accepted). Must have one
    // entry per mesh vertex.
    void set_positions(std::vector<Eigen::Vector3d> positions);
    // Resets the positions to the rest shape.
    void reset();
    // E of the current positions (one local step).
    double energy() const;

    const ArapOptions& options() const { return options_; }
    // The local step's arithmetic from now on (the factor is kept).
    void set_rotations(ArapRotations rotations) { options_.rotations = rotations; }

    const std::vector<int32_t>& body_tets() const { return body_tets_; }
    // Vertices of the body's tets, ascending.
    const std::vector<int32_t>& body_vertices() const { return body_vertices_; }

private:
    struct Factor;
    void local_step();
    void global_step(std::span<const Eigen::Vector3d> targets);
    void reset_rotations();  // every R_t = I

    ArapOptions options_;
    std::vector<Eigen::Vector3d> rest_;
    std::vector<Eigen::Vector3d> positions_;
    std::vector<Tet> tets_;                 // the body's tets, mesh vertex indices
    std::vector<int32_t> body_tets_;
    std::vector<int32_t> body_vertices_;
    std::vector<Eigen::Matrix<double, 4, 3>> gradients_;  // B_t: F_t = [x0 x1 x2 x3] B_t
    std::vector<double> weights_;           // w_t: the volume, larger for slivers (see the top)
    // Per tet, w_t B_t R_t^T: its corners' shares of the global step's right-hand side, made where R_t is
    // found (the local step streams over the tets with B_t at hand; the global step then gathers
    // 3 numbers per corner instead of B_t, R_t and a product).
    std::vector<Eigen::Matrix<double, 4, 3>> rhs_shares_;
    bool rotations_current_ = false;        // rhs_shares_ fit positions_ (saves a local step per frame)
    double energy_ = 0;                     // E for positions_ when rotations_current_
    CompressedRows vertex_tets_;            // per body vertex (local index): its body tets (local index)
    std::vector<int32_t> local_index_;      // mesh vertex -> index in body_vertices_, or -1
    std::vector<int32_t> constrained_;
    std::vector<int32_t> free_index_;       // body vertex (local) -> row of K_ff, or -1 if constrained
    std::vector<int32_t> free_vertices_;    // row of K_ff -> body vertex (local)
    std::unique_ptr<Factor> factor_;
    int factorizations_ = 0;
};

// The body a drag at `grab` deforms: the tets of `piece` reachable through shared vertices from a
// vertex `seed`. Vertices of other bodies (other pieces, detached parts) stay where they are.
std::vector<int32_t> vertex_connected_tets(const TetMesh& mesh, const TetConnectivity& connectivity, int32_t seed);

// The handle: the falloff w(d) = (1 - (d/R)^2)^2 for distance d < R from the grab point, 0 beyond (C1
// at R, 1 at the centre), selects it: the vertices with w >= kHandleMinWeight, the ball of radius
// R sqrt(1 - sqrt(0.5)) ~ 0.54 R. The handle moves as one rigid grip (HandleMotion) and ARAP shapes
// everything between it and the pins. Moving each handle vertex by w of the motion instead (the rim
// by half, the centre by all of it) shears the handle itself: a torus lifted by about the handle's
// width then had tets pushed under the angle guard at any number of iterations, and five times the
// energy of the rigid grip (docs/deformation.md).
inline constexpr double kHandleMinWeight = 0.5;
double handle_falloff(double distance, double radius);

// A sphere whose vertices stay where they are.
struct PinSphere {
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    double radius = 0;
    friend bool operator==(const PinSphere&, const PinSphere&) = default;
};

// How the handle moves: Grab translates it, Bend turns it about an axis, Twist turns it about an axis by
// an angle that grows along the axis. The whole handle follows the motion (see kHandleMinWeight).
struct HandleMotion {
    enum class Kind { Translate, Bend, Twist };
    Kind kind = Kind::Translate;
    Eigen::Vector3d move = Eigen::Vector3d::Zero();                 // Translate
    Eigen::Vector3d axis_point = Eigen::Vector3d::Zero();           // Bend, Twist
    Eigen::Vector3d axis_direction = Eigen::Vector3d::UnitZ();      // Bend, Twist; need not be unit
    double angle = 0;  // Bend: radians; Twist: radians per unit length along the axis

    static HandleMotion translation(const Eigen::Vector3d& move);
    static HandleMotion bend(const Eigen::Vector3d& axis_point, const Eigen::Vector3d& axis_direction, double angle_rad);
    static HandleMotion twist(const Eigen::Vector3d& axis_point, const Eigen::Vector3d& axis_direction,
                              double angle_per_length);
    // The same motion seen in a piece's rest frame (world = rotation * rest + translation).
    HandleMotion in_rest_frame(const RigidTransform& piece) const;
    // Where a point goes under the fraction `f` of the motion.
    Eigen::Vector3d apply(const Eigen::Vector3d& point, double f) const;
    friend bool operator==(const HandleMotion&, const HandleMotion&) = default;
};

// InvalidArgumentError when the motion is not finite or a Bend or Twist axis has zero direction.
void validate_handle_motion(const HandleMotion& motion);

// What a drag holds, in the rest frame of the body's piece. Positions of one piece are rest-frame
// coordinates; grab, move and pins are in world space and mapped through the piece's transform.
struct DragRegion {
    int32_t piece = 0;
    std::vector<int32_t> body_tets;        // vertex_connected_tets of the handle vertex nearest the grab
    std::vector<int32_t> handle;           // weight >= kHandleMinWeight, not pinned
    std::vector<int32_t> pinned;           // body vertices inside a pin sphere
    HandleMotion motion_rest;              // the world motion in the piece's rest frame
    // handle then pinned: the order ArapDeformer::set_constrained and drag_targets use.
    std::vector<int32_t> constrained() const;
};

// Selects the body, handle and pins for a drag of `motion` (world) at `grab` (world) with falloff
// radius `radius`. Throws InvalidArgumentError (naming the problem, for the caller to prefix with
// its options) when radius <= 0 or anything is not finite, a Bend or Twist axis has zero direction,
// no vertex has weight >= kHandleMinWeight,
// every handle vertex is pinned, or handle and pins together hold every vertex of the body.
DragRegion select_drag_region(const TetMesh& mesh, const TetConnectivity& connectivity, const Eigen::Vector3d& grab,
                              double radius, const HandleMotion& motion, std::span<const PinSphere> pins);

// Targets for region.constrained() after the fraction `t` in [0, 1] of the motion: handle vertices
// moved by the fraction t of motion_rest (rest + t move for a translation), pinned at rest.
std::vector<Eigen::Vector3d> drag_targets(const DragRegion& region, std::span<const Eigen::Vector3d> rest, double t);

// Targets for the Bend and Twist tools: `points` rotated about the axis through `axis_point` along
// `axis_direction` (need not be unit; must be non-zero), by `angle_rad` (bend: one rigid rotation) or
// by angle_per_length * s (twist, s the signed distance of the point along the axis from axis_point).
std::vector<Eigen::Vector3d> bend_about_axis(std::span<const Eigen::Vector3d> points, const Eigen::Vector3d& axis_point,
                                             const Eigen::Vector3d& axis_direction, double angle_rad);
std::vector<Eigen::Vector3d> twist_about_axis(std::span<const Eigen::Vector3d> points, const Eigen::Vector3d& axis_point,
                                              const Eigen::Vector3d& axis_direction, double angle_per_length);

// The quality guard of a deformation step, as for cuts and relaxation (relaxation.h: 0.5 degrees).
struct GuardOptions {
    double min_dihedral_guard_deg = 0.5;
    int max_halvings = 30;  // 2^-30 of a step is below any meaningful motion
};

struct GuardedStep {
    std::vector<Eigen::Vector3d> positions;  // old + fraction * (new - old), all mesh vertices
    double fraction = 1;      // 1: the whole step; 0: none of it passed (positions == old)
    int halvings = 0;
    bool shortened() const { return fraction < 1; }
    double min_dihedral_deg = 0;  // over the checked tets at the accepted positions
    size_t inverted_tets = 0;     // checked tets with non-positive volume at the accepted positions
};

// Line search from `old_positions` to `new_positions` over `tets` (indices into mesh.tets; the tets
// whose vertices may move): halves the step until no tet is inverted and no tet's minimum dihedral
// angle is under the guard, or under its value at `old_positions` when it was already below (a tet
// already under the guard may not get worse). Both arrays hold one position per mesh vertex.
// `floor_cosine`, when not empty, gives per tet of `tets` the cosine of the least angle it may end with
// instead (from guard_floors): a drag previewed frame by frame holds its tets to the angles they had
// before the drag, computed once, rather than measuring the previous frame's angles every frame.
// Angles are compared through their cosines (max_dihedral_cosine), so a check costs no arc cosine.
GuardedStep guard_step(const TetMesh& mesh, std::span<const int32_t> tets,
                       std::span<const Eigen::Vector3d> old_positions, std::span<const Eigen::Vector3d> new_positions,
                       const GuardOptions& options = {}, std::span<const double> floor_cosine = {});
// Per tet of `tets`, the cosine of the least angle guard_step lets it end with from `positions`: the
// guard, or its angle there when that is lower (less 1e-9 degrees: a rigid motion changes the angles
// by rounding).
std::vector<double> guard_floors(std::span<const int32_t> tets, const std::vector<Tet>& mesh_tets,
                                 std::span<const Eigen::Vector3d> positions, const GuardOptions& options);

// A whole drag from the deformer's current positions, as the editor's frames run it: the move in
// `steps` equal increments, each `iterations` local/global steps warm-started from the previous one
// and then guarded (guard_step over the body's tets); a shortened step's positions become the warm
// start of the next, so the handle lags behind its target rather than breaking a tet. `rest` holds
// the positions the targets are measured from (drag_targets). Throws InvalidArgumentError for
// steps < 1 or iterations < 1. `progress`, when given, names the stage, gets the fraction of steps
// done, and stops the drag between steps with CancelledError (the deformer then holds a partial drag;
// reset it).
struct DragReport {
    int steps = 0;
    int iterations_per_step = 0;
    size_t body_tets = 0, handle_vertices = 0, pinned_vertices = 0;  // the region's sizes
    double factorization_ms = 0;  // factoring K for the region's constraints (0 when the factor was kept)
    double energy = 0;            // ARAP energy of the final positions
    int shortened_steps = 0;      // steps the guard shortened
    double last_step_fraction = 1;
    double handle_error = 0;      // largest distance of a handle vertex from its final target
    double min_dihedral_deg = 0;  // over the body's tets at the end
    size_t inverted_tets = 0;     // of the body's tets at the end (0 unless the input had some)
};
DragReport run_drag(ArapDeformer& deformer, const TetMesh& mesh, const DragRegion& region,
                    std::span<const Eigen::Vector3d> rest, int steps, int iterations, const GuardOptions& guard = {},
                    Progress* progress = nullptr);

}  // namespace waxwork
