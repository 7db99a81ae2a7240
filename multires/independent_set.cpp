#include "multires/independent_set.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
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

namespace {

// mark_lost_connections restricted to `candidates` (ascending), for the enhancement's later passes.
// Retaining vertices never creates a lost connection (the retained set only grows, so a dropped pair
// keeps every common retained neighbour it had), hence a vertex unmarked after one pass stays
// unmarked and only the previous pass's marks need testing again. R(i) is marked in a per-thread tag
// array instead of the full R lists: the candidates are few after the first pass.
std::vector<int32_t> still_lost(const CompressedRows& graph, std::span<const uint8_t> retained,
                                std::span<const int32_t> candidates) {
    const size_t n = graph.row_count();
    std::vector<uint8_t> lost(candidates.size(), 0);
    tbb::enumerable_thread_specific<std::vector<int32_t>> tags([n] { return std::vector<int32_t>(n, -1); });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<int32_t>& tag = tags.local();
        for (size_t a = r.begin(); a != r.end(); ++a) {
            const int32_t i = candidates[a];
            if (retained[static_cast<size_t>(i)]) continue;
            for (int32_t k : graph.row(static_cast<size_t>(i)))
                if (retained[static_cast<size_t>(k)]) tag[static_cast<size_t>(k)] = i;
            for (int32_t j : graph.row(static_cast<size_t>(i))) {
                if (retained[static_cast<size_t>(j)]) continue;
                bool shared = false;
                for (int32_t k : graph.row(static_cast<size_t>(j)))
                    if (tag[static_cast<size_t>(k)] == i) {
                        shared = true;
                        break;
                    }
                if (!shared) {
                    lost[a] = 1;
                    break;
                }
            }
        }
    });
    std::vector<int32_t> out;
    for (size_t a = 0; a < candidates.size(); ++a)
        if (lost[a]) out.push_back(candidates[a]);
    return out;
}

}  // namespace

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
    std::vector<uint8_t> marked = mark_lost_connections(graph, selection.retained);
    std::vector<int32_t> candidates;
    for (size_t v = 0; v < n; ++v)
        if (marked[v]) candidates.push_back(static_cast<int32_t>(v));
    while (!candidates.empty()) {
        ++selection.enhancement_passes;
        run_independent_set_rounds(graph, codes, marked, selection.retained);  // clears `marked`
        candidates = still_lost(graph, selection.retained, candidates);
        for (int32_t v : candidates) marked[static_cast<size_t>(v)] = 1;
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
    // Links: the coarse index of a retained vertex, the retained neighbours' of a dropped one.
    const size_t n = graph.row_count();
    CompressedRows links;
    links.offsets.assign(n + 1, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) {
            int32_t count = 1;
            if (!retained[v]) {
                count = 0;
                for (int32_t u : graph.row(v)) count += retained[static_cast<size_t>(u)];
            }
            links.offsets[v + 1] = count;
        }
    });
    for (size_t v = 0; v < n; ++v) links.offsets[v + 1] += links.offsets[v];
    links.indices.resize(static_cast<size_t>(links.offsets[n]));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) {
            auto out = static_cast<size_t>(links.offsets[v]);
            if (retained[v]) {
                links.indices[out] = coarse_index[v];
                continue;
            }
            for (int32_t u : graph.row(v))
                if (retained[static_cast<size_t>(u)]) links.indices[out++] = coarse_index[static_cast<size_t>(u)];
        }
    });
    return build_coarse_graph(graph, coarse_index, links.offsets, links.indices);
}

CompressedRows build_coarse_graph(const CompressedRows& graph, std::span<const int32_t> coarse_index,
                                  std::span<const int32_t> link_offsets, std::span<const int32_t> links) {
    std::vector<int32_t> coarse_to_fine;
    for (size_t v = 0; v < coarse_index.size(); ++v)
        if (coarse_index[v] >= 0) coarse_to_fine.push_back(static_cast<int32_t>(v));
    const size_t m = coarse_to_fine.size();
    // Row c (fine vertex i): the links of every neighbour j of i, except c itself. A retained j links
    // to itself (a fine edge between retained vertices is kept); a dropped j links to its retained
    // neighbours (the 2-ring through a dropped vertex). Deduplicated with a per-thread tag array
    // instead of a container per row: the 2-ring repeats each coarse neighbour several times.
    tbb::enumerable_thread_specific<std::vector<int32_t>> tags([m] { return std::vector<int32_t>(m, -1); });
    auto walk = [&](size_t c, std::vector<int32_t>& tag, auto&& emit) {
        const auto key = static_cast<int32_t>(c);
        for (int32_t j : graph.row(static_cast<size_t>(coarse_to_fine[c]))) {
            for (int32_t q = link_offsets[static_cast<size_t>(j)]; q < link_offsets[static_cast<size_t>(j) + 1]; ++q) {
                const int32_t k = links[static_cast<size_t>(q)];
                if (k != key && tag[static_cast<size_t>(k)] != key) {
                    tag[static_cast<size_t>(k)] = key;
                    emit(k);
                }
            }
        }
    };
    // One walk per row into per-chunk buffers (fixed chunks: the layout does not depend on the thread
    // count), then the rows are copied into place once the offsets are known.
    constexpr size_t kChunk = 512;
    const size_t chunks = (m + kChunk - 1) / kChunk;
    std::vector<std::vector<int32_t>> buffers(chunks);
    CompressedRows coarse;
    coarse.offsets.assign(m + 1, 0);
    tbb::parallel_for(size_t{0}, chunks, [&](size_t chunk) {
        std::vector<int32_t>& tag = tags.local();
        std::vector<int32_t>& buffer = buffers[chunk];
        for (size_t c = chunk * kChunk; c < std::min(m, (chunk + 1) * kChunk); ++c) {
            const size_t first = buffer.size();
            walk(c, tag, [&](int32_t k) { buffer.push_back(k); });
            std::sort(buffer.begin() + static_cast<std::ptrdiff_t>(first), buffer.end());
            coarse.offsets[c + 1] = static_cast<int32_t>(buffer.size() - first);
        }
    });
    for (size_t c = 0; c < m; ++c) coarse.offsets[c + 1] += coarse.offsets[c];
    coarse.indices.resize(static_cast<size_t>(coarse.offsets[m]));
    tbb::parallel_for(size_t{0}, chunks, [&](size_t chunk) {
        std::copy(buffers[chunk].begin(), buffers[chunk].end(),
                  coarse.indices.begin() + coarse.offsets[chunk * kChunk]);
    });
    return coarse;
}

}  // namespace waxwork
