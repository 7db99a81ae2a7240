#include "multires/hierarchy.h"

#include "base/error.h"
#include "multires/independent_set.h"
#include "tetops/vertex_map.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <numeric>
#include <optional>
#include <string>
#include <utility>

namespace waxwork {

namespace {

// Copies a large array in parallel chunks (the fine level's copy of the matrix is tens of MB at
// 500K tets; one thread's memcpy leaves the other core idle).
template <typename T>
std::vector<T> parallel_copy(const std::vector<T>& source) {
    std::vector<T> copy(source.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, source.size(), size_t{1} << 16),
                      [&](const tbb::blocked_range<size_t>& r) {
                          std::copy(source.begin() + static_cast<std::ptrdiff_t>(r.begin()),
                                    source.begin() + static_cast<std::ptrdiff_t>(r.end()),
                                    copy.begin() + static_cast<std::ptrdiff_t>(r.begin()));
                      });
    return copy;
}

// InterpolationWeights::LinearExact for one dropped vertex v at x_v: `weights` holds the paper's
// normalised weights p_u over v's retained neighbours (in graph-row order), lambda_v their unnormalised
// sum. Replaces them by w = p + Lambda A^T y, the minimiser of sum_u (w_u - p_u)^2 / lambda_u subject to
// A w = (1, 0, 0, 0), where column u of A is (1, (x_u - x_v) / h): y solves (A Lambda A^T) y =
// (0, -sum_u p_u (x_u - x_v) / h). h, the harmonic mean neighbour distance, and the scaling of Lambda by h keep
// the 4x4 system of order one whatever the model's units. Returns false, leaving the weights alone, when
// the system is singular (fewer than four neighbours, or all of them nearly in a plane) or a weight
// would fall below min_weight.
bool make_linear_exact(std::span<const int32_t> neighbours, std::span<const uint8_t> retained,
                       std::span<const int32_t> original_vertex, std::span<const Eigen::Vector3d> positions,
                       const Eigen::Vector3d& xv, double lambda_v, double min_weight, std::span<double> weights) {
    const auto m = static_cast<Eigen::Index>(weights.size());
    if (m < 4) return false;
    const double h = static_cast<double>(m) / lambda_v;  // the harmonic mean distance
    const Eigen::Map<const Eigen::VectorXd> paper(weights.data(), m);
    // lambda_u h = p_u lambda_v h = p_u m: the inverse distances in units of h.
    const Eigen::VectorXd scaled_lambda = paper * static_cast<double>(m);
    Eigen::Matrix<double, 4, Eigen::Dynamic> a(4, m);
    Eigen::Index k = 0;
    for (const int32_t u : neighbours) {
        if (!retained[static_cast<size_t>(u)]) continue;
        a.col(k++) << 1.0, (positions[static_cast<size_t>(original_vertex[static_cast<size_t>(u)])] - xv) / h;
    }
    const Eigen::Matrix4d gram = a * scaled_lambda.asDiagonal() * a.transpose();
    const Eigen::LDLT<Eigen::Matrix4d> ldlt(gram);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !(ldlt.rcond() > 1e-10)) return false;
    Eigen::Vector4d moment_error = a * paper;  // (1, scaled centroid offset of the paper's weights)
    moment_error[0] = 0.0;
    const Eigen::VectorXd exact = paper - scaled_lambda.cwiseProduct(a.transpose() * ldlt.solve(moment_error));
    if (!exact.allFinite() || exact.minCoeff() < min_weight) return false;
    Eigen::Map<Eigen::VectorXd>(weights.data(), m) = exact;
    return true;
}

