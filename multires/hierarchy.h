// The multi-resolution hierarchy of Li et al. 2013 (TransCut, Sec. 4): graphs G^l (Sec. 4.1), the
// interpolation from level l+1 to level l (Eq. 16) and the coarse systems (Eq. 17), for the three rgb
// channels of a DiffusionMatrix.
//
// Coarse systems. Substituting phi^l = P^l phi^{l+1} (Eq. 16) into the fine equations (Eq. 15) of the
// retained vertices gives Eq. 17: row i of M^{l+1} is row i of M^l times P^l, and b^{l+1}_i = b^l_i.
// In matrix form M^{l+1} = S M^l P^l with S the row selection of P^{l+1} (injection, not P^T), which is
// why the coarse matrices are not symmetric. Their pattern is i, its retained neighbours and the
// retained neighbours of its dropped neighbours: exactly the coarse graph row of i plus the diagonal.
//
// Precision. Coarse values are kept in double: coarse rows sum many fine entries of both signs
// (Eq. 10's weights can be negative), and the coarse solves are a small share of the time.
//
// Stopping rule. Levels are added while the current level has at least min_coarse_vertices vertices;
// a candidate level that keeps more than max_keep_ratio of its parent's vertices is discarded and
// stops the build (a coarse level that barely shrinks costs as much as its parent and gains nothing).
#pragma once

#include "multires/carried_rows.h"
#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "tetops/connectivity.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

// The weights lambda_ij of Eq. 16.
//
// InverseEdgeLength is the paper's ("currently we use the reciprocal of edge length", Sec. 4.2). Its
// weighted average of the retained neighbours does not reproduce linear functions: a dropped vertex
// whose retained neighbours are not centred on it gets the value of their weighted centroid, an error
// of order h |grad phi|. Substituted into the fine equations (Eq. 17) that error is amplified by the
// stiffness (order 1/h), which is why Eq. 17's exact level-1 solution stays about 12% from the fine
// solution on spot whatever the material or the resolution (bench part coarse_start).
//
// LinearExact (beyond the paper) keeps the paper's weights p_u = lambda_u / lambda_v and changes them
// by the least amount, in the norm sum_u (w_u - p_u)^2 / lambda_u, that makes the row reproduce linear
// functions: sum_u w_u = 1 and sum_u w_u (x_u - x_v) = 0 (a 4x4 system per dropped vertex, Lagrange
// multipliers). Rows where that is impossible or would extrapolate keep the paper's weights: fewer than
// four retained neighbours, neighbours (nearly) in a plane, or a weight below min_linear_exact_weight
// (a vertex on the boundary whose retained neighbours all lie to one side).
enum class InterpolationWeights { InverseEdgeLength, LinearExact };

struct HierarchyOptions {
    uint32_t seed = 1;                  // hash key of the independent-set codes
    InterpolationWeights weights = InterpolationWeights::InverseEdgeLength;
    // LinearExact: a row with a weight below this keeps the paper's weights. Mildly negative weights
    // are what linear exactness costs at a vertex whose neighbours are lopsided; strongly negative
    // ones extrapolate and amplify errors.
    double min_linear_exact_weight = -0.3;
    bool enhance = true;                // the enhancement step of Sec. 4.1
    int64_t min_coarse_vertices = 1000; // do not coarsen a level smaller than this
    double max_keep_ratio = 0.8;        // discard a level keeping more than this fraction
    int max_levels = 16;                // including level 0

    friend bool operator==(const HierarchyOptions&, const HierarchyOptions&) = default;
};

// Eq. 16 as a compressed-row operator: row v (a vertex of level l) lists the level-(l+1) vertices it
// interpolates from and the weights lambda_vk / lambda_v (one entry of weight 1 for a retained vertex).
struct InterpolationOperator {
    std::vector<int32_t> offsets{0};
    std::vector<int32_t> columns;
    std::vector<double> weights;
    // InterpolationWeights::LinearExact: how many rows of dropped vertices got linear-exact weights and
    // how many kept the paper's (HierarchyOptions::weights); zero with the paper's weights.
    int64_t linear_exact_rows = 0;
    int64_t paper_weight_rows = 0;

    size_t rows() const { return offsets.size() - 1; }
};

struct HierarchyLevel {
    // Per vertex of this level: its vertex at level 0 (identity at level 0).
    std::vector<int32_t> original_vertex;
    // Per vertex of this level: its vertex at level l-1 (empty at level 0).
    std::vector<int32_t> parent_vertex;
    // G^l: symmetric, rows sorted, no self loops.
    CompressedRows graph;
    // M^l on a compressed-row pattern with the diagonal included (columns ascending per row).
    std::vector<int32_t> offsets{0};
    std::vector<int32_t> columns;
    std::vector<int32_t> diagonal;
    std::array<std::vector<double>, 3> values;
    // From level l+1 to this level (empty on the coarsest level).
    InterpolationOperator interpolation;
    // How level l+1 was selected from this level (zero on the coarsest level).
    int independent_set_rounds = 0;
    int enhancement_passes = 0;
    int64_t enhancement_vertices = 0;
    // rebuild_multires_hierarchy: how many of this level's vertices had no previous vertex or a changed
    // row, around which the selection of level l+1 was made again (from scratch when they are more
    // than half); -1 when no row was compared (a fresh build, the levels below a level made from scratch).
    int64_t changed_vertices = -1;
    // rebuild_multires_hierarchy: how many of this level's Eq. 17 rows were copied from the previous
    // hierarchy rather than computed (0 on a fresh build and on level 0).
    int64_t copied_rows = 0;

    size_t size() const { return diagonal.size(); }
    CsrMatrixView<double> view(int channel) const {
        return {size(), offsets.data(), columns.data(), values[static_cast<size_t>(channel)].data()};
    }
};

