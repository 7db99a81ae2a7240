#include "tetops/connectivity.h"

#include "base/error.h"
#include "base/timing.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <limits>
#include <numeric>
#include <string>

namespace waxwork {
namespace {

using Clock = std::chrono::steady_clock;

// Exclusive prefix sum of counts into offsets (size n+1).
std::vector<int32_t> offsets_from_counts(const std::vector<int32_t>& counts) {
    std::vector<int32_t> offsets(counts.size() + 1, 0);
    std::inclusive_scan(counts.begin(), counts.end(), offsets.begin() + 1);
    return offsets;
}

// Lowers `slot` to `value` when that is smaller: a deterministic "first bad index" out of a parallel loop.
void lower_to(std::atomic<int64_t>& slot, int64_t value) {
    int64_t seen = slot.load(std::memory_order_relaxed);
    while (value < seen && !slot.compare_exchange_weak(seen, value, std::memory_order_relaxed)) {
    }
}

// Parallel counting sort of elements by vertex. The elements are cut into a few contiguous blocks, each
// with its own histogram; a vertex's row takes block 0's elements, then block 1's, and so on, so every
// row comes out ascending and the result does not depend on the number of blocks or threads. Two
// passes over the elements (count, scatter) as in a serial counting sort, on every core. Returns the
// lowest element naming a vertex outside [0, vertex_count), or -1; `rows` is filled only in the latter
// case.
template <size_t N>
int64_t sort_elements_by_vertex(const std::vector<std::array<int32_t, N>>& elements, size_t vertex_count,
                                CompressedRows& rows) {
    const size_t count = elements.size();
    constexpr size_t kMinBlock = 32768;  // below this a block's histogram costs more than its elements
    const auto threads = static_cast<size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
    const size_t blocks = std::clamp<size_t>(std::min(threads, count / kMinBlock), 1, 8);
    const auto block_begin = [&](size_t b) { return count * b / blocks; };
    const uint64_t n_vertices = vertex_count;
    std::vector<std::vector<int32_t>> histograms(blocks);
    std::atomic<int64_t> first_bad{std::numeric_limits<int64_t>::max()};
    tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
        std::vector<int32_t>& h = histograms[b];
        h.assign(vertex_count, 0);
        for (size_t e = block_begin(b); e < block_begin(b + 1); ++e)
            for (int32_t v : elements[e]) {
                if (static_cast<uint64_t>(static_cast<uint32_t>(v)) >= n_vertices) {
                    lower_to(first_bad, static_cast<int64_t>(e));
                    break;
                }
                ++h[static_cast<size_t>(v)];
            }
    });
    if (first_bad.load() != std::numeric_limits<int64_t>::max()) return first_bad.load();

    rows.offsets.assign(vertex_count + 1, 0);
    for (size_t v = 0; v < vertex_count; ++v) {
        int32_t total = 0;
        for (const std::vector<int32_t>& h : histograms) total += h[v];
        rows.offsets[v + 1] = rows.offsets[v] + total;
    }
    // Each block's histogram becomes its cursor: where the block's first element of each row goes.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertex_count, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
            int32_t at = rows.offsets[v];
            for (std::vector<int32_t>& h : histograms) {
                const int32_t c = h[v];
                h[v] = at;
                at += c;
            }
        }
    });
    rows.indices.resize(static_cast<size_t>(rows.offsets.back()));
    tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
        std::vector<int32_t>& cursor = histograms[b];
        for (size_t e = block_begin(b); e < block_begin(b + 1); ++e)
            for (int32_t v : elements[e]) rows.indices[static_cast<size_t>(cursor[v]++)] = static_cast<int32_t>(e);
    });
    return -1;
}

// vertex_tets, after checking every vertex index: InvalidMeshError names the lowest bad tet.
CompressedRows checked_vertex_tets(const TetMesh& mesh) {
    CompressedRows rows;
    const int64_t bad = sort_elements_by_vertex(mesh.tets, mesh.vertex_count(), rows);
    if (bad >= 0) {
        const Tet& tet = mesh.tets[static_cast<size_t>(bad)];
        int32_t v = tet[0];
        for (int32_t u : tet)
            if (u < 0 || static_cast<size_t>(u) >= mesh.vertex_count()) {
                v = u;
                break;
            }
        throw InvalidMeshError("tet " + std::to_string(bad) + " references vertex " + std::to_string(v) +
                               " out of range");
    }
    return rows;
}