HierarchyLevel fine_level(const DiffusionMatrix& matrix) {
    HierarchyLevel level;
    const size_t n = matrix.size();
    level.offsets = matrix.offsets;
    level.columns = parallel_copy(matrix.columns);
    level.diagonal = matrix.diagonal;
    for (size_t c = 0; c < 3; ++c) level.values[c] = parallel_copy(matrix.values[c]);
    level.original_vertex.resize(n);
    for (size_t v = 0; v < n; ++v) level.original_vertex[v] = static_cast<int32_t>(v);
    // G^0: the matrix pattern without the diagonal (the mesh's vertex_vertices). Every row holds its
    // diagonal once, so row i of G^0 starts at offsets[i] - i and the rows fill in parallel.
    for (size_t i = 0; i < n; ++i) {
        const int32_t d = matrix.diagonal[i];
        if (d < matrix.offsets[i] || d >= matrix.offsets[i + 1] || matrix.columns[static_cast<size_t>(d)] != static_cast<int32_t>(i))
            throw InvalidArgumentError("multires hierarchy: row " + std::to_string(i) + " of the matrix has no diagonal entry");
    }
    level.graph.offsets.resize(n + 1);
    for (size_t i = 0; i <= n; ++i) level.graph.offsets[i] = matrix.offsets[i] - static_cast<int32_t>(i);
    level.graph.indices.resize(matrix.nonzeros() - n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            auto out = static_cast<size_t>(level.graph.offsets[i]);
            for (int32_t k = matrix.offsets[i]; k < matrix.offsets[i + 1]; ++k)
                if (static_cast<size_t>(matrix.columns[static_cast<size_t>(k)]) != i)
                    level.graph.indices[out++] = matrix.columns[static_cast<size_t>(k)];
        }
    });
    return level;
}

}  // namespace

InterpolationOperator build_interpolation(const CompressedRows& graph, std::span<const uint8_t> retained,
                                          std::span<const int32_t> coarse_index,
                                          std::span<const int32_t> original_vertex,
                                          std::span<const Eigen::Vector3d> positions,
                                          const HierarchyOptions& options, const CarriedRows* carried,
                                          const InterpolationOperator* previous) {
    const size_t n = graph.row_count();
    InterpolationOperator p;
    p.offsets.assign(n + 1, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
            int32_t count = 1;
            if (carried && carried->kept(v)) {
                const auto old = static_cast<size_t>(carried->previous_row[v]);
                count = previous->offsets[old + 1] - previous->offsets[old];
            } else if (!retained[v]) {
                count = 0;
                for (int32_t u : graph.row(v)) count += retained[static_cast<size_t>(u)] ? 1 : 0;
            }
            p.offsets[v + 1] = count;
        }
    });
    for (size_t v = 0; v < n; ++v) p.offsets[v + 1] += p.offsets[v];
    p.columns.resize(static_cast<size_t>(p.offsets[n]));
    p.weights.resize(p.columns.size());
    const bool linear_exact = options.weights == InterpolationWeights::LinearExact;
    std::atomic<int64_t> linear_exact_rows{0}, paper_weight_rows{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 2048), [&](const tbb::blocked_range<size_t>& r) {
        int64_t corrected = 0, kept = 0;
        for (size_t v = r.begin(); v != r.end(); ++v) {
            auto slot = static_cast<size_t>(p.offsets[v]);
            if (carried && carried->kept(v)) {
                const auto old = static_cast<size_t>(carried->previous_row[v]);
                for (auto q = static_cast<size_t>(previous->offsets[old]); q < static_cast<size_t>(previous->offsets[old + 1]);
                     ++q, ++slot) {
                    p.columns[slot] = carried->new_of_old_column[static_cast<size_t>(previous->columns[q])];
                    p.weights[slot] = previous->weights[q];
                }
                continue;
            }
            if (retained[v]) {  // Eq. 16, first case: copy the coarse value
                p.columns[slot] = coarse_index[v];
                p.weights[slot] = 1.0;
                continue;
            }
            // Eq. 16, second case: lambda_vu = 1 / |x_v - x_u| over R(v), normalised by lambda_v. The
            // floor on the length only guards coincident points (a degenerate mesh), which would
            // otherwise give an infinite weight.
            const Eigen::Vector3d& xv = positions[static_cast<size_t>(original_vertex[v])];
            double total = 0;
            const size_t first = slot;
            for (int32_t u : graph.row(v)) {
                if (!retained[u]) continue;
                const double length = (positions[static_cast<size_t>(original_vertex[u])] - xv).norm();
                const double lambda = 1.0 / std::max(length, 1e-300);
                p.columns[slot] = coarse_index[u];
                p.weights[slot] = lambda;
                total += lambda;
                ++slot;
            }
            for (size_t k = first; k < slot; ++k) p.weights[k] /= total;
            if (linear_exact) {
                const bool made_exact = make_linear_exact(graph.row(v), retained, original_vertex, positions, xv, total,
                                                          options.min_linear_exact_weight,
                                                          std::span<double>(p.weights).subspan(first, slot - first));
                ++(made_exact ? corrected : kept);
            }
        }
        linear_exact_rows += corrected;
        paper_weight_rows += kept;
    });
    p.linear_exact_rows = linear_exact_rows;
    p.paper_weight_rows = paper_weight_rows;
    return p;
}

