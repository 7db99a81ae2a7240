#include "multires/multigrid_preconditioner.h"

#include "base/parallel_rows.h"
#include "multires/carried_rows.h"
#include "multires/link_union.h"
#include "solver/reference/reference_solvers.h"

#include "base/error.h"
#include "tetops/vertex_map.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>

namespace waxwork {

namespace {

constexpr size_t kGrain = 1024;

// P^T as compressed rows: row I lists the fine vertices v with P_vI != 0 in ascending v.
InterpolationOperator transpose(const InterpolationOperator& p, size_t coarse_rows) {
    InterpolationOperator t;
    t.offsets.assign(coarse_rows + 1, 0);
    for (int32_t c : p.columns) ++t.offsets[static_cast<size_t>(c) + 1];
    std::partial_sum(t.offsets.begin(), t.offsets.end(), t.offsets.begin());
    t.columns.resize(p.columns.size());
    t.weights.resize(p.columns.size());
    std::vector<int32_t> next(t.offsets.begin(), t.offsets.end() - 1);
    for (size_t v = 0; v < p.rows(); ++v) {
        for (int32_t q = p.offsets[v]; q < p.offsets[v + 1]; ++q) {
            const auto slot = static_cast<size_t>(next[static_cast<size_t>(p.columns[static_cast<size_t>(q)])]++);
            t.columns[slot] = static_cast<int32_t>(v);
            t.weights[slot] = p.weights[static_cast<size_t>(q)];
        }
    }
    return t;
}

}  // namespace

// The smoother's arrays and the work vectors of one level in the V-cycle's precision.
template <typename Scalar>
struct MultigridLevelData {
    std::array<std::vector<Scalar>, 3> values;    // the operator, per channel
    std::array<std::vector<Scalar>, 3> inv_diag;  // 1 / a_ii
    std::vector<Scalar> p_weights, pt_weights;    // P (this level to the next) and P^T
    std::vector<Scalar> b, x, r, d;
};

// Four lanes of a GCC/Clang vector type: channels r, g, b and an unused zero lane. Holding a vertex's
// (or a stored entry's) three channels in one 16-byte vector lets every row operation of the V-cycle be
// one SIMD operation for all channels (SSE2, the baseline of x86-64) instead of three scalar ones;
// lane-wise IEEE arithmetic rounds exactly as the scalar code does.
template <typename Scalar>
struct RgbLanes;
template <>
struct RgbLanes<float> {
    typedef float type __attribute__((vector_size(16)));
};
template <>
struct RgbLanes<double> {
    typedef double type __attribute__((vector_size(32)));
};

// The same for apply_rgb: one RgbLanes vector per stored entry and per row.
template <typename Scalar>
struct MultigridRgbLevelData {
    using V = typename RgbLanes<Scalar>::type;
    std::vector<V> values;    // per stored entry
    std::vector<V> inv_diag;  // per row
    std::vector<V> b, x, r, d, y;  // per row; y: the next smoothing iterate (swapped with x)
};

struct MultigridPreconditioner::Level {
    size_t n = 0;
    std::vector<int32_t> offsets{0}, columns, diagonal;
    std::array<std::vector<double>, 3> values;  // the operator in double
    std::array<std::vector<double>, 3> row_bound;  // sum_j |a_ij| / a_ii per row (Gershgorin)
    std::array<double, 3> upper{};                 // max of row_bound
    const InterpolationOperator* p = nullptr;      // to this level from the next (null on the coarsest)
    InterpolationOperator pt;                      // P^T
    // A P (this level's operator times P, all channels), kept for partial updates.
    std::vector<int32_t> ap_offsets{0}, ap_columns;
    std::array<std::vector<double>, 3> ap_values;
    // Coarse levels: P^T A P's diagonal before dropping (the drop test's), which a rebuild compares.
    std::array<std::vector<double>, 3> product_diagonal;
    // Coarse levels, per row: recomputed by update_values on the kept pattern of an earlier build,
    // which the drop test on the new values might not choose, so a rebuild copies neither the row
    // nor rows whose drop test reads its diagonal.
    std::vector<uint8_t> updated_on_old_pattern;
    MultigridLevelData<float> f;
    MultigridLevelData<double> d;
    MultigridRgbLevelData<float> rgb_f;
    MultigridRgbLevelData<double> rgb_d;
    std::array<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>, 3> coarsest;  // coarsest level only
    Eigen::VectorXd coarse_rhs, coarse_solution;

