#include "multires/gpu_independent_set.h"

#include "base/error.h"

#include <algorithm>
#include <bit>
#include <string>

namespace waxwork {
namespace {

constexpr GLuint kGroupSize = 64;
constexpr GLuint kMaxGroups = 4096;

// Shared declarations. Vertex states: queue[v] != 0 while v is undecided (a candidate of the current
// rounds); retained[v] = 1 once selected into P^{l+1}; selected[v] = the round that selected it;
// counters[0] = vertices still queued after a round, counters[1] = vertices marked by the enhancement.
constexpr const char* kPrelude = R"(#version 430
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Offsets { int offsets[]; };
layout(std430, binding = 1) readonly buffer Indices { int indices[]; };
layout(std430, binding = 2) buffer Codes { uint codes[]; };
layout(std430, binding = 3) buffer Queue { uint queue[]; };
layout(std430, binding = 4) buffer Retained { uint retained[]; };
layout(std430, binding = 5) buffer Selected { uint selected[]; };
layout(std430, binding = 6) buffer Counters { uint counters[]; };
layout(std430, binding = 7) buffer Candidates { uint candidates[]; };
uniform uint n;
uniform uint round_stamp;
#define FOR_EACH_VERTEX(v) for (uint v = gl_GlobalInvocationID.x; v < n; v += gl_NumWorkGroups.x * 64u)
)";

// independent_set_codes: TEA of (index, seed) in the high bits, the index in the low bits.
constexpr const char* kCodes = R"(
uniform uint seed;
uniform uint index_mask;
uint tea_hash(uint v0, uint v1) {
    const uint key0 = 0xa341316cu, key1 = 0xc8013ea4u, key2 = 0xad90777du, key3 = 0x7e95761eu;
    uint sum = 0u;
    for (int r = 0; r < 8; ++r) {
        sum += 0x9e3779b9u;
        v0 += ((v1 << 4) + key0) ^ (v1 + sum) ^ ((v1 >> 5) + key1);
        v1 += ((v0 << 4) + key2) ^ (v0 + sum) ^ ((v0 >> 5) + key3);
    }
    return v0 ^ v1;
}
void main() {
    FOR_EACH_VERTEX(v) codes[v] = (tea_hash(v, seed) & ~index_mask) | v;
}
)";

// Pass 1 of a round (reads the queue only): a queued vertex whose code is below every queued
// neighbour's is selected.
constexpr const char* kSelect = R"(
void main() {
    FOR_EACH_VERTEX(v) {
        if (queue[v] == 0u) continue;
        bool minimum = true;
        for (int k = offsets[v]; k < offsets[v + 1u] && minimum; ++k) {
            uint u = uint(indices[k]);
            if (queue[u] != 0u && codes[u] < codes[v]) minimum = false;
        }
        if (minimum) selected[v] = round_stamp;
    }
}
)";

// Pass 2 (reads this round's selection only): selected vertices are retained, queued vertices next to
// one are dropped; each vertex writes only its own state. Counts what stays queued.
constexpr const char* kDecide = R"(
void main() {
    FOR_EACH_VERTEX(v) {
        if (queue[v] == 0u) continue;
        if (selected[v] == round_stamp) {
            retained[v] = 1u;
            queue[v] = 0u;
            continue;
        }
        bool dropped = false;
        for (int k = offsets[v]; k < offsets[v + 1u] && !dropped; ++k)
            if (selected[uint(indices[k])] == round_stamp) dropped = true;
        if (dropped)
            queue[v] = 0u;
        else
            atomicAdd(counters[0], 1u);
    }
}
)";

// The enhancement test on the candidates (mark_lost_connections, then still_lost): a dropped vertex
// is marked when some dropped neighbour shares no retained neighbour with it. Marked vertices become
// the next rounds' queue and the next pass's candidates. Rows are sorted: membership by bisection.
constexpr const char* kMark = R"(
bool row_contains(uint row, int value) {
    int lo = offsets[row], hi = offsets[row + 1u];
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (indices[mid] < value) lo = mid + 1; else hi = mid;
    }
    return lo < offsets[row + 1u] && indices[lo] == value;
}
void main() {
    FOR_EACH_VERTEX(i) {
        if (candidates[i] == 0u) continue;
        bool lost = false;
        if (retained[i] == 0u) {
            for (int a = offsets[i]; a < offsets[i + 1u] && !lost; ++a) {
                uint j = uint(indices[a]);
                if (retained[j] != 0u) continue;
                bool meet = false;  // a retained neighbour common to i and j
                for (int b = offsets[i]; b < offsets[i + 1u] && !meet; ++b) {
                    int k = indices[b];
                    if (retained[uint(k)] != 0u && row_contains(j, k)) meet = true;
                }
                lost = !meet;
            }
        }
        candidates[i] = lost ? 1u : 0u;
        queue[i] = lost ? 1u : 0u;
        if (lost) atomicAdd(counters[1], 1u);
    }
}
)";

std::string source(const char* body) { return std::string(kPrelude) + body; }

template <typename T>
GpuBuffer filled(const GlApi& gl, size_t count, T value) {
    const std::vector<T> data(std::max<size_t>(count, 1), value);
    return GpuBuffer::from<T>(gl, data);
}

}  // namespace

