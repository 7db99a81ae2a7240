// A multigrid V-cycle on the independent-set hierarchy (multires/hierarchy.h), used as the
// preconditioner of CG on level 0 (multires/multigrid_cg.h). Beyond the paper: TransCut (Li et al.
// 2013, Sec. 4) only runs its levels once, coarse to fine; here the same graphs and the same Eq. 16
// interpolation P^l serve every CG iteration.
//
// Why Galerkin operators and not Eq. 17. A CG preconditioner must be symmetric positive definite.
// Eq. 17's coarse matrices S M^l P^l (S the row injection) are not symmetric, so a V-cycle built on
// them is not a symmetric operator and CG would lose its short recurrence. The Galerkin product
// A^{l+1} = (P^l)^T A^l P^l is symmetric, and positive definite whenever A^l is and P^l has full column
// rank (every retained vertex interpolates itself with weight 1, so it has). Its pattern is wider than
// Eq. 17's (row I reaches I -P- v -A- j -P- K, up to three fine hops), which costs setup time and memory,
// not correctness. The paper's operators remain in the hierarchy for MultiresSolver.
//
// Why this smoother. The V-cycle B = V(r) is symmetric when the post-smoother is the adjoint of the
// pre-smoother. A Chebyshev polynomial in D^-1 A is self-adjoint in the A inner product, so the same
// polynomial before and after (from a zero start before) gives a symmetric B, and it is fully parallel
// (Gauss-Seidel is sequential, or needs a colouring). B is positive definite when the smoother
// contracts, |p(lambda)| < 1 on the spectrum of D^-1 A: the polynomial is built on [upper/ratio, upper]
// with upper the Gershgorin bound max_i sum_j |a_ij| / a_ii, which is a true upper bound (a power
// iteration estimate could fall short and make high modes grow). The coarsest level is solved
// exactly by a sparse LDL^T factorisation (Eigen SimplicialLDLT, in double).
//
// Precision. The Galerkin products are formed in double (rows sum entries of both signs); the
// V-cycle runs in float when `single_precision` (half the memory traffic of the smoothing sweeps).
// The outer CG runs in double, so the preconditioner's rounding only changes how fast it converges,
// not what it converges to (bench/multires_bench.cpp measures both).
//
// Determinism. Every parallel loop writes disjoint rows and sums in a fixed order: identical results
// on any thread count.
#pragma once

#include "multires/hierarchy.h"

#include <array>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace waxwork {

// Where the entries dropped from a coarse operator go (MultigridOptions::drop_tolerance).
enum class DropLumping {
    // Their absolute values are added to the diagonal. The change diag(sum_j |e_ij|) - E is positive
    // semi-definite for either sign of e_ij ((x_i +- x_j)^2 terms), so the operator stays positive
    // definite by construction; but it is stiffer than the Galerkin one, and the coarse correction
    // weaker (on spot, 500K tets, drop 0.02: 7 MG-CG iterations to 1% instead of 2).
    Absolute,
    // Their signed values are added to the diagonal, preserving row sums (A 1, the smooth mode the
    // coarse levels exist for). Positive dropped entries keep definiteness, negative ones can lose it,
    // and on volumes of extreme slivers they do (a box of 16^3 cells flattened to 0.009 degree
    // dihedrals: the coarsest level is not positive definite). The setup checks every diagonal and the
    // coarsest factorisation; when either fails it is redone with Absolute lumping (see
    // MultigridOptions::fall_back_to_absolute), and MG-CG reports a preconditioner that is not
    // positive (r.Br < 0) as AlgorithmError. On spot it keeps 2-3 iterations with 40% of the operator
    // entries of the exact products (bench/multires_bench.cpp).
    RowSum,
};

