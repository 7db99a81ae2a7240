// The vertex selection of the independent-set hierarchy (Li et al. 2013, TransCut, Sec. 4.1): which
// vertices of a level's graph G^l are retained in P^{l+1}, and the edges E^{l+1} among them.
//
// Reading of the paper followed here:
//  - Priorities. Each vertex gets a 32-bit code h_i: a hash of (i, seed) in the high bits and i itself
//    in the low bits (as many bits as the largest index needs), so codes are unique and the order has
//    no spatial pattern. The hash is a few rounds of TEA (the paper cites Tzeng and Wei's
//    cryptographic-hash noise, [30]); any well-mixing keyed hash serves.
//  - Rounds (Luby style). With Q the undecided candidates and Gamma(i) = N(i) cap Q, a vertex whose code
//    is SMALLER than the codes of all of Gamma(i) is retained (added to P^{l+1}); it and Gamma(i) leave
//    Q, so Gamma(i) is dropped. Repeat until Q is empty. Two vertices retained in one round are never
//    adjacent (one of them would have the larger code), so every round is a race-free parallel pass.
//    Every dropped vertex has a retained neighbour: the one that removed it.
//  - Enhancement. For each fine edge (i, j) whose ends are both dropped, if N(i) cap N(j) cap P^{l+1}
//    is empty the edge "would not be reflected" at level l+1: mark i and j. The marked vertices form a
//    new Q and the same rounds add some of them to P^{l+1} (retained vertices may now be adjacent).
//    Repeat until nothing is marked. Each pass retains at least the smallest-coded marked vertex, so
//    this terminates. Afterwards every dropped-dropped edge has a common retained neighbour k; hence
//    two retained vertices a, b joined by a fine path a-i-j-b through dropped i, j are within coarse
//    distance 2 (a-k-b), which is what keeps 3-ring neighbours connected (Fig. 3: i_1 and i_3).
//  - Coarse edges. E^{l+1} joins two retained vertices when they share a dropped fine neighbour
//    (2-ring through a dropped vertex) or are adjacent in G^l.
#pragma once

#include "multires/carried_rows.h"
#include "tetops/connectivity.h"

#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

// Per-vertex priorities h_i for a graph of vertex_count vertices (unique, deterministic per seed).
std::vector<uint32_t> independent_set_codes(size_t vertex_count, uint32_t seed);

// Runs the independent-set rounds on the candidates (in_queue[v] != 0), which are cleared as they are
// decided; retained[v] is set to 1 for every vertex selected. Neighbours outside the queue are ignored
// (Gamma(i) = N(i) cap Q). Returns the number of rounds.
int run_independent_set_rounds(const CompressedRows& graph, std::span<const uint32_t> codes,
                               std::vector<uint8_t>& in_queue, std::vector<uint8_t>& retained);

// The enhancement test: 1 for each dropped vertex with a dropped neighbour with which it shares no
// retained neighbour (graph rows must be sorted ascending).
std::vector<uint8_t> mark_lost_connections(const CompressedRows& graph, std::span<const uint8_t> retained);

struct VertexSelection {
    std::vector<uint8_t> retained;    // per fine vertex: 1 when it is in P^{l+1}
    int independent_set_rounds = 0;   // rounds of the first independent set
    int enhancement_passes = 0;       // marking passes that found something
    int64_t enhancement_vertices = 0; // vertices added by the enhancement
};

// Independent set then (if enhance) the enhancement loop, on a symmetric graph with sorted rows and no
// self loops. Deterministic for a given seed, whatever the thread count.
VertexSelection select_coarse_vertices(const CompressedRows& graph, uint32_t seed, bool enhance = true);

// The same selection updated after an edit changed the graph in a few places (beyond the paper, for
// the rebuild after a cut). previous_retained: the previous selection carried to this graph's vertices
// (0 for new ones); changed: every vertex whose row differs from the graph the previous selection was
// made on, and every new vertex. Those and their dropped neighbours are decided again by the rounds,
// with the vertices that stay retained counting as already selected, and the enhancement runs on the
// fine edges near them. Everything else keeps its previous state, so the cost follows the edit, not
// the graph. The result has the properties of select_coarse_vertices' (every dropped vertex has a
// retained neighbour, no connection is lost, the vertices the rounds add are independent) when the
// previous selection had them on its graph; it is not the selection a fresh build would make.
// Throws InvalidArgumentError when previous_retained's size is not the graph's or a changed vertex is
// out of range.
VertexSelection update_coarse_vertices(const CompressedRows& graph, uint32_t seed, bool enhance,
                                       std::span<const uint8_t> previous_retained, std::span<const int32_t> changed);

// Fine-to-coarse index (-1 for dropped vertices); coarse vertices keep their fine order.
std::vector<int32_t> coarse_vertex_index(std::span<const uint8_t> retained);

// The coarse graph G^{l+1} (rows sorted, no self loops): retained vertices joined when adjacent in G^l
// or both adjacent to one dropped vertex. Computed per coarse row (the union of its retained
// neighbours and of the retained neighbours of its dropped neighbours), which is the paper's
// sort-and-deduplicate of per-dropped-vertex pairs grouped by row, and runs in parallel without atomics.
CompressedRows build_coarse_graph(const CompressedRows& graph, std::span<const uint8_t> retained,
                                  std::span<const int32_t> coarse_index);

// The same from precomputed links: per fine vertex v, links[link_offsets[v] .. link_offsets[v+1]) are
// the coarse vertices v is represented by (itself when retained, its retained neighbours when dropped):
// the columns of Eq. 16's interpolation operator, which the hierarchy builds anyway. Walking a dropped
// neighbour's links (a few entries) instead of its whole graph row (its degree, which grows on coarse
// levels) is what makes this the cheap way.
// With `carried` (a rebuild), its kept rows are copied from `previous` (the previous coarse graph),
// renumbered (carried_rows.h), instead of computed.
CompressedRows build_coarse_graph(const CompressedRows& graph, std::span<const int32_t> coarse_index,
                                  std::span<const int32_t> link_offsets, std::span<const int32_t> links,
                                  const CarriedRows* carried = nullptr, const CompressedRows* previous = nullptr);

}  // namespace waxwork
