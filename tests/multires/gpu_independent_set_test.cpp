// The device vertex selection (multires/gpu_independent_set.h) against the CPU one, on Mesa's llvmpipe
// through OSMesa in CI: the same codes bit for bit, and the same retained set, rounds and enhancement
// counts on a level-0 graph, on coarse graphs (denser rows, where the enhancement does most) and on
// irregular random graphs, for several seeds.
#include "multires/gpu_independent_set.h"
#include "multires/independent_set.h"
#include "solver/gpu_test_context.h"
#include "multires_test_systems.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

namespace waxwork {
namespace {

void expect_same_selection(GpuVertexSelector& gpu, const CompressedRows& graph, uint32_t seed, bool enhance) {
    const VertexSelection want = select_coarse_vertices(graph, seed, enhance);
    const VertexSelection got = gpu.select(graph, seed, enhance);
    EXPECT_EQ(got.retained, want.retained) << "seed " << seed;
    EXPECT_EQ(got.independent_set_rounds, want.independent_set_rounds);
    EXPECT_EQ(got.enhancement_passes, want.enhancement_passes);
    EXPECT_EQ(got.enhancement_vertices, want.enhancement_vertices);
}

// A symmetric graph with sorted rows and no self loops: each vertex joined to a few random others
// (degrees from 1 to ~20, like coarse levels, plus isolated vertices).
CompressedRows random_graph(size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::vector<std::set<int32_t>> rows(n);
    std::uniform_int_distribution<int32_t> pick(0, static_cast<int32_t>(n) - 1);
    std::uniform_int_distribution<int> degree(0, 10);
    for (size_t v = 0; v + 5 < n; ++v)
        for (int k = degree(rng); k > 0; --k) {
            const int32_t u = pick(rng);
            if (u == static_cast<int32_t>(v)) continue;
            rows[v].insert(u);
            rows[static_cast<size_t>(u)].insert(static_cast<int32_t>(v));
        }
    CompressedRows g;
    for (const auto& row : rows) {
        g.indices.insert(g.indices.end(), row.begin(), row.end());
        g.offsets.push_back(static_cast<int32_t>(g.indices.size()));
    }
    return g;
}

TEST(GpuVertexSelector, CodesEqualTheCpuCodes) {
    WAXWORK_REQUIRE_GL(context);
    GpuVertexSelector gpu(context->gl());
    for (size_t n : {size_t{1}, size_t{2}, size_t{1000}, size_t{70000}})
        for (uint32_t seed : {0u, 1u, 0xdeadbeefu}) EXPECT_EQ(gpu.codes(n, seed), independent_set_codes(n, seed)) << n;
}

TEST(GpuVertexSelector, SameSelectionAsTheCpuOnAMeshGraphAndItsCoarseGraphs) {
    WAXWORK_REQUIRE_GL(context);
    GpuVertexSelector gpu(context->gl());
    const testing::TestSystem s = testing::make_test_system(10);
    CompressedRows graph = s.connectivity.vertex_vertices;
    for (int level = 0; level < 3; ++level) {
        for (uint32_t seed : {1u, 7u}) {
            expect_same_selection(gpu, graph, seed, true);
            expect_same_selection(gpu, graph, seed, false);
        }
        const VertexSelection selection = select_coarse_vertices(graph, 1, true);
        if (level == 0) {
            EXPECT_GT(selection.enhancement_passes, 0);  // the enhancement is exercised
        }
        graph = build_coarse_graph(graph, selection.retained, coarse_vertex_index(selection.retained));
    }
}

TEST(GpuVertexSelector, SameSelectionAsTheCpuOnRandomGraphs) {
    WAXWORK_REQUIRE_GL(context);
    GpuVertexSelector gpu(context->gl());
    for (unsigned seed = 0; seed < 4; ++seed) expect_same_selection(gpu, random_graph(3000 + 500 * seed, seed), seed, true);
}

TEST(GpuVertexSelector, EmptyAndEdgelessGraphs) {
    WAXWORK_REQUIRE_GL(context);
    GpuVertexSelector gpu(context->gl());
    EXPECT_TRUE(gpu.select(CompressedRows{}, 1).retained.empty());
    CompressedRows isolated;
    isolated.offsets.assign(6, 0);
    expect_same_selection(gpu, isolated, 3, true);  // every vertex is its own minimum: all retained
}

}  // namespace
}  // namespace waxwork