// Face neighbours, each face matched exactly once at its smallest vertex: the faces of that vertex's
// star for which it is the minimum are keyed by their other two vertices and matched in a small
// open-addressing table (per thread, sized for the largest star so far, its slots stamped with the
// vertex that filled them so it is never cleared), so the two sides of an interior face meet in one
// probe sequence. This replaces a sort of the star's ~20 faces by a hash and one or two probes each,
// in a table that stays in L1; every (tet, face) slot is written by exactly one task, so no locks.
std::vector<std::array<int32_t, 4>> build_tet_neighbors(const TetMesh& mesh, const CompressedRows& vertex_tets) {
    std::vector<std::array<int32_t, 4>> neighbors(mesh.tets.size());
    std::atomic<int64_t> overfull_face{std::numeric_limits<int64_t>::max()};
    struct FaceSlot {
        uint64_t key;    // the face's two larger vertices
        int32_t owner;   // the vertex whose star filled the slot, or -1
        int32_t tet;     // the first side
        int32_t face;
        int32_t sides;   // how many tets named the face
    };
    struct FaceTable {
        std::vector<FaceSlot> slots;
        std::vector<uint32_t> used;  // slots filled for the current vertex, in order
        int shift = 64;
    };
    tbb::enumerable_thread_specific<FaceTable> tables;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.vertex_count(), 256), [&](const tbb::blocked_range<size_t>& r) {
        FaceTable& table = tables.local();
        for (size_t v = r.begin(); v != r.end(); ++v) {
            const auto self = static_cast<int32_t>(v);
            const auto star = vertex_tets.row(v);
            // At most three faces per tet of the star; at most half the slots filled.
            const size_t capacity = std::bit_ceil(std::max<size_t>(8, 6 * star.size()));
            if (table.slots.size() < capacity) {
                table.slots.assign(capacity, FaceSlot{0, -1, 0, 0, 0});
                table.shift = 64 - std::countr_zero(capacity);
            }
            const uint64_t mask = table.slots.size() - 1;
            table.used.clear();
            for (int32_t t : star) {
                const Tet& tet = mesh.tets[t];
                // Bit k: tet[k] > v. v is the minimum of face f (opposite corner f, f not v's corner)
                // when the two corners other than f and v's are both above it.
                int above = 0, own = 0;
                for (int k = 0; k < 4; ++k) {
                    above |= (tet[k] > self ? 1 : 0) << k;
                    own |= (tet[k] == self ? 1 : 0) << k;
                }
                for (int f = 0; f < 4; ++f) {
                    if (((above | own | (1 << f)) != 0xf) || (own >> f & 1)) continue;
                    int32_t others[2], n = 0;
                    for (int k : kTetFaces[f])
                        if (!(own >> k & 1) && n < 2) others[n++] = tet[k];
                    if (n != 2) continue;  // a degenerate tet naming v twice
                    const auto lo = static_cast<uint32_t>(std::min(others[0], others[1]));
                    const auto hi = static_cast<uint32_t>(std::max(others[0], others[1]));
                    const uint64_t key = (uint64_t{lo} << 32) | hi;
                    uint64_t i = (key * 0x9e3779b97f4a7c15ull) >> table.shift;
                    while (table.slots[i].owner == self && table.slots[i].key != key) i = (i + 1) & mask;
                    FaceSlot& slot = table.slots[i];
                    if (slot.owner != self) {
                        slot = {key, self, t, f, 1};
                        table.used.push_back(static_cast<uint32_t>(i));
                    } else if (++slot.sides == 2) {
                        neighbors[slot.tet][slot.face] = t;
                        neighbors[t][f] = slot.tet;
                    } else {
                        lower_to(overfull_face, slot.tet);
                    }
                }
            }
            for (uint32_t i : table.used)
                if (table.slots[i].sides == 1) neighbors[table.slots[i].tet][table.slots[i].face] = -1;
        }
    });
    if (overfull_face.load() != std::numeric_limits<int64_t>::max())
        throw InvalidMeshError("a face of tet " + std::to_string(overfull_face.load()) +
                               " is shared by more than two tets");
    return neighbors;
}

