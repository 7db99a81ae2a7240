#include "multires/hierarchy.h"
#include "multires/independent_set.h"
#include "multires_test_systems.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <numeric>
#include <queue>
#include <random>
#include <set>

namespace waxwork {
namespace {

bool adjacent(const CompressedRows& g, int32_t a, int32_t b) {
    const auto row = g.row(static_cast<size_t>(a));
    return std::binary_search(row.begin(), row.end(), b);
}

// Breadth-first distances from `source`, up to `limit` steps (-1 beyond).
std::vector<int> distances(const CompressedRows& g, int32_t source, int limit) {
    std::vector<int> d(g.row_count(), -1);
    std::queue<int32_t> queue;
    d[static_cast<size_t>(source)] = 0;
    queue.push(source);
    while (!queue.empty()) {
        const int32_t v = queue.front();
        queue.pop();
        if (d[static_cast<size_t>(v)] == limit) continue;
        for (int32_t u : g.row(static_cast<size_t>(v)))
            if (d[static_cast<size_t>(u)] < 0) {
                d[static_cast<size_t>(u)] = d[static_cast<size_t>(v)] + 1;
                queue.push(u);
            }
    }
    return d;
}

// A 3D lattice of side^3 vertices with 6-neighbour edges, vertex v of the lattice numbered order[v].
CompressedRows lattice_graph(int side, const std::vector<int32_t>& order) {
    const auto n = static_cast<size_t>(side) * static_cast<size_t>(side) * static_cast<size_t>(side);
    std::vector<std::vector<int32_t>> rows(n);
    auto id = [&](int x, int y, int z) { return static_cast<size_t>((z * side + y) * side + x); };
    for (int z = 0; z < side; ++z)
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x) {
                const int32_t v = order[id(x, y, z)];
                if (x + 1 < side) rows[static_cast<size_t>(v)].push_back(order[id(x + 1, y, z)]);
                if (x > 0) rows[static_cast<size_t>(v)].push_back(order[id(x - 1, y, z)]);
                if (y + 1 < side) rows[static_cast<size_t>(v)].push_back(order[id(x, y + 1, z)]);
                if (y > 0) rows[static_cast<size_t>(v)].push_back(order[id(x, y - 1, z)]);
                if (z + 1 < side) rows[static_cast<size_t>(v)].push_back(order[id(x, y, z + 1)]);
                if (z > 0) rows[static_cast<size_t>(v)].push_back(order[id(x, y, z - 1)]);
            }
    CompressedRows g;
    g.offsets.assign(n + 1, 0);
    for (size_t v = 0; v < n; ++v) {
        std::sort(rows[v].begin(), rows[v].end());
        g.offsets[v + 1] = g.offsets[v] + static_cast<int32_t>(rows[v].size());
        g.indices.insert(g.indices.end(), rows[v].begin(), rows[v].end());
    }
    return g;
}

// The coarse graph by its definition: retained pairs adjacent in G or sharing a dropped neighbour.
std::vector<std::pair<int32_t, int32_t>> coarse_edges_by_definition(const CompressedRows& g,
                                                                    const std::vector<uint8_t>& retained,
                                                                    const std::vector<int32_t>& index) {
    std::vector<std::pair<int32_t, int32_t>> edges;
    for (size_t v = 0; v < g.row_count(); ++v)
        for (int32_t a : g.row(v)) {
            if (!retained[static_cast<size_t>(a)]) continue;
            if (retained[v]) edges.emplace_back(index[v], index[static_cast<size_t>(a)]);
            else
                for (int32_t b : g.row(v))
                    if (b != a && retained[static_cast<size_t>(b)])
                        edges.emplace_back(index[static_cast<size_t>(a)], index[static_cast<size_t>(b)]);
        }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    return edges;
}

void expect_independent_and_dominating(const CompressedRows& g, const std::vector<uint8_t>& retained) {
    size_t kept = 0;
    for (size_t v = 0; v < g.row_count(); ++v) {
        bool has_retained_neighbour = false;
        for (int32_t u : g.row(v)) {
            if (retained[v]) { EXPECT_FALSE(retained[static_cast<size_t>(u)]) << "retained " << v << " and " << u << " are adjacent"; }
            has_retained_neighbour = has_retained_neighbour || retained[static_cast<size_t>(u)];
        }
        if (!retained[v]) { EXPECT_TRUE(has_retained_neighbour) << "dropped vertex " << v << " has no retained neighbour"; }
        kept += retained[v];
    }
    EXPECT_GT(kept, 0u);
    EXPECT_LT(kept, g.row_count());
}

TEST(IndependentSet, CodesAreUniqueAndCarryTheIndex) {
    const auto codes = independent_set_codes(5000, 7);
    std::set<uint32_t> unique(codes.begin(), codes.end());
    EXPECT_EQ(unique.size(), codes.size());
    for (size_t v = 0; v < codes.size(); ++v) EXPECT_EQ(codes[v] & 0x1fffu, v);  // 13 index bits
    // The hash, not the index, orders the vertices: neighbouring indices are not sorted.
    int ascending = 0;
    for (size_t v = 1; v < codes.size(); ++v) ascending += codes[v] > codes[v - 1];
    EXPECT_GT(ascending, 2000);
    EXPECT_LT(ascending, 3000);
    EXPECT_NE(independent_set_codes(5000, 8), codes);
}

TEST(IndependentSet, BeforeEnhancementIsIndependentAndDominating) {
    const auto s = testing::make_test_system(8);
    const CompressedRows& g = s.connectivity.vertex_vertices;
    const VertexSelection selection = select_coarse_vertices(g, 3, /*enhance=*/false);
    expect_independent_and_dominating(g, selection.retained);
    EXPECT_GT(selection.independent_set_rounds, 1);
    // Also on a denser coarse graph (level 1 of the hierarchy).
    const auto index = coarse_vertex_index(selection.retained);
    const CompressedRows coarse = build_coarse_graph(g, selection.retained, index);
    expect_independent_and_dominating(coarse, select_coarse_vertices(coarse, 4, false).retained);
}

TEST(IndependentSet, EnhancementLeavesNoLostConnection) {
    const auto s = testing::make_test_system(8);
    const CompressedRows& g = s.connectivity.vertex_vertices;
    const VertexSelection plain = select_coarse_vertices(g, 3, false);
    const auto lost_before = mark_lost_connections(g, plain.retained);
    const VertexSelection selection = select_coarse_vertices(g, 3, true);
    const auto& retained = selection.retained;
    // The enhancement only adds vertices to the plain independent set.
    for (size_t v = 0; v < g.row_count(); ++v)
        if (plain.retained[v]) { EXPECT_TRUE(retained[v]); }
    const int64_t marked_before = std::count(lost_before.begin(), lost_before.end(), uint8_t{1});
    EXPECT_EQ(marked_before > 0, selection.enhancement_passes > 0);
    const auto lost_after = mark_lost_connections(g, retained);
    EXPECT_EQ(std::count(lost_after.begin(), lost_after.end(), uint8_t{1}), 0);

    const auto index = coarse_vertex_index(retained);
    const CompressedRows coarse = build_coarse_graph(g, retained, index);
    for (size_t v = 0; v < g.row_count(); ++v) {
        // Interpolation stays possible: every dropped vertex keeps a retained neighbour.
        if (!retained[v]) {
            bool any = false;
            for (int32_t u : g.row(v)) any = any || retained[static_cast<size_t>(u)];
            EXPECT_TRUE(any) << v;
        }
        for (int32_t u : g.row(v)) {
            // Every dropped-dropped edge has a common retained neighbour (the enhancement's criterion).
            if (!retained[v] && !retained[static_cast<size_t>(u)]) {
                bool shared = false;
                for (int32_t w : g.row(v)) shared = shared || (retained[static_cast<size_t>(w)] && adjacent(g, u, w));
                EXPECT_TRUE(shared) << v << "-" << u;
            }
            // No fine edge between coarse vertices is lost.
            if (retained[v] && retained[static_cast<size_t>(u)]) {
                EXPECT_TRUE(adjacent(coarse, index[v], index[static_cast<size_t>(u)]));
            }
        }
        // Retained vertices two steps apart through a dropped vertex are coarse neighbours.
        if (!retained[v]) {
            for (int32_t a : g.row(v))
                for (int32_t b : g.row(v))
                    if (a != b && retained[static_cast<size_t>(a)] && retained[static_cast<size_t>(b)]) {
                        EXPECT_TRUE(adjacent(coarse, index[static_cast<size_t>(a)], index[static_cast<size_t>(b)]));
                    }
        }
    }
    // 3-ring neighbours (Fig. 3: i_1 - j - j' - i_3 with both middle vertices dropped) stay within two
    // coarse steps; any two retained vertices within three fine steps stay within three coarse steps
    // (a path through retained vertices keeps its edges, so the coarse distance never grows).
    for (size_t v = 0; v < g.row_count(); ++v) {
        if (!retained[v]) continue;
        const auto fine_d = distances(g, static_cast<int32_t>(v), 3);
        const auto coarse_d = distances(coarse, index[v], 3);
        for (size_t u = 0; u < g.row_count(); ++u)
            if (retained[u] && fine_d[u] > 0) { EXPECT_GE(coarse_d[static_cast<size_t>(index[u])], 0) << v << " " << u; }
    }
    for (size_t i = 0; i < g.row_count(); ++i) {
        if (retained[i]) continue;
        for (int32_t j : g.row(i)) {
            if (retained[static_cast<size_t>(j)]) continue;
            for (int32_t a : g.row(i)) {
                if (!retained[static_cast<size_t>(a)]) continue;
                const auto coarse_d = distances(coarse, index[static_cast<size_t>(a)], 2);
                for (int32_t b : g.row(static_cast<size_t>(j)))
                    if (retained[static_cast<size_t>(b)] && b != a) {
                        EXPECT_GE(coarse_d[static_cast<size_t>(index[static_cast<size_t>(b)])], 0) << a << " " << b;
                    }
            }
        }
    }
    // The coarse graph is symmetric, sorted, without self loops, and nothing beyond the 2-ring.
    for (size_t c = 0; c < coarse.row_count(); ++c) {
        const auto row = coarse.row(c);
        EXPECT_TRUE(std::is_sorted(row.begin(), row.end()));
        for (int32_t d : row) {
            EXPECT_NE(static_cast<size_t>(d), c);
            EXPECT_TRUE(adjacent(coarse, d, static_cast<int32_t>(c)));
        }
    }
}

// build_coarse_graph reads each row back either by scanning a bitmap over the row's span of coarse
// indices or, when that span is long against the row's links (vertex orders without spatial
// coherence), by walking the links again and sorting. In lattice order the spans are short; shuffled,
// they cover most of the index range. Both must give exactly the definition, rows sorted and unique.
TEST(IndependentSet, CoarseGraphIsTheDefinitionInAnyVertexOrder) {
    constexpr int side = 40;
    std::vector<int32_t> order(static_cast<size_t>(side * side * side));
    std::iota(order.begin(), order.end(), 0);
    for (const bool shuffled : {false, true}) {
        if (shuffled) std::shuffle(order.begin(), order.end(), std::mt19937(5));
        const CompressedRows g = lattice_graph(side, order);
        const VertexSelection selection = select_coarse_vertices(g, 2);
        const auto index = coarse_vertex_index(selection.retained);
        const CompressedRows coarse = build_coarse_graph(g, selection.retained, index);
        std::vector<std::pair<int32_t, int32_t>> edges;
        std::vector<int32_t> spans;
        for (size_t c = 0; c < coarse.row_count(); ++c) {
            const auto row = coarse.row(c);
            ASSERT_FALSE(row.empty());
            EXPECT_TRUE(std::adjacent_find(row.begin(), row.end(), std::greater_equal<>()) == row.end())
                << "row " << c << " is not strictly ascending";
            for (int32_t d : row) edges.emplace_back(static_cast<int32_t>(c), d);
            spans.push_back(row.back() - row.front());
        }
        EXPECT_EQ(edges, coarse_edges_by_definition(g, selection.retained, index)) << "shuffled: " << shuffled;
        std::nth_element(spans.begin(), spans.begin() + static_cast<std::ptrdiff_t>(spans.size() / 2), spans.end());
        const double median_span = static_cast<double>(spans[spans.size() / 2]) / static_cast<double>(coarse.row_count());
        if (shuffled) { EXPECT_GT(median_span, 0.5); } else { EXPECT_LT(median_span, 0.1); }
    }
}

TEST(IndependentSet, DeterministicForASeed) {
    const auto s = testing::make_test_system(6);
    const CompressedRows& g = s.connectivity.vertex_vertices;
    EXPECT_EQ(select_coarse_vertices(g, 11).retained, select_coarse_vertices(g, 11).retained);
    EXPECT_NE(select_coarse_vertices(g, 11).retained, select_coarse_vertices(g, 12).retained);
}

}  // namespace
}  // namespace waxwork
