#include "multires/independent_set.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>

namespace waxwork {

namespace {

// TEA (Wheeler and Needham's Tiny Encryption Algorithm) with the vertex index and the seed as the
// plaintext and a fixed key: the GPU-friendly hash family of the paper's reference [30]. Eight
// rounds already decorrelate neighbouring indices, which is all the independent set needs.
uint32_t tea_hash(uint32_t v0, uint32_t v1) {
    constexpr uint32_t key[4] = {0xa341316cu, 0xc8013ea4u, 0xad90777du, 0x7e95761eu};
    uint32_t sum = 0;
    for (int round = 0; round < 8; ++round) {
        sum += 0x9e3779b9u;
        v0 += ((v1 << 4) + key[0]) ^ (v1 + sum) ^ ((v1 >> 5) + key[1]);
        v1 += ((v0 << 4) + key[2]) ^ (v0 + sum) ^ ((v0 >> 5) + key[3]);
    }
    return v0 ^ v1;
}

constexpr size_t kGrain = 2048;

}  // namespace

std::vector<uint32_t> independent_set_codes(size_t vertex_count, uint32_t seed) {
    // Low bits hold the index (unique codes); the remaining high bits hold the hash.
    const int index_bits = vertex_count <= 1 ? 1 : std::bit_width(static_cast<uint32_t>(vertex_count - 1));
    const uint32_t index_mask = index_bits >= 32 ? 0xffffffffu : ((1u << index_bits) - 1u);
    std::vector<uint32_t> codes(vertex_count);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertex_count, kGrain), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
            const auto index = static_cast<uint32_t>(v);
            codes[v] = (tea_hash(index, seed) & ~index_mask) | index;
        }
    });
    return codes;
}

int run_independent_set_rounds(const CompressedRows& graph, std::span<const uint32_t> codes,
                               std::vector<uint8_t>& in_queue, std::vector<uint8_t>& retained) {
    const size_t n = graph.row_count();
    std::vector<int32_t> active;
    for (size_t v = 0; v < n; ++v)
        if (in_queue[v]) active.push_back(static_cast<int32_t>(v));
    std::vector<uint8_t> selected(n, 0);
    int rounds = 0;
    while (!active.empty()) {
        ++rounds;
        // Pass 1 reads the queue only: i is selected when its code is below every queued neighbour's.
        tbb::parallel_for(tbb::blocked_range<size_t>(0, active.size(), kGrain), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t a = r.begin(); a != r.end(); ++a) {
                const int32_t v = active[a];
                bool minimum = true;
                for (int32_t u : graph.row(v))
                    if (in_queue[u] && codes[u] < codes[v]) {
                        minimum = false;
                        break;
                    }
                selected[v] = minimum;
            }
        });
        // Pass 2 reads the selection only: selected vertices are retained, their queued neighbours
        // (Gamma) dropped. Each vertex writes only its own flags.
        tbb::parallel_for(tbb::blocked_range<size_t>(0, active.size(), kGrain), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t a = r.begin(); a != r.end(); ++a) {
                const int32_t v = active[a];
                if (selected[v]) {
                    retained[v] = 1;
                    continue;
                }
                for (int32_t u : graph.row(v))
                    if (selected[u]) {
                        in_queue[v] = 2;  // decided this round (dropped); cleared below
                        break;
                    }
            }
        });
        size_t kept = 0;
        for (int32_t v : active) {
            if (selected[v] || in_queue[v] == 2) {
                in_queue[v] = 0;
                selected[v] = 0;
            } else {
                active[kept++] = v;
            }
        }
        active.resize(kept);
    }
    return rounds;
}

