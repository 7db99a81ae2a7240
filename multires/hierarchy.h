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

#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"
#include "tetops/connectivity.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

struct HierarchyOptions {
    uint32_t seed = 1;                  // hash key of the independent-set codes
    bool enhance = true;                // the enhancement step of Sec. 4.1
    int64_t min_coarse_vertices = 1000; // do not coarsen a level smaller than this
    double max_keep_ratio = 0.8;        // discard a level keeping more than this fraction
    int max_levels = 16;                // including level 0
};

// Eq. 16 as a compressed-row operator: row v (a vertex of level l) lists the level-(l+1) vertices it
// interpolates from and the weights lambda_vk / lambda_v (one entry of weight 1 for a retained vertex).
struct InterpolationOperator {
    std::vector<int32_t> offsets{0};
    std::vector<int32_t> columns;
    std::vector<double> weights;

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

    size_t size() const { return diagonal.size(); }
    CsrMatrixView<double> view(int channel) const {
        return {size(), offsets.data(), columns.data(), values[static_cast<size_t>(channel)].data()};
    }
};

struct MultiresHierarchy {
    std::vector<HierarchyLevel> levels;  // levels[0] is the fine system
    double build_ms = 0;

    size_t level_count() const { return levels.size(); }
};

// Builds levels 1.. from the assembled fine system. positions: the mesh vertex positions (rest frame),
// for the inverse edge-length weights of Eq. 16. Deterministic for a given seed.
// Throws InvalidArgumentError when positions do not match the matrix.
MultiresHierarchy build_multires_hierarchy(const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                                           const HierarchyOptions& options = {});

// The vertices each coarse level keeps, without building any operator: entry l-1 lists the level-0
// vertices of level l (HierarchyLevel::original_vertex), for views and statistics. graph: G^0, the
// matrix pattern without the diagonal (the mesh's vertex_vertices). The same levels as
// build_multires_hierarchy on a matrix with this pattern and the same options, at the cost of the
// selections and coarse graphs only.
std::vector<std::vector<int32_t>> hierarchy_level_vertices(const CompressedRows& graph, const HierarchyOptions& options = {});

// Eq. 16 weights for one coarsening step: row v of the operator from the retained flags.
InterpolationOperator build_interpolation(const CompressedRows& graph, std::span<const uint8_t> retained,
                                          std::span<const int32_t> coarse_index,
                                          std::span<const int32_t> original_vertex,
                                          std::span<const Eigen::Vector3d> positions);

// Eq. 17: the coarse level's matrix (all three channels) on the coarse graph's pattern.
void build_coarse_matrix(const HierarchyLevel& fine, std::span<const int32_t> coarse_to_fine, HierarchyLevel& coarse);

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
