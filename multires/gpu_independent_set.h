// The hierarchy's vertex selection (independent_set.h: Luby-style rounds on the 32-bit hash|index
// codes, then the enhancement loop) as OpenGL 4.3 compute shaders. The paper designed this step for
// the GPU (Sec. 4.1): every round is two race-free passes over the vertices, one reading only the
// queue and one reading only the round's selection.
//
// The result is identical to select_coarse_vertices for the same graph and seed (same retained set,
// rounds, passes and counts): the codes are the same integer arithmetic, and each pass decides what
// the CPU pass decides. One difference in how: the CPU clears each round's selection after the round,
// the device stamps selections with the round number instead, so no clearing pass is needed.
#pragma once

#include "gl/gpu_compute.h"
#include "multires/independent_set.h"

#include <cstdint>
#include <vector>

namespace waxwork {

class GpuVertexSelector {
public:
    // Compiles the kernels. Throws GpuError when the driver cannot run them. The context of `gl` must
    // stay current while the selector lives.
    explicit GpuVertexSelector(const GlApi& gl);

    // select_coarse_vertices on the device (same preconditions: symmetric graph, sorted rows, no self
    // loops). Uploads the graph, reads back the retained flags.
    VertexSelection select(const CompressedRows& graph, uint32_t seed, bool enhance = true);
    // independent_set_codes on the device (for tests: the priorities must be the CPU's bit for bit).
    std::vector<uint32_t> codes(size_t vertex_count, uint32_t seed);

private:
    // Runs rounds until the queue is empty; returns their number.
    int run_rounds(size_t n, int& round_stamp);
    void launch(const ComputeProgram& program, size_t n);
    uint32_t read_counter(int which);
    void reset_counters();

    const GlApi* gl_;
    ComputeProgram codes_, select_, decide_, mark_;
    GpuBuffer offsets_, indices_, codes_buffer_, queue_, retained_, selected_, counters_, candidates_;
};

}  // namespace waxwork