// Where build_multires_hierarchy's time went, summed over the levels (milliseconds, wall clock).
struct HierarchyBuildTimes {
    double fine_level = 0;     // level 0: the copy of the matrix and G^0
    double selection = 0;      // independent sets and enhancement (Sec. 4.1)
    double interpolation = 0;  // Eq. 16
    double coarse_graph = 0;   // E^{l+1}
    double coarse_matrix = 0;  // Eq. 17
};

struct MultiresHierarchy {
    std::vector<HierarchyLevel> levels;  // levels[0] is the fine system
    // The level-0 positions Eq. 16's weights were computed from: a rebuild copies the interpolation
    // rows of vertices that did not move.
    std::vector<Eigen::Vector3d> positions;
    HierarchyOptions options;  // what it was built with (a rebuild must use the same)
    double build_ms = 0;
    HierarchyBuildTimes build_times;  // build_ms by phase

    size_t level_count() const { return levels.size(); }
};

// Builds levels 1.. from the assembled fine system. positions: the mesh vertex positions (rest frame),
// for the weights of Eq. 16. Deterministic for a given seed.
// Throws InvalidArgumentError when positions do not match the matrix or min_linear_exact_weight is
// not a finite number.
MultiresHierarchy build_multires_hierarchy(const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                                           const HierarchyOptions& options = {});

// The hierarchy of an edited system, carrying each level's selection over from `previous` (beyond the
// paper: it rebuilds after a cut, Sec. 5, from scratch). new_of_old_vertex: per level-0 vertex of
// `previous`, its vertex in `matrix` or -1 when the edit removed it (a cut's vertex map; the identity
// when only positions or values changed). Level by level, the vertices whose graph row is not their
// previous vertex's row (or that have none) and their dropped neighbours are selected again
// (update_coarse_vertices) and the rest keep their previous state, so the selection costs what the
// edit touched. Rows of Eq. 16, of the coarse graphs and of Eq. 17 that nothing changed reaches
// (no changed row, selection state, position or fine matrix value within their stencil) are copied
// from `previous` and renumbered, the others computed (carried_rows.h; copies happen only when the
// map keeps the surviving vertices' order, as a cut's compaction does, so they equal computed rows
// bit for bit). Levels past the previous hierarchy's depth are selected from scratch, and so are the
// first level where more than half of the rows changed and every coarser one (little would be left
// to carry). The result has every property the tests ask of a fresh build (independent-set cover, no
// lost connection, Eq. 17 on its own graphs) but is not the fresh build's selection. When no row
// changed (positions or values only) every selection is previous's, so a rebuild of a fresh build
// equals build_multires_hierarchy(matrix, positions, options) exactly without selecting anything
// again. Throws as build_multires_hierarchy, and InvalidArgumentError when `options` are not the ones
// `previous` was built with, the map's size is not previous's level-0 size, an entry is outside
// [-1, matrix.size()) or two vertices map to one.
MultiresHierarchy rebuild_multires_hierarchy(const MultiresHierarchy& previous, std::span<const int32_t> new_of_old_vertex,
                                             const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                                             const HierarchyOptions& options = {});

// The vertices each coarse level keeps, without building any operator: entry l-1 lists the level-0
// vertices of level l (HierarchyLevel::original_vertex), for views and statistics. graph: G^0, the
// matrix pattern without the diagonal (the mesh's vertex_vertices). The same levels as
// build_multires_hierarchy on a matrix with this pattern and the same options, at the cost of the
// selections and coarse graphs only.
std::vector<std::vector<int32_t>> hierarchy_level_vertices(const CompressedRows& graph, const HierarchyOptions& options = {});

// Eq. 16 weights for one coarsening step: row v of the operator from the retained flags, with the
// weights `options.weights` names (InterpolationWeights).
// With `carried` (a rebuild), its kept rows are copied from `previous` (carried_rows.h); only the
// paper's weights are carried (with LinearExact every row's counts must be known, so pass none).
InterpolationOperator build_interpolation(const CompressedRows& graph, std::span<const uint8_t> retained,
                                          std::span<const int32_t> coarse_index,
                                          std::span<const int32_t> original_vertex,
                                          std::span<const Eigen::Vector3d> positions,
                                          const HierarchyOptions& options = {}, const CarriedRows* carried = nullptr,
                                          const InterpolationOperator* previous = nullptr);

// Eq. 17: the coarse level's matrix (all three channels) on the coarse graph's pattern.
// With `carried` (a rebuild), the values of its kept rows are copied from `previous` (the previous
// coarse level, whose kept rows have the same pattern up to renumbering; carried_rows.h).
void build_coarse_matrix(const HierarchyLevel& fine, std::span<const int32_t> coarse_to_fine, HierarchyLevel& coarse,
                         const CarriedRows* carried = nullptr, const HierarchyLevel* previous = nullptr);

// Eq. 17 for the listed coarse rows only, on the existing pattern: row c depends on fine row
// coarse_to_fine[c] alone, so after the fine rows R changed, the rows c with coarse_to_fine[c] in R are
// all that change. Same arithmetic as build_coarse_matrix (bit-identical results).
void update_coarse_rows(const HierarchyLevel& fine, std::span<const int32_t> coarse_to_fine, HierarchyLevel& coarse,
                        std::span<const int32_t> rows);

// fine = P coarse (Eq. 16).
void interpolate(const InterpolationOperator& interpolation, std::span<const double> coarse, std::span<double> fine);

// b^l from b^0 by injection (b^{l+1}_i = b^l_i, Eq. 17).
void restrict_right_hand_side(const HierarchyLevel& level, std::span<const double> level0_b, std::span<double> b);

}  // namespace waxwork
