#include "multires/independent_set.h"

#include "base/error.h"
#include "base/parallel_rows.h"
#include "multires/link_union.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <memory>
#include <string>

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
        if (in_queue[v]) {
            in_queue[v] = 1;  // 2 marks "dropped this round" below
            active.push_back(static_cast<int32_t>(v));
        }
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
        // Pass 2: selected vertices are retained and drop their queued neighbours (Gamma). Pushing from
        // the few selected rows reads less than every other active vertex searching its row for a
        // selected neighbour; two selected vertices may drop the same neighbour, hence the atomic
        // (relaxed: the same value, read only after the pass) byte stores.
        tbb::parallel_for(tbb::blocked_range<size_t>(0, active.size(), kGrain), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t a = r.begin(); a != r.end(); ++a) {
                const int32_t v = active[a];
                if (!selected[v]) continue;
                retained[v] = 1;
                for (int32_t u : graph.row(v)) {
                    std::atomic_ref<uint8_t> queued(in_queue[static_cast<size_t>(u)]);
                    if (queued.load(std::memory_order_relaxed) == 1) queued.store(2, std::memory_order_relaxed);
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

namespace {

// The enhancement test's lost connections, per vertex: the dropped neighbours j of a dropped vertex i
// with which it shares no retained neighbour are partners[graph.offsets[i] .. + count[i]). Laid out
// like the graph's rows (a vertex has at most its degree of partners), so every vertex fills its own
// slots in parallel with no counting pass.
struct LostConnections {
    std::vector<int32_t> count;
    // Not zero-filled: only the tested vertices' slots are written and read, and after a local update
    // (update_coarse_vertices) those lie on a few of the array's pages; filling it would touch all
    // of them (an array the size of the graph, for a region of a few thousand vertices).
    std::unique_ptr<int32_t[]> partners;
};

// Per thread, tag[u] == i when u is adjacent to a "joiner" of i: a neighbour k of i that can join i to
// its neighbours (retained; in the later passes, newly retained). A dropped pair (i, j) shares one
// exactly when tag[j] == i. Tagging the rows of i's few joiners reads contiguous rows; intersecting
// per-vertex lists of retained neighbours for every pair instead reads two scattered lists per pair
// and takes 1.7x as long at 97K vertices.
// One selection keeps its tags through all its tests: a tag left by an earlier test names a joiner
// that is still retained (the retained set only grows), so it can only say "joined", which stays true.
class JoinedTags {
public:
    explicit JoinedTags(size_t vertex_count) : tags_([vertex_count] { return std::vector<int32_t>(vertex_count, -1); }) {}

    // The calling thread's tags, to fetch once per range (each fetch is a thread-local lookup).
    std::vector<int32_t>& local() { return tags_.local(); }

    // Tags in `tags` the neighbours of each neighbour k of i with is_joiner(k).
    template <typename IsJoiner>
    static void tag(const CompressedRows& graph, size_t i, IsJoiner&& is_joiner, std::vector<int32_t>& tags) {
        const auto key = static_cast<int32_t>(i);
        for (int32_t k : graph.row(i))
            if (is_joiner(static_cast<size_t>(k)))
                for (int32_t u : graph.row(static_cast<size_t>(k))) tags[static_cast<size_t>(u)] = key;
    }

private:
    tbb::enumerable_thread_specific<std::vector<int32_t>> tags_;
};

// Tests the vertices `vertex(0 .. count)` names (every vertex, or a list); the others get no partners.
template <typename VertexAt>
LostConnections find_lost_connections(const CompressedRows& graph, std::span<const uint8_t> retained, size_t count,
                                      VertexAt&& vertex, JoinedTags& joined) {
    const size_t n = graph.row_count();
    LostConnections lost;
    lost.count.assign(n, 0);
    lost.partners = std::make_unique_for_overwrite<int32_t[]>(graph.indices.size());
    // Each vertex tests all its dropped neighbours (the test is symmetric, so both ends of a lost edge
    // list it), and writes only its own slots.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kGrain), [&](const tbb::blocked_range<size_t>& range) {
        std::vector<int32_t>& tag = joined.local();
        for (size_t a = range.begin(); a != range.end(); ++a) {
            const size_t i = vertex(a);
            if (retained[i]) continue;
            JoinedTags::tag(graph, i, [&](size_t k) { return retained[k] != 0; }, tag);
            auto out = static_cast<size_t>(graph.offsets[i]);
            for (int32_t j : graph.row(i))
                if (!retained[static_cast<size_t>(j)] && tag[static_cast<size_t>(j)] != static_cast<int32_t>(i))
                    lost.partners[out++] = j;
            lost.count[i] = static_cast<int32_t>(out - static_cast<size_t>(graph.offsets[i]));
        }
    });
    return lost;
}

LostConnections find_lost_connections(const CompressedRows& graph, std::span<const uint8_t> retained,
                                      JoinedTags& joined) {
    return find_lost_connections(graph, retained, graph.row_count(), [](size_t a) { return a; }, joined);
}

// The enhancement's later passes: which of `candidates` (ascending; the vertices with lost connections
// before the last independent-set pass, whose newly retained vertices are flagged in `fresh`) still
// have one. Retaining vertices never creates a lost connection (the retained set only grows, so a
// dropped pair keeps every common retained neighbour it had), so only the listed lost edges need
// testing again, and a common retained neighbour of a listed pair can only be a fresh vertex. The
// lists are compacted in place to the edges still lost.
std::vector<int32_t> still_lost(const CompressedRows& graph, std::span<const uint8_t> retained,
                                std::span<const uint8_t> fresh, std::span<const int32_t> candidates,
                                LostConnections& lost, JoinedTags& joined) {
    std::vector<uint8_t> is_lost(candidates.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<int32_t>& tag = joined.local();
        for (size_t a = r.begin(); a != r.end(); ++a) {
            const auto i = static_cast<size_t>(candidates[a]);
            if (retained[i]) continue;
            JoinedTags::tag(graph, i, [&](size_t k) { return fresh[k] != 0; }, tag);
            const auto first = static_cast<size_t>(graph.offsets[i]);
            size_t kept = first;
            for (size_t q = first; q < first + static_cast<size_t>(lost.count[i]); ++q) {
                const int32_t j = lost.partners[q];
                if (!retained[static_cast<size_t>(j)] && tag[static_cast<size_t>(j)] != static_cast<int32_t>(i))
                    lost.partners[kept++] = j;
            }
            lost.count[i] = static_cast<int32_t>(kept - first);
            is_lost[a] = kept > first;
        }
    });
    std::vector<int32_t> out;
    for (size_t a = 0; a < candidates.size(); ++a)
        if (is_lost[a]) out.push_back(candidates[a]);
    return out;
}

}  // namespace