void build_coarse_matrix(const HierarchyLevel& fine, std::span<const int32_t> coarse_to_fine, HierarchyLevel& coarse,
                         const CarriedRows* carried, const HierarchyLevel* previous) {
    const size_t m = coarse_to_fine.size();
    const CompressedRows& g = coarse.graph;
    coarse.offsets.assign(m + 1, 0);
    for (size_t c = 0; c < m; ++c) coarse.offsets[c + 1] = coarse.offsets[c] + static_cast<int32_t>(g.row(c).size()) + 1;
    const auto nnz = static_cast<size_t>(coarse.offsets[m]);
    coarse.columns.resize(nnz);
    coarse.diagonal.resize(m);
    for (auto& v : coarse.values) v.assign(nnz, 0.0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, m, 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t c = r.begin(); c != r.end(); ++c) {
            // Pattern: the coarse graph row with the diagonal merged in, ascending.
            size_t out = static_cast<size_t>(coarse.offsets[c]);
            bool diagonal_placed = false;
            for (int32_t k : g.row(c)) {
                if (!diagonal_placed && k > static_cast<int32_t>(c)) {
                    coarse.diagonal[c] = static_cast<int32_t>(out);
                    coarse.columns[out++] = static_cast<int32_t>(c);
                    diagonal_placed = true;
                }
                coarse.columns[out++] = k;
            }
            if (!diagonal_placed) {
                coarse.diagonal[c] = static_cast<int32_t>(out);
                coarse.columns[out++] = static_cast<int32_t>(c);
            }
        }
    });
    std::vector<int32_t> computed;
    computed.reserve(m);
    for (size_t c = 0; c < m; ++c)
        if (!carried || !carried->kept(c)) computed.push_back(static_cast<int32_t>(c));
    if (carried) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, m, 1024), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t c = r.begin(); c != r.end(); ++c) {
                if (!carried->kept(c)) continue;
                const auto old = static_cast<size_t>(carried->previous_row[c]);
                const auto from = static_cast<std::ptrdiff_t>(previous->offsets[old]);
                const auto to = static_cast<std::ptrdiff_t>(previous->offsets[old + 1]);
                for (size_t ch = 0; ch < 3; ++ch)
                    std::copy(previous->values[ch].begin() + from, previous->values[ch].begin() + to,
                              coarse.values[ch].begin() + coarse.offsets[c]);
            }
        });
    }
    update_coarse_rows(fine, coarse_to_fine, coarse, computed);
}

void update_coarse_rows(const HierarchyLevel& fine, std::span<const int32_t> coarse_to_fine, HierarchyLevel& coarse,
                        std::span<const int32_t> rows) {
    const size_t m = coarse_to_fine.size();
    const InterpolationOperator& p = fine.interpolation;
    // Per thread, the position of each coarse column within the current row (replacing a binary search
    // per product term; stale entries from other rows are never read: every column a row's products
    // reach is in its pattern, the coarse graph row plus the diagonal, see hierarchy.h), and the row's
    // sums with the three channels side by side, written to the three value arrays once at the end:
    // scattered read-modify-writes into one small buffer instead of three large arrays.
    struct RowScratch {
        std::vector<int32_t> position;
        std::vector<std::array<double, 3>> sums;
    };
    tbb::enumerable_thread_specific<RowScratch> scratch([m] { return RowScratch{std::vector<int32_t>(m, -1), {}}; });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rows.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        RowScratch& local = scratch.local();
        for (size_t index = r.begin(); index != r.end(); ++index) {
            const auto c = static_cast<size_t>(rows[index]);
            const auto begin = static_cast<size_t>(coarse.offsets[c]), end = static_cast<size_t>(coarse.offsets[c + 1]);
            for (size_t s = begin; s < end; ++s)
                local.position[static_cast<size_t>(coarse.columns[s])] = static_cast<int32_t>(s - begin);
            local.sums.assign(end - begin, {0.0, 0.0, 0.0});
            // Eq. 17: sum over the fine row of i of M_ij P_jk into coarse column k.
            const auto i = static_cast<size_t>(coarse_to_fine[c]);
            for (int32_t e = fine.offsets[i]; e < fine.offsets[i + 1]; ++e) {
                const auto j = static_cast<size_t>(fine.columns[static_cast<size_t>(e)]);
                const double m0 = fine.values[0][static_cast<size_t>(e)];
                const double m1 = fine.values[1][static_cast<size_t>(e)];
                const double m2 = fine.values[2][static_cast<size_t>(e)];
                for (int32_t q = p.offsets[j]; q < p.offsets[j + 1]; ++q) {
                    std::array<double, 3>& sum =
                        local.sums[static_cast<size_t>(local.position[static_cast<size_t>(p.columns[static_cast<size_t>(q)])])];
                    const double w = p.weights[static_cast<size_t>(q)];
                    sum[0] += m0 * w;
                    sum[1] += m1 * w;
                    sum[2] += m2 * w;
                }
            }
            for (size_t s = begin; s < end; ++s)
                for (size_t ch = 0; ch < 3; ++ch) coarse.values[ch][s] = local.sums[s - begin][ch];
        }
    });
}