// Edges and vertex one-rings. Each vertex gathers its neighbours from its star, deduplicated through a
// per-thread mark array indexed by vertex (one test per candidate instead of sorting the ~80
// candidates of a star), and sorts the ~14 left. The rows go to a scratch buffer at three times the
// star's offset (a bound on the ring), so every vertex works alone; one parallel copy then compacts
// them into vertex_vertices and writes each vertex's larger neighbours, in vertex order, as the sorted
// edge list.
void build_edges_and_one_rings(const TetMesh& mesh, TetConnectivity& c) {
    const size_t n = mesh.vertex_count();
    const CompressedRows& vertex_tets = c.vertex_tets;
    std::vector<int32_t> scratch(3 * vertex_tets.indices.size());
    std::vector<int32_t> ring_counts(n), upper_counts(n);
    tbb::enumerable_thread_specific<std::vector<int32_t>> marks([n] { return std::vector<int32_t>(n, -1); });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<int32_t>& mark = marks.local();
        for (size_t v = r.begin(); v != r.end(); ++v) {
            const auto self = static_cast<int32_t>(v);
            mark[v] = self;  // v is not its own neighbour
            int32_t* begin = scratch.data() + 3 * static_cast<size_t>(vertex_tets.offsets[v]);
            int32_t* out = begin;
            for (int32_t t : vertex_tets.row(v))
                for (int32_t u : mesh.tets[t])
                    if (mark[u] != self) {
                        mark[u] = self;
                        *out++ = u;
                    }
            std::sort(begin, out);
            ring_counts[v] = static_cast<int32_t>(out - begin);
            upper_counts[v] = static_cast<int32_t>(out - std::upper_bound(begin, out, self));
        }
    });
    CompressedRows& rows = c.vertex_vertices;
    rows.offsets = offsets_from_counts(ring_counts);
    rows.indices.resize(static_cast<size_t>(rows.offsets.back()));
    const std::vector<int32_t> edge_offsets = offsets_from_counts(upper_counts);
    c.edges.resize(static_cast<size_t>(edge_offsets.back()));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
            const int32_t* ring = scratch.data() + 3 * static_cast<size_t>(vertex_tets.offsets[v]);
            std::copy_n(ring, ring_counts[v], rows.indices.data() + rows.offsets[v]);
            const int32_t* upper = ring + (ring_counts[v] - upper_counts[v]);
            for (int32_t k = 0; k < upper_counts[v]; ++k)
                c.edges[static_cast<size_t>(edge_offsets[v] + k)] = {static_cast<int32_t>(v), upper[k]};
        }
    });
}

std::vector<BoundaryFace> build_boundary_faces(const TetMesh& mesh,
                                               const std::vector<std::array<int32_t, 4>>& neighbors) {
    std::vector<int32_t> counts(mesh.tets.size());
    tbb::parallel_for(size_t{0}, mesh.tets.size(), [&](size_t t) {
        counts[t] = static_cast<int32_t>(std::count(neighbors[t].begin(), neighbors[t].end(), -1));
    });
    const std::vector<int32_t> offsets = offsets_from_counts(counts);
    std::vector<BoundaryFace> faces(static_cast<size_t>(offsets.back()));
    tbb::parallel_for(size_t{0}, mesh.tets.size(), [&](size_t t) {
        int32_t out = offsets[t];
        for (int f = 0; f < 4; ++f)
            if (neighbors[t][f] < 0) {
                const Tet& tet = mesh.tets[t];
                faces[static_cast<size_t>(out++)] = {{tet[kTetFaces[f][0]], tet[kTetFaces[f][1]], tet[kTetFaces[f][2]]},
                                                     static_cast<int32_t>(t), f};
            }
    });
    return faces;
}