std::vector<uint8_t> mark_lost_connections(const CompressedRows& graph, std::span<const uint8_t> retained) {
    JoinedTags joined(graph.row_count());
    const LostConnections lost = find_lost_connections(graph, retained, joined);
    std::vector<uint8_t> marked(lost.count.size());
    for (size_t v = 0; v < marked.size(); ++v) marked[v] = lost.count[v] > 0;
    return marked;
}

namespace {

int64_t count_retained(std::span<const uint8_t> retained) {
    int64_t count = 0;
    for (uint8_t r : retained) count += r;
    return count;
}

// The enhancement loop (independent_set.h) from the lost connections `lost` of `selection.retained`:
// marks their ends, runs the rounds on them, and repeats on the connections still lost.
void enhance_selection(const CompressedRows& graph, std::span<const uint32_t> codes, LostConnections& lost,
                       JoinedTags& joined, VertexSelection& selection) {
    const size_t n = graph.row_count();
    const int64_t before = count_retained(selection.retained);
    std::vector<uint8_t> marked(n, 0);
    std::vector<int32_t> candidates;
    for (size_t v = 0; v < n; ++v)
        if (lost.count[v] > 0) {
            marked[v] = 1;
            candidates.push_back(static_cast<int32_t>(v));
        }
    std::vector<uint8_t> fresh(n, 0);
    while (!candidates.empty()) {
        ++selection.enhancement_passes;
        run_independent_set_rounds(graph, codes, marked, selection.retained);  // clears `marked`
        // Only candidates were queued, so the candidates now retained are the pass's new vertices.
        for (int32_t v : candidates) fresh[static_cast<size_t>(v)] = selection.retained[static_cast<size_t>(v)];
        std::vector<int32_t> next = still_lost(graph, selection.retained, fresh, candidates, lost, joined);
        for (int32_t v : candidates) fresh[static_cast<size_t>(v)] = 0;
        candidates = std::move(next);
        for (int32_t v : candidates) marked[static_cast<size_t>(v)] = 1;
    }
    selection.enhancement_vertices += count_retained(selection.retained) - before;
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
    JoinedTags joined(n);
    LostConnections lost = find_lost_connections(graph, selection.retained, joined);
    enhance_selection(graph, codes, lost, joined, selection);
    return selection;
}

VertexSelection update_coarse_vertices(const CompressedRows& graph, uint32_t seed, bool enhance,
                                       std::span<const uint8_t> previous_retained, std::span<const int32_t> changed) {
    const size_t n = graph.row_count();
    if (previous_retained.size() != n)
        throw InvalidArgumentError("coarse vertex update: " + std::to_string(previous_retained.size()) +
                                   " previous flags for a " + std::to_string(n) + "-vertex graph");
    for (const int32_t v : changed)
        if (v < 0 || static_cast<size_t>(v) >= n)
            throw InvalidArgumentError("coarse vertex update: changed vertex " + std::to_string(v) + " is not in the " +
                                       std::to_string(n) + "-vertex graph");
    VertexSelection selection;
    selection.retained.assign(previous_retained.begin(), previous_retained.end());
    // The queue: the changed vertices and their dropped neighbours, all undecided again. A dropped
    // vertex further away keeps the retained neighbour that covered it (neither its row nor that
    // neighbour is touched), and two retained vertices newly adjacent both changed rows, so both are queued.
    std::vector<uint8_t> queue(n, 0);
    for (const int32_t v : changed) {
        queue[static_cast<size_t>(v)] = 1;
        for (const int32_t u : graph.row(static_cast<size_t>(v)))
            if (!selection.retained[static_cast<size_t>(u)]) queue[static_cast<size_t>(u)] = 1;
    }
    for (const int32_t v : changed) selection.retained[static_cast<size_t>(v)] = 0;
    std::vector<int32_t> queued;
    for (size_t v = 0; v < n; ++v)
        if (queue[v]) queued.push_back(static_cast<int32_t>(v));
    // A queued vertex next to a vertex that stays retained is covered by it: dropped before the rounds,
    // as if that neighbour had been selected in an earlier round. The rest run the rounds as usual.
    for (const int32_t v : queued)
        for (const int32_t u : graph.row(static_cast<size_t>(v)))
            if (selection.retained[static_cast<size_t>(u)]) {
                queue[static_cast<size_t>(v)] = 0;
                break;
            }
    const std::vector<uint32_t> codes = independent_set_codes(n, seed);
    selection.independent_set_rounds = run_independent_set_rounds(graph, codes, queue, selection.retained);
    if (!enhance) return selection;
    // A fine edge can lose its connection only where a row changed or a vertex changed state (the queue)
    // or next to such a vertex (a common neighbour changed state): test the queue and its neighbours. The
    // previous selection had no lost connection elsewhere, and nothing else changed there.
    std::vector<uint8_t> tested(n, 0);
    for (const int32_t v : queued) {
        tested[static_cast<size_t>(v)] = 1;
        for (const int32_t u : graph.row(static_cast<size_t>(v))) tested[static_cast<size_t>(u)] = 1;
    }
    std::vector<int32_t> region;
    for (size_t v = 0; v < n; ++v)
        if (tested[v]) region.push_back(static_cast<int32_t>(v));
    JoinedTags joined(n);
    LostConnections lost = find_lost_connections(graph, selection.retained, region.size(),
                                                 [&](size_t a) { return static_cast<size_t>(region[a]); }, joined);
    enhance_selection(graph, codes, lost, joined, selection);
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
                                  std::span<const int32_t> link_offsets, std::span<const int32_t> links,
                                  const CarriedRows* carried, const CompressedRows* previous) {
    std::vector<int32_t> coarse_to_fine;
    for (size_t v = 0; v < coarse_index.size(); ++v)
        if (coarse_index[v] >= 0) coarse_to_fine.push_back(static_cast<int32_t>(v));
    const size_t m = coarse_to_fine.size();
    // Row c (fine vertex i): the links of every neighbour j of i, except c itself. A retained j links
    // to itself (a fine edge between retained vertices is kept); a dropped j links to its retained
    // neighbours (the 2-ring through a dropped vertex), so each coarse neighbour comes several times.
    tbb::enumerable_thread_specific<LinkUnion> unions([m] { return LinkUnion(m); });
    CompressedRows coarse;
    build_rows_in_chunks(m, 512, coarse.offsets, coarse.indices, [&](size_t c, std::vector<int32_t>& row) {
        if (carried && carried->kept(c)) {
            for (const int32_t k : previous->row(static_cast<size_t>(carried->previous_row[c])))
                row.push_back(carried->new_of_old_column[static_cast<size_t>(k)]);
            return;
        }
        unions.local().append(graph.row(static_cast<size_t>(coarse_to_fine[c])), link_offsets.data(), links.data(),
                              static_cast<int32_t>(c), row);
    });
    return coarse;
}

}  // namespace waxwork