void interpolate(const InterpolationOperator& p, std::span<const double> coarse, std::span<double> fine) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, p.rows(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
            double sum = 0;
            for (int32_t q = p.offsets[v]; q < p.offsets[v + 1]; ++q)
                sum += p.weights[static_cast<size_t>(q)] * coarse[static_cast<size_t>(p.columns[static_cast<size_t>(q)])];
            fine[v] = sum;
        }
    });
}

void restrict_right_hand_side(const HierarchyLevel& level, std::span<const double> level0_b, std::span<double> b) {
    for (size_t v = 0; v < level.size(); ++v) b[v] = level0_b[static_cast<size_t>(level.original_vertex[v])];
}

namespace {

// One coarsening step of a level with `level_count` levels built so far (the stopping rule of hierarchy.h).
struct CoarseningStep {
    VertexSelection selection;
    std::vector<int32_t> coarse_index;    // fine -> coarse, -1 when dropped
    std::vector<int32_t> coarse_to_fine;  // coarse -> fine
};

// What a rebuild carries into one level's selection from the previous hierarchy (update_coarse_vertices).
struct CarriedSelection {
    std::vector<uint8_t> previous_retained;  // per vertex of the new level
    std::vector<int32_t> changed;            // new vertices and vertices whose row changed
};

std::optional<CoarseningStep> coarsen(const CompressedRows& graph, size_t level_count, const HierarchyOptions& options,
                                      const CarriedSelection* carried = nullptr) {
    const size_t n = graph.row_count();
    if (static_cast<int>(level_count) >= options.max_levels || static_cast<int64_t>(n) < options.min_coarse_vertices)
        return std::nullopt;
    // Each level gets its own key so that successive selections are uncorrelated.
    const uint32_t seed = options.seed * 0x9e3779b1u + static_cast<uint32_t>(level_count);
    CoarseningStep step;
    step.selection = carried ? update_coarse_vertices(graph, seed, options.enhance, carried->previous_retained,
                                                      carried->changed)
                             : select_coarse_vertices(graph, seed, options.enhance);
    step.coarse_index = coarse_vertex_index(step.selection.retained);
    for (size_t v = 0; v < n; ++v)
        if (step.selection.retained[v]) step.coarse_to_fine.push_back(static_cast<int32_t>(v));
    if (static_cast<double>(step.coarse_to_fine.size()) > options.max_keep_ratio * static_cast<double>(n) ||
        step.coarse_to_fine.empty())
        return std::nullopt;
    return step;
}

// The vertices of `graph` (a new level l) whose row is not the row of their previous vertex in
// `previous_graph` (the previous level l) under the map, and the vertices that have none, ascending.
// old_of_new: per new vertex its previous vertex or -1; new_of_old the inverse.
std::vector<int32_t> changed_rows(const CompressedRows& graph, const CompressedRows& previous_graph,
                                  std::span<const int32_t> old_of_new, std::span<const int32_t> new_of_old) {
    const size_t n = graph.row_count();
    std::vector<uint8_t> changed(n, 0);
    tbb::enumerable_thread_specific<std::vector<int32_t>> buffers;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 2048), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<int32_t>& mapped = buffers.local();
        for (size_t v = r.begin(); v != r.end(); ++v) {
            const int32_t o = old_of_new[v];
            if (o < 0) {
                changed[v] = 1;
                continue;
            }
            const std::span<const int32_t> row = graph.row(v), old_row = previous_graph.row(static_cast<size_t>(o));
            if (row.size() != old_row.size()) {
                changed[v] = 1;
                continue;
            }
            mapped.clear();
            for (const int32_t u : old_row) mapped.push_back(new_of_old[static_cast<size_t>(u)]);
            // An edit that compacts the vertices keeps their order, so the mapped row is usually sorted.
            if (!std::is_sorted(mapped.begin(), mapped.end())) std::sort(mapped.begin(), mapped.end());
            changed[v] = !std::equal(mapped.begin(), mapped.end(), row.begin());
        }
    });
    std::vector<int32_t> rows;
    for (size_t v = 0; v < n; ++v)
        if (changed[v]) rows.push_back(static_cast<int32_t>(v));
    return rows;
}