struct MultigridOptions {
    int smoothing_steps = 2;         // Chebyshev degree, the same before and after the coarse correction
    double chebyshev_ratio = 8.0;    // the polynomial damps [upper / ratio, upper]
    bool single_precision = true;    // V-cycle vectors and smoothing matrices in float
    // Coarse entries with |a_ij| < drop_tolerance sqrt(a_ii a_jj) in every channel are dropped from the
    // Galerkin operator and added to the diagonal as `lumping` says (0: exact Galerkin products). The
    // exact products of Eq. 16's wide interpolation fill in (spot, 500K tets: 14, 55, 126, 179 entries
    // per row on levels 0-3, 3.6 times level 0's entries in all), which makes each V-cycle and the
    // setup expensive; 0.02 keeps 1.45 times level 0's.
    double drop_tolerance = 0.02;
    DropLumping lumping = DropLumping::RowSum;
    // When a RowSum setup fails (a coarse diagonal or the coarsest factorisation not positive), build
    // again with Absolute lumping, which is positive definite by construction (stability study,
    // "slivers, multigrid"). false: throw the AlgorithmError instead.
    bool fall_back_to_absolute = true;

    friend bool operator==(const MultigridOptions&, const MultigridOptions&) = default;
};

class MultigridPreconditioner {
public:
    // Galerkin operators for all three channels on the hierarchy's levels and interpolation. The
    // hierarchy must outlive the preconditioner (its interpolation operators are borrowed).
    // Throws AlgorithmError when a diagonal is not positive or the coarsest factorisation fails.
    explicit MultigridPreconditioner(const MultiresHierarchy& hierarchy, const MultigridOptions& options = {});
    // The same after an edit, reusing `previous`: `hierarchy` was rebuilt (rebuild_multires_hierarchy)
    // from the hierarchy `previous` was built on, which must still be alive, and new_of_old_vertex is
    // the edit's level-0 vertex map. A row of A P whose matrix row and interpolation rows the edit left
    // unchanged up to renumbering, and a Galerkin row whose P^T row, A P rows and drop-test diagonals it
    // left unchanged, is copied from `previous` with renumbered columns instead of being accumulated
    // again (beyond the paper; an edit changes a region, the products of the rest stay). A copied row
    // is what the accumulation would give, bit for bit (same sums in the same order), so the result
    // equals MultigridPreconditioner(hierarchy, options) (tested). Copies need an order-preserving map
    // and the options `previous` ended with (its lumping after a fallback); otherwise every row is
    // computed. Throws as the other constructor, and InvalidArgumentError when the map does not fit.
    MultigridPreconditioner(const MultiresHierarchy& hierarchy, const MultigridPreconditioner& previous,
                            std::span<const int32_t> new_of_old_vertex, const MultigridOptions& options = {});
    ~MultigridPreconditioner();
    MultigridPreconditioner(const MultigridPreconditioner&) = delete;
    MultigridPreconditioner& operator=(const MultigridPreconditioner&) = delete;

    // The hierarchy the operators were built on.
    const MultiresHierarchy& hierarchy() const { return hierarchy_; }
    size_t level_count() const;
    // Rows and stored entries of level l's Galerkin operator (level 0: the fine matrix).
    size_t rows(size_t level) const;
    size_t nonzeros(size_t level) const;
    // Level l's operator for one channel, in double (for tests).
    CsrMatrixView<double> view(size_t level, int channel) const;
    double setup_ms() const { return setup_ms_; }
    // The rebuild constructor's copies: rows of level l's A P (to level l + 1) and of level l's Galerkin
    // operator taken from the previous preconditioner (zero after the other constructor).
    size_t copied_product_rows(size_t level) const;
    size_t copied_operator_rows(size_t level) const;
    // The lumping the operators were built with: Absolute after a RowSum setup failed, with the reason.
    DropLumping lumping() const { return options_.lumping; }
    const std::string& lumping_fallback_reason() const { return lumping_fallback_reason_; }

    // What a device V-cycle (gpu_multigrid_preconditioner.h) needs to run the same algorithm with the
    // same coefficients. Level l's position of (i, i) in its stored entries:
    std::span<const int32_t> diagonal(size_t level) const;
    // P^l (level l from level l + 1; Eq. 16 weights) and its transpose. Throws on the coarsest level.
    const InterpolationOperator& interpolation(size_t level) const;
    const InterpolationOperator& transposed_interpolation(size_t level) const;
    // The smoother's polynomial on level l per channel (Saad, Iterative Methods, Alg. 12.1 on D^-1 A):
    // the first step from a residual r = D^-1 (b - A x) is d = inv_theta r; step s >= 2 (index s - 2)
    // is d = c_d d + c_r D^-1 (b - A x). Computed in double; the float V-cycle rounds each to float.
    struct Chebyshev {
        std::array<double, 3> inv_theta{};
        std::vector<std::array<double, 3>> c_d, c_r;  // smoothing_steps - 1 entries
    };
    Chebyshev chebyshev(size_t level) const;
    // x = A_L^-1 b on the coarsest level L for three interleaved channels (x[3 i + c]), by the exact
    // factorisation the V-cycle uses: b is widened to double, x rounded to float, as apply_rgb does.
    // Throws InvalidArgumentError on a size mismatch. Not thread-safe.
    void solve_coarsest_rgb(std::span<const float> b, std::span<float> x);
    // x = A_L^-1 b on the coarsest level for one channel, in double (the cascadic solver's coarsest
    // solve, cascadic_solver.h). Throws InvalidArgumentError on a size mismatch or a bad channel. Not
    // thread-safe.
    void solve_coarsest(int channel, std::span<const double> b, std::span<double> x);