// Face-connected components by a concurrent union-find (Anderson and Woll's, without ranks): a union
// links the larger of two roots below the smaller with a compare-and-swap and starts again when
// another thread moved that root first, so each class ends rooted at its lowest tet whatever the
// interleaving; finds halve their paths with plain stores (a benign race: a tet that is not a root
// never becomes one again, and any value stored is one of its ancestors). Labels
// follow the roots in tet order, as DisjointSets::label_classes numbers them.
void label_components(const std::vector<std::array<int32_t, 4>>& neighbors, TetConnectivity& out) {
    const size_t n = neighbors.size();
    std::vector<std::atomic<int32_t>> parent(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 8192), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t t = r.begin(); t != r.end(); ++t) parent[t].store(static_cast<int32_t>(t), std::memory_order_relaxed);
    });
    const auto find = [&](int32_t x) {
        int32_t p = parent[x].load(std::memory_order_relaxed);
        while (p != x) {
            const int32_t g = parent[p].load(std::memory_order_relaxed);
            if (g != p) parent[x].store(g, std::memory_order_relaxed);
            x = g;
            p = parent[x].load(std::memory_order_relaxed);
        }
        return x;
    };
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t t = r.begin(); t != r.end(); ++t)
            for (int32_t o : neighbors[t]) {
                if (o <= static_cast<int32_t>(t)) continue;
                int32_t a = static_cast<int32_t>(t), b = o;
                for (;;) {
                    a = find(a), b = find(b);
                    if (a == b) break;
                    if (a > b) std::swap(a, b);  // b, the larger root, goes below a
                    int32_t expected = b;
                    if (parent[b].compare_exchange_strong(expected, a, std::memory_order_relaxed)) break;
                }
            }
    });
    // Roots in tet order get 0, 1, ...; every other tet takes its root's label (roots come first).
    out.tet_component.assign(n, -1);
    int32_t count = 0;
    for (size_t t = 0; t < n; ++t)
        if (parent[t].load(std::memory_order_relaxed) == static_cast<int32_t>(t)) out.tet_component[t] = count++;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 8192), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t t = r.begin(); t != r.end(); ++t)
            if (out.tet_component[t] < 0) out.tet_component[t] = out.tet_component[static_cast<size_t>(find(static_cast<int32_t>(t)))];
    });
    out.component_count = count;
}

}  // namespace

template <size_t N>
CompressedRows vertex_elements(const std::vector<std::array<int32_t, N>>& elements, size_t vertex_count) {
    CompressedRows rows;
    sort_elements_by_vertex(elements, vertex_count, rows);
    return rows;
}
template CompressedRows vertex_elements(const std::vector<std::array<int32_t, 3>>&, size_t);
template CompressedRows vertex_elements(const std::vector<std::array<int32_t, 4>>&, size_t);

std::vector<std::array<int32_t, 4>> build_face_neighbors(const TetMesh& mesh) {
    return build_tet_neighbors(mesh, checked_vertex_tets(mesh));
}

TetConnectivity build_connectivity(const TetMesh& mesh, ConnectivityBuildTimes* times) {
    ConnectivityBuildTimes local;
    ConnectivityBuildTimes& t = times ? *times : local;
    TetConnectivity c;
    auto start = Clock::now();
    const auto lap = [&](double& slot) {
        slot = milliseconds_since(start);
        start = Clock::now();
    };
    c.vertex_tets = checked_vertex_tets(mesh);
    lap(t.vertex_tets);
    c.tet_neighbors = build_tet_neighbors(mesh, c.vertex_tets);
    lap(t.tet_neighbors);
    build_edges_and_one_rings(mesh, c);
    lap(t.one_rings);
    c.boundary_faces = build_boundary_faces(mesh, c.tet_neighbors);
    c.is_boundary_vertex.assign(mesh.vertex_count(), 0);
    for (const BoundaryFace& f : c.boundary_faces)
        for (int32_t v : f.vertices) c.is_boundary_vertex[static_cast<size_t>(v)] = 1;
    for (size_t v = 0; v < c.is_boundary_vertex.size(); ++v)
        if (c.is_boundary_vertex[v]) c.boundary_vertices.push_back(static_cast<int32_t>(v));
    lap(t.boundary);
    label_components(c.tet_neighbors, c);
    lap(t.components);
    return c;
}

}  // namespace waxwork