// What a rebuild copies into one coarsening step from the previous hierarchy (carried_rows.h): the
// kept rows of Eq. 16 (per fine vertex), of the coarse graph and of Eq. 17 (per coarse vertex).
struct CarriedOperators {
    std::vector<uint8_t> keep_interpolation, keep_graph, keep_matrix;
    std::vector<int32_t> previous_fine_row;    // per fine vertex: its previous vertex
    std::vector<int32_t> previous_coarse_row;  // per coarse vertex: its previous coarse vertex (where kept)
    std::vector<int32_t> new_of_old_coarse;    // previous coarse vertex -> new, or -1
    const HierarchyLevel* previous_fine = nullptr;
    const HierarchyLevel* previous_coarse = nullptr;

    CarriedRows interpolation_rows() const { return {keep_interpolation, previous_fine_row, new_of_old_coarse}; }
    CarriedRows graph_rows() const { return {keep_graph, previous_coarse_row, new_of_old_coarse}; }
    CarriedRows matrix_rows() const { return {keep_matrix, previous_coarse_row, new_of_old_coarse}; }
};

// The coarse level of `step` and the fine level's Eq. 16 and Eq. 17 operators, computed, or with
// `carried` partly copied from the previous hierarchy.
HierarchyLevel add_coarse_level(HierarchyLevel& fine, const CoarseningStep& step,
                                std::span<const Eigen::Vector3d> positions, const HierarchyOptions& options,
                                const CarriedOperators* carried, HierarchyBuildTimes& times,
                                const std::function<void(double&)>& time) {
    HierarchyLevel coarse;
    coarse.parent_vertex = step.coarse_to_fine;
    coarse.original_vertex.resize(step.coarse_to_fine.size());
    for (size_t c = 0; c < step.coarse_to_fine.size(); ++c)
        coarse.original_vertex[c] = fine.original_vertex[static_cast<size_t>(step.coarse_to_fine[c])];
    const CarriedRows interpolation_rows = carried ? carried->interpolation_rows() : CarriedRows{};
    const CarriedRows graph_rows = carried ? carried->graph_rows() : CarriedRows{};
    const CarriedRows matrix_rows = carried ? carried->matrix_rows() : CarriedRows{};
    fine.interpolation = build_interpolation(fine.graph, step.selection.retained, step.coarse_index, fine.original_vertex,
                                             positions, options, carried ? &interpolation_rows : nullptr,
                                             carried ? &carried->previous_fine->interpolation : nullptr);
    time(times.interpolation);
    // P's columns are exactly each fine vertex's coarse links (independent_set.h).
    coarse.graph = build_coarse_graph(fine.graph, step.coarse_index, fine.interpolation.offsets,
                                      fine.interpolation.columns, carried ? &graph_rows : nullptr,
                                      carried ? &carried->previous_coarse->graph : nullptr);
    time(times.coarse_graph);
    fine.independent_set_rounds = step.selection.independent_set_rounds;
    fine.enhancement_passes = step.selection.enhancement_passes;
    fine.enhancement_vertices = step.selection.enhancement_vertices;
    build_coarse_matrix(fine, step.coarse_to_fine, coarse, carried ? &matrix_rows : nullptr,
                        carried ? carried->previous_coarse : nullptr);
    if (carried)
        coarse.copied_rows = std::count(carried->keep_matrix.begin(), carried->keep_matrix.end(), uint8_t{1});
    time(times.coarse_matrix);
    return coarse;
}

// flags | the flags of each vertex's neighbours: one ring wider.
std::vector<uint8_t> widen(const CompressedRows& graph, std::span<const uint8_t> flags) {
    std::vector<uint8_t> wider(flags.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, flags.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
            uint8_t any = flags[v];
            for (const int32_t u : graph.row(v)) any |= flags[static_cast<size_t>(u)];
            wider[v] = any;
        }
    });
    return wider;
}