GpuVertexSelector::GpuVertexSelector(const GlApi& gl) : gl_(&gl) {
    require_compute_support(gl);
    codes_ = ComputeProgram(gl, "independent_set_codes", source(kCodes));
    select_ = ComputeProgram(gl, "independent_set_select", source(kSelect));
    decide_ = ComputeProgram(gl, "independent_set_decide", source(kDecide));
    mark_ = ComputeProgram(gl, "independent_set_mark", source(kMark));
    counters_ = filled<uint32_t>(gl, 2, 0);
    check_gpu_error(gl, "compiling the independent-set kernels");
}

void GpuVertexSelector::launch(const ComputeProgram& program, size_t n) {
    program.use();
    offsets_.bind(0);
    indices_.bind(1);
    codes_buffer_.bind(2);
    queue_.bind(3);
    retained_.bind(4);
    selected_.bind(5);
    counters_.bind(6);
    candidates_.bind(7);
    gl_->Uniform1ui(program.uniform("n"), static_cast<GLuint>(n));
    program.dispatch(static_cast<GLuint>(std::clamp<size_t>((n + kGroupSize - 1) / kGroupSize, 1, kMaxGroups)));
}

void GpuVertexSelector::reset_counters() {
    const uint32_t zeros[2] = {0, 0};
    counters_.write(0, sizeof zeros, zeros);
}

uint32_t GpuVertexSelector::read_counter(int which) {
    uint32_t value = 0;
    counters_.read(static_cast<size_t>(which) * sizeof(uint32_t), sizeof value, &value);
    return value;
}

int GpuVertexSelector::run_rounds(size_t n, int& round_stamp) {
    int rounds = 0;
    for (;;) {
        ++rounds;
        ++round_stamp;
        reset_counters();
        select_.use();
        gl_->Uniform1ui(select_.uniform("round_stamp"), static_cast<GLuint>(round_stamp));
        launch(select_, n);
        decide_.use();
        gl_->Uniform1ui(decide_.uniform("round_stamp"), static_cast<GLuint>(round_stamp));
        launch(decide_, n);
        if (read_counter(0) == 0) return rounds;
        if (rounds > static_cast<int>(n) + 1)  // each round retains the smallest queued code: cannot happen
            throw AlgorithmError("GPU independent set: no progress after " + std::to_string(rounds) + " rounds");
    }
}

std::vector<uint32_t> GpuVertexSelector::codes(size_t vertex_count, uint32_t seed) {
    if (vertex_count > static_cast<size_t>(INT32_MAX))
        throw InvalidArgumentError("GPU independent set: too many vertices for 32-bit codes");
    const int index_bits = vertex_count <= 1 ? 1 : std::bit_width(static_cast<uint32_t>(vertex_count - 1));
    const uint32_t index_mask = index_bits >= 32 ? 0xffffffffu : ((1u << index_bits) - 1u);
    codes_buffer_ = filled<uint32_t>(*gl_, vertex_count, 0);
    if (!offsets_.id()) offsets_ = filled<int32_t>(*gl_, 1, 0);
    for (GpuBuffer* b : {&indices_, &queue_, &retained_, &selected_, &candidates_})
        if (!b->id()) *b = filled<uint32_t>(*gl_, 1, 0);
    codes_.use();
    gl_->Uniform1ui(codes_.uniform("seed"), seed);
    gl_->Uniform1ui(codes_.uniform("index_mask"), index_mask);
    if (vertex_count > 0) launch(codes_, vertex_count);
    std::vector<uint32_t> out = codes_buffer_.download<uint32_t>();
    out.resize(vertex_count);
    return out;
}

VertexSelection GpuVertexSelector::select(const CompressedRows& graph, uint32_t seed, bool enhance) {
    const size_t n = graph.row_count();
    VertexSelection selection;
    if (n == 0) return selection;
    offsets_ = GpuBuffer::from<int32_t>(*gl_, graph.offsets);
    indices_ = graph.indices.empty() ? filled<int32_t>(*gl_, 1, 0) : GpuBuffer::from<int32_t>(*gl_, graph.indices);
    queue_ = filled<uint32_t>(*gl_, n, 1);
    retained_ = filled<uint32_t>(*gl_, n, 0);
    selected_ = filled<uint32_t>(*gl_, n, 0);
    candidates_ = filled<uint32_t>(*gl_, n, 1);
    codes(n, seed);  // into codes_buffer_, where the rounds read them

    int round_stamp = 0;
    selection.independent_set_rounds = run_rounds(n, round_stamp);
    auto retained_count = [&] {
        const std::vector<uint32_t> r = retained_.download<uint32_t>();
        int64_t count = 0;
        for (size_t v = 0; v < n; ++v) count += r[v];
        return count;
    };
    if (enhance) {
        const int64_t before = retained_count();
        for (;;) {
            reset_counters();
            launch(mark_, n);
            if (read_counter(1) == 0) break;
            ++selection.enhancement_passes;
            run_rounds(n, round_stamp);
        }
        selection.enhancement_vertices = retained_count() - before;
    }
    check_gpu_error(*gl_, "selecting the coarse vertices");
    const std::vector<uint32_t> retained = retained_.download<uint32_t>();
    selection.retained.assign(retained.begin(), retained.begin() + static_cast<std::ptrdiff_t>(n));
    return selection;
}

}  // namespace waxwork