    template <typename Scalar>
    MultigridLevelData<Scalar>& data() {
        if constexpr (std::is_same_v<Scalar, float>)
            return f;
        else
            return d;
    }
    template <typename Scalar>
    MultigridRgbLevelData<Scalar>& rgb() {
        if constexpr (std::is_same_v<Scalar, float>)
            return rgb_f;
        else
            return rgb_d;
    }
};

MultigridPreconditioner::~MultigridPreconditioner() = default;

size_t MultigridPreconditioner::level_count() const { return levels_.size(); }
size_t MultigridPreconditioner::rows(size_t level) const { return levels_.at(level)->n; }
size_t MultigridPreconditioner::nonzeros(size_t level) const { return levels_.at(level)->columns.size(); }
CsrMatrixView<double> MultigridPreconditioner::view(size_t level, int channel) const {
    const Level& l = *levels_.at(level);
    return {l.n, l.offsets.data(), l.columns.data(), l.values.at(static_cast<size_t>(channel)).data()};
}

std::span<const int32_t> MultigridPreconditioner::diagonal(size_t level) const { return levels_.at(level)->diagonal; }

const InterpolationOperator& MultigridPreconditioner::interpolation(size_t level) const {
    const Level& l = *levels_.at(level);
    if (!l.p) throw InvalidArgumentError("multigrid: level " + std::to_string(level) + " is the coarsest (no P)");
    return *l.p;
}

const InterpolationOperator& MultigridPreconditioner::transposed_interpolation(size_t level) const {
    interpolation(level);  // the same check
    return levels_[level]->pt;
}

MultigridPreconditioner::Chebyshev MultigridPreconditioner::chebyshev(size_t level) const {
    const Level& l = *levels_.at(level);
    Chebyshev out;
    std::array<double, 3> delta{}, sigma{}, rho{};
    for (size_t ch = 0; ch < 3; ++ch) {
        const double upper = l.upper[ch], lower = upper / options_.chebyshev_ratio;
        const double theta = 0.5 * (upper + lower);
        delta[ch] = 0.5 * (upper - lower);
        sigma[ch] = theta / delta[ch];
        out.inv_theta[ch] = 1.0 / theta;
        rho[ch] = 1.0 / sigma[ch];
    }
    for (int step = 1; step < options_.smoothing_steps; ++step) {
        std::array<double, 3> c_d{}, c_r{};
        for (size_t ch = 0; ch < 3; ++ch) {
            const double rho_next = 1.0 / (2.0 * sigma[ch] - rho[ch]);
            c_d[ch] = rho_next * rho[ch];
            c_r[ch] = 2.0 * rho_next / delta[ch];
            rho[ch] = rho_next;
        }
        out.c_d.push_back(c_d);
        out.c_r.push_back(c_r);
    }
    return out;
}

void MultigridPreconditioner::solve_coarsest_rgb(std::span<const float> b, std::span<float> x) {
    Level& level = *levels_.back();
    const size_t n = level.n;
    if (b.size() != 3 * n || x.size() != 3 * n)
        throw InvalidArgumentError("multigrid solve_coarsest_rgb: vectors of size " + std::to_string(b.size()) +
                                   " and " + std::to_string(x.size()) + " for 3 x " + std::to_string(n) + " entries");
    for (size_t ch = 0; ch < 3; ++ch) {
        for (size_t i = 0; i < n; ++i) level.coarse_rhs[static_cast<Eigen::Index>(i)] = static_cast<double>(b[3 * i + ch]);
        level.coarse_solution = level.coarsest[ch].solve(level.coarse_rhs);
        for (size_t i = 0; i < n; ++i) x[3 * i + ch] = static_cast<float>(level.coarse_solution[static_cast<Eigen::Index>(i)]);
    }
}

void MultigridPreconditioner::solve_coarsest(int channel, std::span<const double> b, std::span<double> x) {
    Level& level = *levels_.back();
    if (channel < 0 || channel > 2) throw InvalidArgumentError("multigrid solve_coarsest: channel must be 0, 1 or 2");
    if (b.size() != level.n || x.size() != level.n)
        throw InvalidArgumentError("multigrid solve_coarsest: vectors of size " + std::to_string(b.size()) + " and " +
                                   std::to_string(x.size()) + " for " + std::to_string(level.n) + " entries");
    const auto n = static_cast<Eigen::Index>(level.n);
    level.coarse_solution = level.coarsest[static_cast<size_t>(channel)].solve(Eigen::Map<const Eigen::VectorXd>(b.data(), n));
    std::copy(level.coarse_solution.begin(), level.coarse_solution.end(), x.begin());
}

// A level pair (l, l + 1) of the previous preconditioner, for the rebuild constructor, and the maps
// between its vertices and the new ones (-1: none).
struct MultigridPreconditioner::CarriedLevel {
    const Level* old_fine = nullptr;
    const Level* old_coarse = nullptr;
    std::vector<int32_t> old_of_new_fine;    // new level-l vertex -> previous
    std::vector<int32_t> new_of_old_fine;    // previous level-l vertex -> new
    std::vector<int32_t> old_of_new_coarse;  // new level-(l+1) vertex -> previous
    std::vector<int32_t> new_of_old_coarse;  // previous level-(l+1) vertex -> new
};

MultigridPreconditioner::MultigridPreconditioner(const MultiresHierarchy& hierarchy, const MultigridOptions& options)
    : hierarchy_(hierarchy), options_(options) {
    build(nullptr, {});
}

MultigridPreconditioner::MultigridPreconditioner(const MultiresHierarchy& hierarchy, const MultigridPreconditioner& previous,
                                                 std::span<const int32_t> new_of_old_vertex, const MultigridOptions& options)
    : hierarchy_(hierarchy), options_(options) {
    const size_t n = hierarchy.levels.at(0).size();
    if (new_of_old_vertex.size() != previous.rows(0))
        throw InvalidArgumentError("multigrid rebuild: a vertex map of " + std::to_string(new_of_old_vertex.size()) +
                                   " entries for a preconditioner on " + std::to_string(previous.rows(0)) + " vertices");
    for (size_t o = 0; o < new_of_old_vertex.size(); ++o)
        if (new_of_old_vertex[o] < -1 || new_of_old_vertex[o] >= static_cast<int64_t>(n))
            throw InvalidArgumentError("multigrid rebuild: vertex " + std::to_string(o) + " maps to " +
                                       std::to_string(new_of_old_vertex[o]) + ", outside the " + std::to_string(n) +
                                       "-vertex hierarchy");
    build(&previous, new_of_old_vertex);
}

void MultigridPreconditioner::build(const MultigridPreconditioner* previous, std::span<const int32_t> new_of_old_vertex) {
    if (options_.smoothing_steps < 1 || !(options_.chebyshev_ratio > 1))
        throw InvalidArgumentError("multigrid: smoothing_steps must be >= 1 and chebyshev_ratio > 1");
    const auto start = std::chrono::steady_clock::now();
    // Rows are copied only from a build with the same options (lumping included) under a map that
    // keeps the vertices' order (carried_rows.h).
    const auto source = [&]() -> const MultigridPreconditioner* {
        return previous && previous->options_ == options_ && keeps_vertex_order(new_of_old_vertex) ? previous : nullptr;
    };
    try {
        build_levels(source(), new_of_old_vertex);
    } catch (const AlgorithmError& e) {
        const bool lumped_rows = options_.lumping == DropLumping::RowSum && options_.drop_tolerance > 0;
        if (!lumped_rows || !options_.fall_back_to_absolute) throw;
        lumping_fallback_reason_ = std::string(e.what()) + " with row-sum lumping; built with absolute lumping";
        options_.lumping = DropLumping::Absolute;
        levels_.clear();
        build_levels(source(), new_of_old_vertex);
    }
    setup_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

size_t MultigridPreconditioner::copied_product_rows(size_t level) const { return copied_product_rows_.at(level); }
size_t MultigridPreconditioner::copied_operator_rows(size_t level) const { return copied_operator_rows_.at(level); }

void MultigridPreconditioner::build_levels(const MultigridPreconditioner* previous,
                                           std::span<const int32_t> new_of_old_vertex) {
    const MultiresHierarchy& hierarchy = hierarchy_;
    const HierarchyLevel& fine = hierarchy.levels.at(0);
    copied_product_rows_.assign(hierarchy.level_count(), 0);
    copied_operator_rows_.assign(hierarchy.level_count(), 0);
    auto level0 = std::make_unique<Level>();
    level0->n = fine.size();
    level0->offsets = fine.offsets;
    level0->columns = fine.columns;
    level0->diagonal = fine.diagonal;
    level0->values = fine.values;
    levels_.push_back(std::move(level0));
    std::optional<CarriedLevel> carried;
    if (previous) {
        carried.emplace();
        carried->new_of_old_fine.assign(new_of_old_vertex.begin(), new_of_old_vertex.end());
        carried->old_of_new_fine = inverse_vertex_map(new_of_old_vertex, fine.size());
    }
    for (size_t l = 0; l + 1 < hierarchy.level_count(); ++l) {
        levels_[l]->p = &hierarchy.levels[l].interpolation;
        auto next = std::make_unique<Level>();
        next->n = hierarchy.levels[l + 1].size();
        levels_[l]->pt = transpose(*levels_[l]->p, next->n);
        levels_.push_back(std::move(next));
        if (carried && l + 1 < previous->levels_.size()) {
            // The coarse vertices correspond through their parents (the retained fine vertices).
            carried->old_fine = previous->levels_[l].get();
            carried->old_coarse = previous->levels_[l + 1].get();
            const std::vector<int32_t>& new_parent = hierarchy.levels[l + 1].parent_vertex;
            carried->new_of_old_coarse =
                new_of_old_coarse_vertices(previous->hierarchy_.levels[l + 1].parent_vertex, carried->new_of_old_fine,
                                           inverse_vertex_map(new_parent, levels_[l]->n));
            carried->old_of_new_coarse = inverse_vertex_map(carried->new_of_old_coarse, new_parent.size());
        } else {
            carried.reset();
        }
        build_galerkin_operator(l + 1, carried ? &*carried : nullptr);
        if (carried) {
            carried->old_of_new_fine = std::move(carried->old_of_new_coarse);
            carried->new_of_old_fine = std::move(carried->new_of_old_coarse);
        }
    }
    for (size_t l = 0; l < levels_.size(); ++l) {
        Level& level = *levels_[l];
        for (auto& v : level.row_bound) v.assign(level.n, 0.0);
        std::vector<int32_t> all(level.n);
        std::iota(all.begin(), all.end(), 0);
        prepare_smoother(l, all);
        auto copy_transfer = [&](auto& data) {
            using S = typename std::decay_t<decltype(data.b)>::value_type;
            data.b.assign(level.n, S(0));
            data.x.assign(level.n, S(0));
            data.r.assign(level.n, S(0));
            data.d.assign(level.n, S(0));
            if (level.p) {
                data.p_weights.assign(level.p->weights.begin(), level.p->weights.end());
                data.pt_weights.assign(level.pt.weights.begin(), level.pt.weights.end());
            }
        };
        auto size_rgb = [&](auto& data) {
            using S = typename std::decay_t<decltype(data.b)>::value_type;  // the lane vector
            for (auto* v : {&data.b, &data.x, &data.r, &data.d, &data.y}) v->assign(level.n, S{});
        };
        if (options_.single_precision) {
            copy_transfer(level.f);
            size_rgb(level.rgb_f);
        } else {
            copy_transfer(level.d);
            size_rgb(level.rgb_d);
        }
    }
    factorize_coarsest();
}

// Per-thread sparse accumulator over the columns of one product row.
struct MultigridPreconditioner::Accumulator {
    std::vector<int32_t> tag;                 // row currently using the column, or -1
    std::vector<int32_t> slot;                // where the column sits in the current row
    std::vector<int32_t> touched;             // columns of the current row in first-touch order
    // Indexed by column, the three channels side by side: one cache line per touched column instead
    // of three (the accumulation's scattered adds are its cost).
    std::vector<std::array<double, 3>> sum;
    explicit Accumulator(size_t columns) : tag(columns, -1), slot(columns, -1), sum(columns, {0.0, 0.0, 0.0}) {}
};

namespace {

bool same_interpolation_row(const InterpolationOperator& p, size_t row, const InterpolationOperator& old_p,
                            size_t old_row, const std::vector<int32_t>& old_of_new_column) {
    return row_change<1>({p.offsets, p.columns, {&p.weights}}, row, {old_p.offsets, old_p.columns, {&old_p.weights}},
                         old_row, old_of_new_column) == RowChange::None;
}

}  // namespace

void MultigridPreconditioner::build_galerkin_operator(size_t l, const CarriedLevel* carried) {
    Level& fine = *levels_[l - 1];
    Level& coarse = *levels_[l];
    const InterpolationOperator& p = *fine.p;
    const size_t n = fine.n, m = coarse.n;
    // A rebuild copies A P row v when row v of A and the P rows of its columns are unchanged up to
    // renumbering (the sums are then the same, in the same order).
    std::vector<uint8_t> keep_product;
    if (carried) {
        const Level& old_fine = *carried->old_fine;
        std::vector<uint8_t> same_interpolation(n, 0);
        for_rows(n, kGrain, [&](size_t j) {
            const int32_t o = carried->old_of_new_fine[j];
            same_interpolation[j] = o >= 0 && same_interpolation_row(p, j, *old_fine.p, static_cast<size_t>(o),
                                                                     carried->old_of_new_coarse);
        });
        keep_product.assign(n, 0);
        const OperatorRows<3> rows = matrix_rows(fine.offsets, fine.columns, fine.values);
        const OperatorRows<3> old_rows = matrix_rows(old_fine.offsets, old_fine.columns, old_fine.values);
        for_rows(n, kGrain, [&](size_t v) {
            const int32_t o = carried->old_of_new_fine[v];
            if (o < 0 || row_change(rows, v, old_rows, static_cast<size_t>(o), carried->old_of_new_fine) != RowChange::None)
                return;
            for (int32_t e = fine.offsets[v]; e < fine.offsets[v + 1]; ++e)
                if (!same_interpolation[static_cast<size_t>(fine.columns[static_cast<size_t>(e)])]) return;
            keep_product[v] = 1;
        });
    }
    const auto kept_product = [&](size_t v) { return !keep_product.empty() && keep_product[v]; };
    // A P: row v reaches K through v -A- j -P- K; columns ascending (the order the Galerkin rows and
    // their updates sum in).
    {
        tbb::enumerable_thread_specific<LinkUnion> unions([m] { return LinkUnion(m); });
        build_rows_in_chunks(n, 512, fine.ap_offsets, fine.ap_columns, [&](size_t v, std::vector<int32_t>& row) {
            if (kept_product(v)) {
                const Level& old_fine = *carried->old_fine;
                const auto o = static_cast<size_t>(carried->old_of_new_fine[v]);
                for (int32_t e = old_fine.ap_offsets[o]; e < old_fine.ap_offsets[o + 1]; ++e)
                    row.push_back(carried->new_of_old_coarse[static_cast<size_t>(old_fine.ap_columns[static_cast<size_t>(e)])]);
                return;
            }
            const auto a_row = std::span<const int32_t>(fine.columns).subspan(
                static_cast<size_t>(fine.offsets[v]), static_cast<size_t>(fine.offsets[v + 1] - fine.offsets[v]));
            unions.local().append(a_row, p.offsets.data(), p.columns.data(), -1, row);
        });
        for (auto& v : fine.ap_values) v.assign(fine.ap_columns.size(), 0.0);
    }
    std::vector<int32_t> computed;
    for (size_t v = 0; v < n; ++v)
        if (!kept_product(v)) computed.push_back(static_cast<int32_t>(v));
    compute_product_rows(l, computed);
    if (carried) {
        const Level& old_fine = *carried->old_fine;
        for_rows(n, kGrain, [&](size_t v) {
            if (!keep_product[v]) return;
            const auto o = static_cast<size_t>(carried->old_of_new_fine[v]);
            for (size_t ch = 0; ch < 3; ++ch)
                std::copy(old_fine.ap_values[ch].begin() + old_fine.ap_offsets[o],
                          old_fine.ap_values[ch].begin() + old_fine.ap_offsets[o + 1],
                          fine.ap_values[ch].begin() + fine.ap_offsets[v]);
        });
        copied_product_rows_[l - 1] = n - computed.size();
    }

    // P^T (A P), full: accumulated row by row; then the kept pattern (see drop_tolerance) and its
    // values. The drop test needs every row's diagonal first; a diagonal entry is one column of the
    // row, found in the few A P rows of P^T's row instead of accumulating the whole row.
    const InterpolationOperator& pt = fine.pt;
    std::array<std::vector<double>, 3> diagonal;
    for (auto& d : diagonal) d.assign(m, 0.0);
    for_rows(m, kGrain, [&](size_t row) {
        // The same additions in the same order as accumulate_galerkin_row's for column `row` (each A P
        // row holds a column once), so the diagonal is bit-identical to the accumulated one.
        std::array<double, 3> sum{};
        for (int32_t a = pt.offsets[row]; a < pt.offsets[row + 1]; ++a) {
            const auto v = static_cast<size_t>(pt.columns[static_cast<size_t>(a)]);
            const double w = pt.weights[static_cast<size_t>(a)];
            for (int32_t e = fine.ap_offsets[v]; e < fine.ap_offsets[v + 1]; ++e) {
                if (fine.ap_columns[static_cast<size_t>(e)] != static_cast<int32_t>(row)) continue;
                for (size_t ch = 0; ch < 3; ++ch) sum[ch] += w * fine.ap_values[ch][static_cast<size_t>(e)];
                break;
            }
        }
        for (size_t ch = 0; ch < 3; ++ch) diagonal[ch][row] = sum[ch];
    });
    // A rebuild copies Galerkin row I when its P^T row is unchanged up to renumbering, each A P row in
    // it was copied, and every column those rows reach kept its diagonal (the drop test reads them).
    std::vector<uint8_t> keep_operator;
    if (carried) {
        const Level& old_fine = *carried->old_fine;
        const Level& old_coarse = *carried->old_coarse;
        std::vector<uint8_t> same_diagonal(m, 0);
        for_rows(m, kGrain, [&](size_t k) {
            const int32_t o = carried->old_of_new_coarse[k];
            if (o < 0 || old_coarse.updated_on_old_pattern[static_cast<size_t>(o)]) return;
            bool same = true;
            for (size_t ch = 0; ch < 3; ++ch) same = same && diagonal[ch][k] == old_coarse.product_diagonal[ch][static_cast<size_t>(o)];
            same_diagonal[k] = same;
        });
        std::vector<uint8_t> settled(n, 0);  // A P row copied, every column's diagonal unchanged
        for_rows(n, kGrain, [&](size_t v) {
            if (!keep_product[v]) return;
            for (int32_t e = fine.ap_offsets[v]; e < fine.ap_offsets[v + 1]; ++e)
                if (!same_diagonal[static_cast<size_t>(fine.ap_columns[static_cast<size_t>(e)])]) return;
            settled[v] = 1;
        });
        keep_operator.assign(m, 0);
        for_rows(m, kGrain, [&](size_t row) {
            const int32_t o = carried->old_of_new_coarse[row];
            if (o < 0 || !same_interpolation_row(pt, row, old_fine.pt, static_cast<size_t>(o), carried->old_of_new_fine)) return;
            for (int32_t a = pt.offsets[row]; a < pt.offsets[row + 1]; ++a)
                if (!settled[static_cast<size_t>(pt.columns[static_cast<size_t>(a)])]) return;
            keep_operator[row] = 1;
        });
        copied_operator_rows_[l] = static_cast<size_t>(std::count(keep_operator.begin(), keep_operator.end(), 1));
    }
    // The drop test compares |a_ik| with theta sqrt(|a_ii a_kk|), the square roots taken once per row.
    const double theta = options_.drop_tolerance;
    std::array<std::vector<double>, 3> root_diagonal;
    for (size_t ch = 0; ch < 3; ++ch) {
        root_diagonal[ch].resize(m);
        for_rows(m, kGrain, [&](size_t row) { root_diagonal[ch][row] = std::sqrt(std::abs(diagonal[ch][row])); });
    }
    auto kept = [&](size_t row, size_t k, const Accumulator& acc) {
        if (k == row) return true;
        for (size_t ch = 0; ch < 3; ++ch)
            if (std::abs(acc.sum[k][ch]) >= theta * root_diagonal[ch][row] * root_diagonal[ch][k]) return true;
        return false;
    };
    // Pattern and values in one accumulation per row (build_rows_in_chunks). What compute_galerkin_rows
    // does for a row, with the kept columns chosen here (dropped entries lumped in first-touch order,
    // as there: bit-identical).
    struct ChunkRows {
        std::vector<int32_t> columns;
        std::vector<std::array<double, 3>> values;
    };
    constexpr size_t kChunk = 256;
    coarse.diagonal.assign(m, -1);  // the slot within the row until the offsets are known
    tbb::enumerable_thread_specific<Accumulator> scratch([m] { return Accumulator(m); });
    build_rows_in_chunks<ChunkRows>(
        m, kChunk, coarse.offsets,
        [&](size_t row, ChunkRows& buffer) {
            if (!keep_operator.empty() && keep_operator[row]) {
                const Level& old_coarse = *carried->old_coarse;
                const auto o = static_cast<size_t>(carried->old_of_new_coarse[row]);
                const auto old_begin = static_cast<size_t>(old_coarse.offsets[o]), old_end = static_cast<size_t>(old_coarse.offsets[o + 1]);
                for (size_t s = old_begin; s < old_end; ++s) {
                    buffer.columns.push_back(carried->new_of_old_coarse[static_cast<size_t>(old_coarse.columns[s])]);
                    buffer.values.push_back({old_coarse.values[0][s], old_coarse.values[1][s], old_coarse.values[2][s]});
                }
                coarse.diagonal[row] = old_coarse.diagonal[o] - static_cast<int32_t>(old_begin);
                return old_end - old_begin;
            }
            Accumulator& acc = scratch.local();
            accumulate_galerkin_row(l, row, acc);
            const size_t begin = buffer.columns.size();
            std::array<double, 3> lumped{};
            for (int32_t k : acc.touched) {
                if (kept(row, static_cast<size_t>(k), acc)) {
                    buffer.columns.push_back(k);
                    continue;
                }
                for (size_t ch = 0; ch < 3; ++ch) {
                    const double value = acc.sum[static_cast<size_t>(k)][ch];
                    lumped[ch] += options_.lumping == DropLumping::Absolute ? std::abs(value) : value;
                }
            }
            const auto first = buffer.columns.begin() + static_cast<std::ptrdiff_t>(begin);
            std::sort(first, buffer.columns.end());
            const auto diagonal_slot = std::lower_bound(first, buffer.columns.end(), static_cast<int32_t>(row)) - first;
            coarse.diagonal[row] = static_cast<int32_t>(diagonal_slot);
            for (auto k = first; k != buffer.columns.end(); ++k) buffer.values.push_back(acc.sum[static_cast<size_t>(*k)]);
            for (size_t ch = 0; ch < 3; ++ch) buffer.values[begin + static_cast<size_t>(diagonal_slot)][ch] += lumped[ch];
            clear(acc);
            return buffer.columns.size() - begin;
        },
        [&](size_t total) {
            coarse.columns.resize(total);
            for (auto& v : coarse.values) v.resize(total);
        },
        [&](size_t chunk, const ChunkRows& buffer) {
            const auto out = static_cast<size_t>(coarse.offsets[chunk * kChunk]);
            std::copy(buffer.columns.begin(), buffer.columns.end(), coarse.columns.begin() + static_cast<std::ptrdiff_t>(out));
            for (size_t e = 0; e < buffer.values.size(); ++e)
                for (size_t ch = 0; ch < 3; ++ch) coarse.values[ch][out + e] = buffer.values[e][ch];
            for (size_t row = chunk * kChunk; row < std::min(m, (chunk + 1) * kChunk); ++row)
                coarse.diagonal[row] += coarse.offsets[row];
        });
    coarse.product_diagonal = std::move(diagonal);
    coarse.updated_on_old_pattern.assign(m, 0);
}

void MultigridPreconditioner::clear(Accumulator& acc) {
    for (int32_t k : acc.touched) {
        acc.tag[static_cast<size_t>(k)] = -1;
        acc.sum[static_cast<size_t>(k)] = {0.0, 0.0, 0.0};
    }
    acc.touched.clear();
}

// Row `row` of P^T (A P) into acc (all three channels), summed in a fixed order (ascending v of
// P^T's row, then A P's row): deterministic.
void MultigridPreconditioner::accumulate_galerkin_row(size_t l, size_t row, Accumulator& acc) const {
    const Level& fine = *levels_[l - 1];
    const InterpolationOperator& pt = fine.pt;
    const auto tag = static_cast<int32_t>(row);
    for (int32_t a = pt.offsets[row]; a < pt.offsets[row + 1]; ++a) {
        const auto v = static_cast<size_t>(pt.columns[static_cast<size_t>(a)]);
        const double w = pt.weights[static_cast<size_t>(a)];
        for (int32_t e = fine.ap_offsets[v]; e < fine.ap_offsets[v + 1]; ++e) {
            const auto k = static_cast<size_t>(fine.ap_columns[static_cast<size_t>(e)]);
            if (acc.tag[k] != tag) {
                acc.tag[k] = tag;
                acc.touched.push_back(static_cast<int32_t>(k));
            }
            for (size_t ch = 0; ch < 3; ++ch) acc.sum[k][ch] += w * fine.ap_values[ch][static_cast<size_t>(e)];
        }
    }
}

void MultigridPreconditioner::compute_product_rows(size_t l, std::span<const int32_t> rows) {
    Level& fine = *levels_[l - 1];
    const InterpolationOperator& p = *fine.p;
    const size_t m = levels_[l]->n;
    tbb::enumerable_thread_specific<std::vector<int32_t>> slots([m] { return std::vector<int32_t>(m, -1); });
    for_rows(rows.size(), kGrain, [&](size_t index) {
        const auto v = static_cast<size_t>(rows[index]);
        auto& slot = slots.local();
        const auto begin = static_cast<size_t>(fine.ap_offsets[v]), end = static_cast<size_t>(fine.ap_offsets[v + 1]);
        for (size_t s = begin; s < end; ++s) slot[static_cast<size_t>(fine.ap_columns[s])] = static_cast<int32_t>(s);
        for (auto& values : fine.ap_values)
            std::fill(values.begin() + static_cast<std::ptrdiff_t>(begin), values.begin() + static_cast<std::ptrdiff_t>(end), 0.0);
        for (int32_t e = fine.offsets[v]; e < fine.offsets[v + 1]; ++e) {
            const auto j = static_cast<size_t>(fine.columns[static_cast<size_t>(e)]);
            for (int32_t q = p.offsets[j]; q < p.offsets[j + 1]; ++q) {
                const auto s = static_cast<size_t>(slot[static_cast<size_t>(p.columns[static_cast<size_t>(q)])]);
                const double w = p.weights[static_cast<size_t>(q)];
                for (size_t ch = 0; ch < 3; ++ch) fine.ap_values[ch][s] += fine.values[ch][static_cast<size_t>(e)] * w;
            }
        }
    });
}

void MultigridPreconditioner::compute_galerkin_rows(size_t l, std::span<const int32_t> rows) {
    Level& coarse = *levels_[l];
    const size_t m = coarse.n;
    tbb::enumerable_thread_specific<Accumulator> scratch([m] { return Accumulator(m); });
    for_rows(rows.size(), kGrain, [&](size_t index) {
        const auto row = static_cast<size_t>(rows[index]);
        Accumulator& acc = scratch.local();
        accumulate_galerkin_row(l, row, acc);
        // Dropped entries go to the diagonal (MultigridOptions::lumping says how).
        const auto begin = static_cast<size_t>(coarse.offsets[row]), end = static_cast<size_t>(coarse.offsets[row + 1]);
        for (size_t s = begin; s < end; ++s) acc.slot[static_cast<size_t>(coarse.columns[s])] = static_cast<int32_t>(s);
        std::array<double, 3> lumped{};
        for (size_t ch = 0; ch < 3; ++ch)
            std::fill(coarse.values[ch].begin() + static_cast<std::ptrdiff_t>(begin),
                      coarse.values[ch].begin() + static_cast<std::ptrdiff_t>(end), 0.0);
        for (int32_t k : acc.touched) {
            const int32_t s = acc.slot[static_cast<size_t>(k)];
            const bool in_pattern = s >= static_cast<int32_t>(begin) && s < static_cast<int32_t>(end) &&
                                    coarse.columns[static_cast<size_t>(s)] == k;
            for (size_t ch = 0; ch < 3; ++ch) {
                const double value = acc.sum[static_cast<size_t>(k)][ch];
                if (in_pattern)
                    coarse.values[ch][static_cast<size_t>(s)] = value;
                else
                    lumped[ch] += options_.lumping == DropLumping::Absolute ? std::abs(value) : value;
            }
        }
        for (size_t ch = 0; ch < 3; ++ch) coarse.values[ch][static_cast<size_t>(coarse.diagonal[row])] += lumped[ch];
        clear(acc);
    });
}

void MultigridPreconditioner::prepare_smoother(size_t l, std::span<const int32_t> rows) {
    Level& level = *levels_[l];
    auto& data_f = level.f;
    auto& data_d = level.d;
    const bool single = options_.single_precision;
    for (size_t ch = 0; ch < 3; ++ch) {
        if (single) {
            data_f.values[ch].resize(level.columns.size());
            data_f.inv_diag[ch].resize(level.n);
        } else {
            data_d.values[ch].resize(level.columns.size());
            data_d.inv_diag[ch].resize(level.n);
        }
    }
    if (single) {
        level.rgb_f.values.resize(level.columns.size());  // new entries zero, the fourth lane too
        level.rgb_f.inv_diag.resize(level.n);
    } else {
        level.rgb_d.values.resize(level.columns.size());
        level.rgb_d.inv_diag.resize(level.n);
    }
    std::atomic<bool> bad{false};
    for_rows(rows.size(), kGrain, [&](size_t index) {
        const auto i = static_cast<size_t>(rows[index]);
        for (size_t ch = 0; ch < 3; ++ch) {
            const std::vector<double>& values = level.values[ch];
            const double diag = values[static_cast<size_t>(level.diagonal[i])];
            if (!(diag > 0) || !std::isfinite(diag)) {
                bad = true;
                continue;
            }
            double sum = 0;
            for (int32_t k = level.offsets[i]; k < level.offsets[i + 1]; ++k) {
                sum += std::abs(values[static_cast<size_t>(k)]);
                auto& rgb_f = level.rgb_f.values[static_cast<size_t>(k)];
                auto& rgb_d = level.rgb_d.values[static_cast<size_t>(k)];
                if (single) {
                    data_f.values[ch][static_cast<size_t>(k)] = static_cast<float>(values[static_cast<size_t>(k)]);
                    rgb_f[ch] = data_f.values[ch][static_cast<size_t>(k)];
                } else {
                    data_d.values[ch][static_cast<size_t>(k)] = values[static_cast<size_t>(k)];
                    rgb_d[ch] = values[static_cast<size_t>(k)];
                }
            }
            level.row_bound[ch][i] = sum / diag;
            if (single) {
                data_f.inv_diag[ch][i] = static_cast<float>(1.0 / diag);
                level.rgb_f.inv_diag[i][ch] = data_f.inv_diag[ch][i];
            } else {
                data_d.inv_diag[ch][i] = 1.0 / diag;
                level.rgb_d.inv_diag[i][ch] = 1.0 / diag;
            }
        }
    });
    if (bad)
        throw AlgorithmError("multigrid: level " + std::to_string(l) +
                             " has a non-positive or non-finite diagonal (matrix not positive definite)");
    for (size_t ch = 0; ch < 3; ++ch)
        level.upper[ch] = *std::max_element(level.row_bound[ch].begin(), level.row_bound[ch].end());
}

void MultigridPreconditioner::factorize_coarsest() {
    Level& level = *levels_.back();
    const auto n = static_cast<Eigen::Index>(level.n);
    for (size_t ch = 0; ch < 3; ++ch) {
        level.coarsest[ch].compute(
            to_eigen_sparse(CsrMatrixView<double>{level.n, level.offsets.data(), level.columns.data(), level.values[ch].data()}));
        if (level.coarsest[ch].info() != Eigen::Success || (level.coarsest[ch].vectorD().array() <= 0).any())
            throw AlgorithmError("multigrid: the coarsest level (" + std::to_string(level.n) +
                                 " vertices) is not positive definite");
    }
    level.coarse_rhs.resize(n);
    level.coarse_solution.resize(n);
}

std::vector<std::vector<int32_t>> MultigridPreconditioner::update_values(std::span<const int32_t> changed_rows) {
    const HierarchyLevel& fine = hierarchy_.levels[0];
    Level& level0 = *levels_[0];
    for (int32_t row : changed_rows) {
        if (row < 0 || static_cast<size_t>(row) >= level0.n)
            throw InvalidArgumentError("multigrid update_values: row " + std::to_string(row) + " out of range");
        for (size_t ch = 0; ch < 3; ++ch)
            std::copy(fine.values[ch].begin() + fine.offsets[static_cast<size_t>(row)],
                      fine.values[ch].begin() + fine.offsets[static_cast<size_t>(row) + 1],
                      level0.values[ch].begin() + level0.offsets[static_cast<size_t>(row)]);
    }
    std::vector<int32_t> rows(changed_rows.begin(), changed_rows.end());
    std::vector<std::vector<int32_t>> level_rows{rows};
    prepare_smoother(0, rows);
    // A one-level hierarchy: level 0 is the coarsest level, solved exactly, so its factorisation must
    // follow the new values (the loop below refactorises only a coarsest level it reaches).
    if (levels_.size() == 1 && !rows.empty()) factorize_coarsest();
    std::vector<uint8_t> touched;
    for (size_t l = 1; l < levels_.size() && !rows.empty(); ++l) {
        // Coarse row I depends on the fine rows v with P_vI != 0 (and, by symmetry of A, on nothing
        // else: a changed entry a_vj sits in the changed row v).
        const InterpolationOperator& p = *levels_[l - 1]->p;
        compute_product_rows(l, rows);
        touched.assign(levels_[l]->n, 0);
        for (int32_t v : rows)
            for (int32_t q = p.offsets[static_cast<size_t>(v)]; q < p.offsets[static_cast<size_t>(v) + 1]; ++q)
                touched[static_cast<size_t>(p.columns[static_cast<size_t>(q)])] = 1;
        rows.clear();
        for (size_t i = 0; i < touched.size(); ++i)
            if (touched[i]) rows.push_back(static_cast<int32_t>(i));
        compute_galerkin_rows(l, rows);
        for (const int32_t row : rows) levels_[l]->updated_on_old_pattern[static_cast<size_t>(row)] = 1;
        prepare_smoother(l, rows);
        if (l + 1 == levels_.size() && !rows.empty()) factorize_coarsest();
        level_rows.push_back(rows);
    }
    level_rows.resize(levels_.size());  // levels the change did not reach: no rows
    return level_rows;
}

namespace {

// y_i = (b_i - (A x)_i) / a_ii for every row.
template <typename Scalar>
void scaled_residual(size_t n, const int32_t* offsets, const int32_t* columns, const Scalar* values,
                     const Scalar* inv_diag, const Scalar* b, const Scalar* x, Scalar* y) {
    for_rows(n, kGrain, [&](size_t i) {
        Scalar sum = b[i];
        for (int32_t k = offsets[i]; k < offsets[i + 1]; ++k) sum -= values[k] * x[columns[k]];
        y[i] = sum * inv_diag[i];
    });
}

}  // namespace

template <typename Scalar>
void MultigridPreconditioner::vcycle(size_t l, int channel) {
    Level& level = *levels_[l];
    MultigridLevelData<Scalar>& w = level.data<Scalar>();
    const auto ch = static_cast<size_t>(channel);
    const size_t n = level.n;
    if (l + 1 == levels_.size()) {
        for (size_t i = 0; i < n; ++i) level.coarse_rhs[static_cast<Eigen::Index>(i)] = static_cast<double>(w.b[i]);
        level.coarse_solution = level.coarsest[ch].solve(level.coarse_rhs);
        for (size_t i = 0; i < n; ++i) w.x[i] = static_cast<Scalar>(level.coarse_solution[static_cast<Eigen::Index>(i)]);
        return;
    }
    const Scalar* values = w.values[ch].data();
    const Scalar* inv_diag = w.inv_diag[ch].data();
    const int32_t* offsets = level.offsets.data();
    const int32_t* columns = level.columns.data();
    // Chebyshev smoothing on [upper / ratio, upper] (Saad, Iterative Methods, Alg. 12.1 on D^-1 A).
    const double upper = level.upper[ch];
    const double lower = upper / options_.chebyshev_ratio;
    const double theta = 0.5 * (upper + lower), delta = 0.5 * (upper - lower), sigma = theta / delta;
    auto smooth = [&](bool zero_start) {
        if (zero_start) {
            for_rows(n, kGrain, [&](size_t i) { w.r[i] = w.b[i] * inv_diag[i]; });
        } else {
            scaled_residual(n, offsets, columns, values, inv_diag, w.b.data(), w.x.data(), w.r.data());
        }
        const auto inv_theta = static_cast<Scalar>(1.0 / theta);
        for_rows(n, kGrain, [&](size_t i) {
            w.d[i] = w.r[i] * inv_theta;
            w.x[i] = zero_start ? w.d[i] : w.x[i] + w.d[i];
        });
        double rho = 1.0 / sigma;
        for (int step = 1; step < options_.smoothing_steps; ++step) {
            const double rho_next = 1.0 / (2.0 * sigma - rho);
            const auto c_d = static_cast<Scalar>(rho_next * rho), c_r = static_cast<Scalar>(2.0 * rho_next / delta);
            rho = rho_next;
            // d = c_d d + c_r D^-1 (b - A x), then x += d (a second pass: rows read neighbours' x).
            for_rows(n, kGrain, [&](size_t i) {
                Scalar sum = w.b[i];
                for (int32_t k = offsets[i]; k < offsets[i + 1]; ++k) sum -= values[k] * w.x[static_cast<size_t>(columns[k])];
                w.d[i] = c_d * w.d[i] + c_r * (sum * inv_diag[i]);
            });
            for_rows(n, kGrain, [&](size_t i) { w.x[i] += w.d[i]; });
        }
    };
    smooth(true);
    // r = b - A x, restricted with P^T to the next level's right-hand side.
    for_rows(n, kGrain, [&](size_t i) {
        Scalar sum = w.b[i];
        for (int32_t k = offsets[i]; k < offsets[i + 1]; ++k) sum -= values[k] * w.x[static_cast<size_t>(columns[k])];
        w.r[i] = sum;
    });
    MultigridLevelData<Scalar>& next = levels_[l + 1]->data<Scalar>();
    const InterpolationOperator& pt = level.pt;
    for_rows(levels_[l + 1]->n, kGrain, [&](size_t c) {
        Scalar sum = 0;
        for (int32_t a = pt.offsets[c]; a < pt.offsets[c + 1]; ++a)
            sum += w.pt_weights[static_cast<size_t>(a)] * w.r[static_cast<size_t>(pt.columns[static_cast<size_t>(a)])];
        next.b[c] = sum;
    });
    vcycle<Scalar>(l + 1, channel);
    const InterpolationOperator& p = *level.p;
    for_rows(n, kGrain, [&](size_t i) {
        Scalar sum = 0;
        for (int32_t q = p.offsets[i]; q < p.offsets[i + 1]; ++q)
            sum += w.p_weights[static_cast<size_t>(q)] * next.x[static_cast<size_t>(p.columns[static_cast<size_t>(q)])];
        w.x[i] += sum;
    });
    smooth(false);
}

void MultigridPreconditioner::apply(int channel, std::span<const double> r, std::span<double> z) {
    if (channel < 0 || channel > 2)
        throw InvalidArgumentError("multigrid: channel " + std::to_string(channel) + " is not 0, 1 or 2");
    const size_t n = levels_[0]->n;
    if (r.size() != n || z.size() != n)
        throw InvalidArgumentError("multigrid: vectors of size " + std::to_string(r.size()) + " and " +
                                   std::to_string(z.size()) + " for " + std::to_string(n) + " vertices");
    auto run = [&](auto& data, auto tag) {
        using Scalar = decltype(tag);
        for_rows(n, kGrain, [&](size_t i) { data.b[i] = static_cast<Scalar>(r[i]); });
        vcycle<Scalar>(0, channel);
        for_rows(n, kGrain, [&](size_t i) { z[i] = static_cast<double>(data.x[i]); });
    };
    if (options_.single_precision)
        run(levels_[0]->f, float{});
    else
        run(levels_[0]->d, double{});
}

}  // namespace waxwork

namespace waxwork {

template <typename Scalar>
void MultigridPreconditioner::vcycle_rgb(size_t l) {
    using V = typename RgbLanes<Scalar>::type;
    Level& level = *levels_[l];
    MultigridRgbLevelData<Scalar>& w = level.rgb<Scalar>();
    const size_t n = level.n;
    if (l + 1 == levels_.size()) {
        for (size_t ch = 0; ch < 3; ++ch) {
            for (size_t i = 0; i < n; ++i) level.coarse_rhs[static_cast<Eigen::Index>(i)] = static_cast<double>(w.b[i][ch]);
            level.coarse_solution = level.coarsest[ch].solve(level.coarse_rhs);
            for (size_t i = 0; i < n; ++i) w.x[i][ch] = static_cast<Scalar>(level.coarse_solution[static_cast<Eigen::Index>(i)]);
        }
        return;
    }
    const V* values = w.values.data();
    const V* inv_diag = w.inv_diag.data();
    const int32_t* offsets = level.offsets.data();
    const int32_t* columns = level.columns.data();
    // b - A x for row i, all channels; the same order of operations per lane as vcycle's loops.
    // (Written through a reference: returning the 32-byte double vector by value would change the
    // ABI without AVX, -Wpsabi.)
    auto residual = [&](size_t i, const V* x, V& sum) {
        sum = w.b[i];
        for (int32_t k = offsets[i]; k < offsets[i + 1]; ++k) sum -= values[k] * x[columns[k]];
    };
    // Chebyshev constants per channel (chebyshev() and vcycle have the derivation); the fourth lane
    // stays zero.
    const Chebyshev coefficients = chebyshev(l);
    V inv_theta{};
    for (size_t ch = 0; ch < 3; ++ch) inv_theta[ch] = static_cast<Scalar>(coefficients.inv_theta[ch]);
    // Steps 2.. of the polynomial: d = c_d d + c_r D^-1 (b - A x), x' = x + d, written to y (rows read
    // their neighbours' x, so the new iterate goes to the other buffer; one pass instead of two).
    auto chebyshev_steps = [&] {
        for (size_t s = 0; s < coefficients.c_d.size(); ++s) {
            V c_d{}, c_r{};
            for (size_t ch = 0; ch < 3; ++ch) {
                c_d[ch] = static_cast<Scalar>(coefficients.c_d[s][ch]);
                c_r[ch] = static_cast<Scalar>(coefficients.c_r[s][ch]);
            }
            const V* x = w.x.data();
            V* y = w.y.data();
            for_rows(n, kGrain, [&](size_t i) {
                V sum;
                residual(i, x, sum);
                w.d[i] = c_d * w.d[i] + c_r * (sum * inv_diag[i]);
                y[i] = x[i] + w.d[i];
            });
            std::swap(w.x, w.y);
        }
    };
    // Pre-smoothing from a zero start.
    for_rows(n, kGrain, [&](size_t i) {
        const V r = w.b[i] * inv_diag[i];
        w.d[i] = r * inv_theta;
        w.x[i] = w.d[i];
    });
    chebyshev_steps();
    // r = b - A x, restricted with P^T.
    for_rows(n, kGrain, [&](size_t i) { residual(i, w.x.data(), w.r[i]); });
    Level& coarse = *levels_[l + 1];
    MultigridRgbLevelData<Scalar>& next = coarse.rgb<Scalar>();
    const MultigridLevelData<Scalar>& transfer = level.data<Scalar>();
    const InterpolationOperator& pt = level.pt;
    for_rows(coarse.n, kGrain, [&](size_t c) {
        V sum{};
        for (int32_t a = pt.offsets[c]; a < pt.offsets[c + 1]; ++a)
            sum += transfer.pt_weights[static_cast<size_t>(a)] * w.r[static_cast<size_t>(pt.columns[static_cast<size_t>(a)])];
        next.b[c] = sum;
    });
    vcycle_rgb<Scalar>(l + 1);
    const InterpolationOperator& p = *level.p;
    for_rows(n, kGrain, [&](size_t i) {
        V sum{};
        for (int32_t q = p.offsets[i]; q < p.offsets[i + 1]; ++q)
            sum += transfer.p_weights[static_cast<size_t>(q)] * next.x[static_cast<size_t>(p.columns[static_cast<size_t>(q)])];
        w.x[i] += sum;
    });
    // Post-smoothing: the same polynomial from the corrected iterate (first step fused: y = x + d).
    {
        const V* x = w.x.data();
        V* y = w.y.data();
        for_rows(n, kGrain, [&](size_t i) {
            V sum;
            residual(i, x, sum);
            const V r = sum * inv_diag[i];
            w.d[i] = r * inv_theta;
            y[i] = x[i] + w.d[i];
        });
        std::swap(w.x, w.y);
    }
    chebyshev_steps();
}

void MultigridPreconditioner::apply_rgb(std::span<const double> r, std::span<double> z) {
    const size_t n = levels_[0]->n;
    if (r.size() != 3 * n || z.size() != 3 * n)
        throw InvalidArgumentError("multigrid apply_rgb: vectors of size " + std::to_string(r.size()) + " and " +
                                   std::to_string(z.size()) + " for 3 x " + std::to_string(n) + " entries");
    auto run = [&](auto& data, auto tag) {
        using Scalar = decltype(tag);
        for_rows(n, kGrain, [&](size_t i) {
            data.b[i] = typename RgbLanes<Scalar>::type{static_cast<Scalar>(r[3 * i]), static_cast<Scalar>(r[3 * i + 1]),
                                                        static_cast<Scalar>(r[3 * i + 2]), Scalar(0)};
        });
        vcycle_rgb<Scalar>(0);
        for_rows(n, kGrain, [&](size_t i) {
            for (size_t ch = 0; ch < 3; ++ch) z[3 * i + ch] = static_cast<double>(data.x[i][ch]);
        });
    };
    if (options_.single_precision)
        run(levels_[0]->rgb_f, float{});
    else
        run(levels_[0]->rgb_d, double{});
}

}  // namespace waxwork