// Which operator rows of one carried level can be copied. touched: per fine vertex, 1 when it is new,
// its row changed, it moved (positions), or its selection state changed. An Eq. 16 row reads its
// vertex, its neighbours' states and positions: it is copied when neither touched nor next to a
// touched vertex (and carry_interpolation: with linear-exact weights every row is computed, for
// its counts). A coarse graph row reads its fine vertex's neighbours' links (their Eq. 16 columns):
// copied when the fine vertex and its neighbours have untouched Eq. 16 rows (copied or computed,
// they equal the previous ones). An Eq. 17 row reads the same and the fine matrix row: copied when
// the graph row is and that matrix row did not change (values_changed, per fine vertex).
// previous_coarse_index: the previous level's fine-to-coarse index (coarse_vertex_index).
CarriedOperators carry_operators(const CompressedRows& graph, const CoarseningStep& step,
                                 std::span<const uint8_t> touched, std::span<const uint8_t> values_changed,
                                 std::span<const int32_t> old_of_new, std::span<const int32_t> previous_coarse_index,
                                 std::span<const int32_t> new_of_old_coarse, const HierarchyLevel& previous_fine,
                                 const HierarchyLevel& previous_coarse, bool carry_interpolation) {
    CarriedOperators carried;
    carried.previous_fine = &previous_fine;
    carried.previous_coarse = &previous_coarse;
    carried.new_of_old_coarse.assign(new_of_old_coarse.begin(), new_of_old_coarse.end());
    carried.previous_fine_row.assign(old_of_new.begin(), old_of_new.end());
    const std::vector<uint8_t> dirty_interpolation = widen(graph, touched);
    const std::vector<uint8_t> dirty_links = widen(graph, dirty_interpolation);
    const size_t n = graph.row_count(), m = step.coarse_to_fine.size();
    carried.keep_interpolation.resize(n);
    for (size_t v = 0; v < n; ++v) carried.keep_interpolation[v] = carry_interpolation && !dirty_interpolation[v];
    carried.keep_graph.assign(m, 0);
    carried.keep_matrix.assign(m, 0);
    carried.previous_coarse_row.assign(m, -1);
    for (size_t c = 0; c < m; ++c) {
        const auto i = static_cast<size_t>(step.coarse_to_fine[c]);
        // Not touched: i is an old vertex, retained before as now.
        if (dirty_links[i]) continue;
        carried.previous_coarse_row[c] = previous_coarse_index[static_cast<size_t>(old_of_new[i])];
        carried.keep_graph[c] = 1;
        carried.keep_matrix[c] = !values_changed[i];
    }
    return carried;
}

void check_hierarchy_inputs(const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                            const HierarchyOptions& options) {
    if (positions.size() != matrix.size())
        throw InvalidArgumentError("multires hierarchy: " + std::to_string(positions.size()) + " positions for a " +
                                   std::to_string(matrix.size()) + "-vertex matrix");
    if (!std::isfinite(options.min_linear_exact_weight))
        throw InvalidArgumentError("multires hierarchy: the linear-exact weight floor must be a finite number (got " +
                                   std::to_string(options.min_linear_exact_weight) + ")");
}

// Per new level-0 vertex: 1 when it has no previous vertex or its position (moved) or matrix row
// (values_changed: pattern or values) is not its previous vertex's; moved is 1 everywhere when the
// previous positions are unknown. Returns the vertices whose graph row changed or that have no
// previous vertex (changed_rows for level 0: a graph row is its matrix row's pattern without the
// diagonal, so one walk of the rows serves both). old_of_new must keep the vertices' order
// (keeps_vertex_order): the columns are compared in order.
std::vector<int32_t> level0_changes(const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                                    const MultiresHierarchy& previous, std::span<const int32_t> old_of_new,
                                    std::vector<uint8_t>& moved, std::vector<uint8_t>& values_changed) {
    const size_t n = matrix.size();
    const HierarchyLevel& old = previous.levels[0];
    const bool known_positions = previous.positions.size() == old.size();
    moved.assign(n, 1);
    values_changed.assign(n, 1);
    std::vector<uint8_t> pattern_changed(n, 1);
    const OperatorRows<3> rows = matrix_rows(matrix.offsets, matrix.columns, matrix.values);
    const OperatorRows<3> old_rows = matrix_rows(old.offsets, old.columns, old.values);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 2048), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
            const int32_t o = old_of_new[v];
            if (o < 0) continue;
            const auto ou = static_cast<size_t>(o);
            moved[v] = !known_positions || positions[v] != previous.positions[ou];
            const RowChange change = row_change(rows, v, old_rows, ou, old_of_new);
            values_changed[v] = change != RowChange::None;
            pattern_changed[v] = change == RowChange::Pattern;
        }
    });
    std::vector<int32_t> changed;
    for (size_t v = 0; v < n; ++v)
        if (pattern_changed[v]) changed.push_back(static_cast<int32_t>(v));
    return changed;
}