std::vector<uint8_t> mark_lost_connections(const CompressedRows& graph, std::span<const uint8_t> retained) {
    const size_t n = graph.row_count();
    // R(v) = N(v) cap P^{l+1} for every vertex first: these lists hold one to a few entries, so testing
    // an edge is a merge of two tiny lists instead of two full (on coarse levels, long) neighbourhoods.
    CompressedRows r;
    r.offsets.assign(n + 1, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) {
            int32_t count = 0;
            for (int32_t u : graph.row(v)) count += retained[static_cast<size_t>(u)];
            r.offsets[v + 1] = count;
        }
    });
    for (size_t v = 0; v < n; ++v) r.offsets[v + 1] += r.offsets[v];
    r.indices.resize(static_cast<size_t>(r.offsets[n]));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) {
            auto out = static_cast<size_t>(r.offsets[v]);
            for (int32_t u : graph.row(v))
                if (retained[static_cast<size_t>(u)]) r.indices[out++] = u;
        }
    });
    std::vector<uint8_t> marked(n, 0);
    // Each vertex tests all its dropped neighbours (the test is symmetric), so every vertex writes only
    // its own mark.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
            if (retained[i]) continue;
            const auto ri = r.row(i);
            for (int32_t j : graph.row(i)) {
                if (retained[static_cast<size_t>(j)]) continue;
                const auto rj = r.row(static_cast<size_t>(j));
                bool shared = false;
                auto a = ri.begin();
                auto b = rj.begin();
                while (a != ri.end() && b != rj.end() && !shared) {
                    if (*a < *b) {
                        ++a;
                    } else if (*b < *a) {
                        ++b;
                    } else {
                        shared = true;
                    }
                }
                if (!shared) {
                    marked[i] = 1;
                    break;
                }
            }
        }
    });
    return marked;
}

VertexSelection select_coarse_vertices(const CompressedRows& graph, uint32_t seed, bool enhance) {
    const size_t n = graph.row_count();
    VertexSelection selection;
    selection.retained.assign(n, 0);
    const std::vector<uint32_t> codes = independent_set_codes(n, seed);
    std::vector<uint8_t> queue(n, 1);
    selection.independent_set_rounds = run_independent_set_rounds(graph, codes, queue, selection.retained);
    if (!enhance) return selection;
    int64_t before = 0;
    for (uint8_t r : selection.retained) before += r;
    while (true) {
        std::vector<uint8_t> marked = mark_lost_connections(graph, selection.retained);
        if (std::find(marked.begin(), marked.end(), uint8_t{1}) == marked.end()) break;
        ++selection.enhancement_passes;
        run_independent_set_rounds(graph, codes, marked, selection.retained);
    }
    int64_t after = 0;
    for (uint8_t r : selection.retained) after += r;
    selection.enhancement_vertices = after - before;
    return selection;
}

std::vector<int32_t> coarse_vertex_index(std::span<const uint8_t> retained) {
    std::vector<int32_t> index(retained.size(), -1);
    int32_t next = 0;
    for (size_t v = 0; v < retained.size(); ++v)
        if (retained[v]) index[v] = next++;
    return index;
}

CompressedRows build_coarse_graph(const CompressedRows& graph, std::span<const uint8_t> retained,
                                  std::span<const int32_t> coarse_index) {
    std::vector<int32_t> coarse_to_fine;
    for (size_t v = 0; v < retained.size(); ++v)
        if (retained[v]) coarse_to_fine.push_back(static_cast<int32_t>(v));
    const size_t m = coarse_to_fine.size();
    std::vector<std::vector<int32_t>> rows(m);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, m, 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t c = r.begin(); c != r.end(); ++c) {
            const int32_t i = coarse_to_fine[c];
            std::vector<int32_t>& row = rows[c];
            for (int32_t j : graph.row(i)) {
                if (retained[j]) {
                    row.push_back(coarse_index[j]);  // fine edge between retained vertices: kept
                } else {
                    for (int32_t k : graph.row(j))  // 2-ring through the dropped vertex j
                        if (retained[k] && k != i) row.push_back(coarse_index[k]);
                }
            }
            std::sort(row.begin(), row.end());
            row.erase(std::unique(row.begin(), row.end()), row.end());
        }
    });
    CompressedRows coarse;
    coarse.offsets.assign(m + 1, 0);
    for (size_t c = 0; c < m; ++c) coarse.offsets[c + 1] = coarse.offsets[c] + static_cast<int32_t>(rows[c].size());
    coarse.indices.resize(static_cast<size_t>(coarse.offsets[m]));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, m, 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t c = r.begin(); c != r.end(); ++c)
            std::copy(rows[c].begin(), rows[c].end(), coarse.indices.begin() + coarse.offsets[c]);
    });
    return coarse;
}

}  // namespace waxwork