    // z = B r for one channel: one V-cycle from a zero start. Not thread-safe (shared work vectors).
    void apply(int channel, std::span<const double> r, std::span<double> z);

    // The three channels at once, vectors interleaved (r[3 i + c] is channel c at vertex i): one sweep
    // over each level's pattern serves all three channels, so a V-cycle reads the column indices once
    // instead of three times. Inside, a vertex's (and a stored entry's) channels are one four-lane
    // vector (r, g, b, 0), so each row operation is one SIMD operation for the three channels. The
    // arithmetic per channel is the same, in the same order, as apply()'s: the result equals three
    // apply() calls exactly (tested). Not thread-safe.
    void apply_rgb(std::span<const double> r, std::span<double> z);

    // After the level-0 values changed in the rows `changed_rows` (ascending; pattern and hierarchy
    // unchanged; the hierarchy's level 0 already holds the new values): recomputes exactly the coarse
    // rows that depend on them, level by level, and refactorises the coarsest level if it was
    // reached (level 0 itself in a one-level hierarchy). The result equals a new preconditioner built
    // on the updated hierarchy. Returns the rows recomputed on every level (level 0: changed_rows), so a
    // device copy can upload only those (GpuMultigridPreconditioner::update_values).
    std::vector<std::vector<int32_t>> update_values(std::span<const int32_t> changed_rows);

private:
    struct Level;
    struct Accumulator;
    struct CarriedLevel;
    // build_levels, redone with absolute lumping when a row-sum build fails (MultigridOptions).
    void build(const MultigridPreconditioner* previous, std::span<const int32_t> new_of_old_vertex);
    // With `previous`: copies the rows the edit left unchanged (the rebuild constructor).
    void build_levels(const MultigridPreconditioner* previous, std::span<const int32_t> new_of_old_vertex);
    // A P's pattern and values, then P^T A P's kept pattern and values (compute_galerkin_rows' result);
    // with `carried`, rows the edit left unchanged are copied from the previous preconditioner.
    void build_galerkin_operator(size_t l, const CarriedLevel* carried);
    void compute_product_rows(size_t l, std::span<const int32_t> rows);
    void accumulate_galerkin_row(size_t l, size_t row, Accumulator& acc) const;
    static void clear(Accumulator& acc);
    void compute_galerkin_rows(size_t l, std::span<const int32_t> rows);
    void prepare_smoother(size_t l, std::span<const int32_t> rows);
    void factorize_coarsest();
    template <typename Scalar>
    void vcycle(size_t l, int channel);
    template <typename Scalar>
    void vcycle_rgb(size_t l);

    const MultiresHierarchy& hierarchy_;
    MultigridOptions options_;
    std::vector<std::unique_ptr<Level>> levels_;
    double setup_ms_ = 0;
    std::string lumping_fallback_reason_;
    std::vector<size_t> copied_product_rows_, copied_operator_rows_;  // per level
};

// A hierarchy and the preconditioner built on it, owned together (the preconditioner borrows the
// hierarchy): what a device solver takes over when they were built beforehand on the host (the live
// solver builds them when an edit arrives, rebuilt from the previous ones, and hands them over at the
// next GPU frame, when the context is current).
struct MultigridOperators {
    std::unique_ptr<MultiresHierarchy> hierarchy;
    std::unique_ptr<MultigridPreconditioner> preconditioner;  // built on *hierarchy, or null
};

}  // namespace waxwork