// A rebuild selects a level, and every coarser one, from scratch once more than this share of its rows
// changed (a fracture's walls cross the whole volume; a region of fixed size is a larger share of a
// coarser level). The update would select most vertices again anyway, and little would be left to copy
// for the cost of working out what may be: spot broken into 5 cells at 59,332 tets changes 37% of
// level 0, 65% of level 1 and 93% of level 2, and rebuilt every level 1.09x as long as from scratch
// (docs/solvers.md). A fresh level is also the
// selection a build from scratch would make on its graph.
constexpr double kMaxCarriedChangeShare = 0.5;

// Builds the hierarchy's levels; with `previous` and its level-0 vertex map, carries each level's
// selection from the previous hierarchy (rebuild_multires_hierarchy), and the operator rows the edit
// did not reach.
MultiresHierarchy build_levels(const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                               const HierarchyOptions& options, const MultiresHierarchy* previous,
                               std::span<const int32_t> new_of_old_vertex) {
    check_hierarchy_inputs(matrix, positions, options);
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    auto lap = start;
    // Adds the time since the last lap to `phase`.
    const std::function<void(double&)> time = [&lap](double& phase) {
        const auto now = Clock::now();
        phase += std::chrono::duration<double, std::milli>(now - lap).count();
        lap = now;
    };
    MultiresHierarchy hierarchy;
    HierarchyBuildTimes& times = hierarchy.build_times;
    hierarchy.levels.push_back(fine_level(matrix));
    hierarchy.positions.assign(positions.begin(), positions.end());
    hierarchy.options = options;
    time(times.fine_level);
    // Per vertex of the previous hierarchy's current level: its vertex in the new level (-1: none).
    std::vector<int32_t> new_of_old;
    // Per vertex of the new current level: moved (its level-0 position) and matrix row changed.
    std::vector<uint8_t> moved, values_changed;
    // Operator rows are copied only under an order-preserving map, and Eq. 16's only with the paper's
    // weights (a linear-exact row's counts must be known).
    const bool carry_rows = previous && keeps_vertex_order(new_of_old_vertex);
    const bool carry_interpolation = carry_rows && options.weights == InterpolationWeights::InverseEdgeLength;
    if (previous) new_of_old.assign(new_of_old_vertex.begin(), new_of_old_vertex.end());
    bool carrying = previous != nullptr;  // false from the first level built from scratch on
    for (;;) {
        HierarchyLevel& fine = hierarchy.levels.back();
        const size_t l = hierarchy.levels.size() - 1;
        const size_t n = fine.graph.row_count();
        bool carry = carrying && l + 1 < previous->level_count();
        std::optional<CarriedSelection> carried;
        std::vector<int32_t> old_of_new, old_coarse_index;  // previous level l -> its level l+1 (-1: dropped)
        if (carry) {
            const HierarchyLevel& old_fine = previous->levels[l];
            const HierarchyLevel& old_coarse = previous->levels[l + 1];
            std::vector<uint8_t> old_retained(old_fine.graph.row_count(), 0);
            for (const int32_t p : old_coarse.parent_vertex) old_retained[static_cast<size_t>(p)] = 1;
            old_coarse_index = coarse_vertex_index(old_retained);
            old_of_new = inverse_vertex_map(new_of_old, n);
            carried.emplace();
            carried->previous_retained.assign(n, 0);
            for (size_t v = 0; v < n; ++v)
                if (old_of_new[v] >= 0) carried->previous_retained[v] = old_retained[static_cast<size_t>(old_of_new[v])];
            carried->changed = l == 0 && carry_rows
                                   ? level0_changes(matrix, positions, *previous, old_of_new, moved, values_changed)
                                   : changed_rows(fine.graph, old_fine.graph, old_of_new, new_of_old);
            fine.changed_vertices = static_cast<int64_t>(carried->changed.size());
            if (static_cast<double>(carried->changed.size()) > kMaxCarriedChangeShare * static_cast<double>(n)) {
                carried.reset();
                carry = carrying = false;
            }
        }
        std::optional<CoarseningStep> step =
            coarsen(fine.graph, hierarchy.levels.size(), options, carried ? &*carried : nullptr);
        time(times.selection);
        if (!step) break;
        std::optional<CarriedOperators> operators;
        if (carry) {
            const HierarchyLevel& old_coarse = previous->levels[l + 1];
            std::vector<int32_t> next = new_of_old_coarse_vertices(old_coarse.parent_vertex, new_of_old, step->coarse_index);
            if (carry_rows) {
                std::vector<uint8_t> touched(n);
                for (size_t v = 0; v < n; ++v)
                    touched[v] = old_of_new[v] < 0 || moved[v] ||
                                 step->selection.retained[v] != carried->previous_retained[v];
                for (const int32_t v : carried->changed) touched[static_cast<size_t>(v)] = 1;
                operators = carry_operators(fine.graph, *step, touched, values_changed, old_of_new, old_coarse_index,
                                            next, previous->levels[l], old_coarse, carry_interpolation);
            }
            new_of_old = std::move(next);
        }
        hierarchy.levels.push_back(
            add_coarse_level(fine, *step, positions, options, operators ? &*operators : nullptr, times, time));
        if (operators) {
            // The next level's vertices: moved with their level-0 vertex; their matrix row changed
            // unless its Eq. 17 row was copied.
            std::vector<uint8_t> next_moved(step->coarse_to_fine.size()), next_changed(step->coarse_to_fine.size());
            for (size_t c = 0; c < step->coarse_to_fine.size(); ++c) {
                next_moved[c] = moved[static_cast<size_t>(step->coarse_to_fine[c])];
                next_changed[c] = !operators->keep_matrix[c];
            }
            moved = std::move(next_moved);
            values_changed = std::move(next_changed);
        }
    }
    hierarchy.build_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    return hierarchy;
}

}  // namespace

MultiresHierarchy build_multires_hierarchy(const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                                           const HierarchyOptions& options) {
    return build_levels(matrix, positions, options, nullptr, {});
}

MultiresHierarchy rebuild_multires_hierarchy(const MultiresHierarchy& previous, std::span<const int32_t> new_of_old_vertex,
                                             const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                                             const HierarchyOptions& options) {
    if (previous.levels.empty()) return build_multires_hierarchy(matrix, positions, options);
    if (!(previous.options == options))
        throw InvalidArgumentError("multires hierarchy rebuild: the options differ from those the previous hierarchy "
                                   "was built with (seed, weights, enhancement or stopping rule)");
    const size_t old_count = previous.levels[0].size();
    if (new_of_old_vertex.size() != old_count)
        throw InvalidArgumentError("multires hierarchy rebuild: a vertex map of " + std::to_string(new_of_old_vertex.size()) +
                                   " entries for a hierarchy on " + std::to_string(old_count) + " vertices");
    std::vector<uint8_t> taken(matrix.size(), 0);
    for (size_t o = 0; o < old_count; ++o) {
        const int32_t v = new_of_old_vertex[o];
        if (v < -1 || v >= static_cast<int64_t>(matrix.size()))
            throw InvalidArgumentError("multires hierarchy rebuild: vertex " + std::to_string(o) + " maps to " +
                                       std::to_string(v) + ", outside the " + std::to_string(matrix.size()) +
                                       "-vertex matrix");
        if (v >= 0 && std::exchange(taken[static_cast<size_t>(v)], uint8_t{1}))
            throw InvalidArgumentError("multires hierarchy rebuild: two vertices map to vertex " + std::to_string(v));
    }
    return build_levels(matrix, positions, options, &previous, new_of_old_vertex);
}

std::vector<std::vector<int32_t>> hierarchy_level_vertices(const CompressedRows& graph, const HierarchyOptions& options) {
    std::vector<std::vector<int32_t>> levels;
    const CompressedRows* level_graph = &graph;  // G^0 is read in place, coarser graphs are owned
    CompressedRows coarse_graph;
    std::vector<int32_t> original(graph.row_count());
    std::iota(original.begin(), original.end(), 0);
    while (std::optional<CoarseningStep> step = coarsen(*level_graph, levels.size() + 1, options)) {
        std::vector<int32_t> kept(step->coarse_to_fine.size());
        for (size_t c = 0; c < kept.size(); ++c) kept[c] = original[static_cast<size_t>(step->coarse_to_fine[c])];
        coarse_graph = build_coarse_graph(*level_graph, step->selection.retained, step->coarse_index);
        level_graph = &coarse_graph;
        original = kept;
        levels.push_back(std::move(kept));
    }
    return levels;
}

}  // namespace waxwork
