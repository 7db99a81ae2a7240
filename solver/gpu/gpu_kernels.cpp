#include "solver/gpu/gpu_kernels.h"

#include <algorithm>
#include <string>

namespace waxwork {
namespace {

constexpr GLuint kGroupSize = 256;
// Reductions use at most this many workgroups (grid-stride loops beyond): enough to fill a large GPU
// (512 x 256 = 128K threads), few enough that the partials read back in one small transfer.
constexpr GLuint kMaxGroups = 512;
constexpr size_t kMaxSums = 6;

GLuint groups_for(size_t count) {
    const size_t g = (count + kGroupSize - 1) / kGroupSize;
    return static_cast<GLuint>(std::clamp<size_t>(g, 1, kMaxGroups));
}

// Shared by every kernel: workgroup size, the grid-stride loop bound and the output of NSUMS
// per-thread sums (binding 5, one slot per invocation; kFold adds them up).
//
// Why no shared-memory tree: llvmpipe runs each barrier() as a switch through all 256 invocations of
// a workgroup (coroutines). On spot at 50K tets (13K vertices) a three-channel dot took 4.4 ms with a
// binary tree (8 barriers), 2.3 ms with a 16 x 16 fold (2 barriers) and 0.5 ms with no barrier at all,
// as here (bench/gpu_solver_bench.cpp, BM_GpuDot; the matrix product likewise). On a GPU the
// price is a few MB of writes at most (512 x 256 x 6 floats) and one more small dispatch.
const char* kPrelude = R"(#version 430
layout(local_size_x = 256) in;
layout(std430, binding = 5) writeonly buffer ThreadSums { float thread_sums[]; };
uniform uint n;
#ifdef NSUMS
void reduce_partials(float v[NSUMS]) {
    for (int c = 0; c < NSUMS; ++c) thread_sums[gl_GlobalInvocationID.x * uint(NSUMS) + uint(c)] = v[c];
}
#endif
#define STRIDE (gl_NumWorkGroups.x * 256u)
)";

// The sparse row product of one slot, per format: ACC slot_product(uint t) reads the vector xin
// (binding 3), int slot_row(uint t) is the row the slot computes (-1: padding).
const char* kMatrixCommon = R"(
layout(std430, binding = 0) readonly buffer Starts { int starts[]; };
layout(std430, binding = 1) readonly buffer Columns { int columns[]; };
layout(std430, binding = 2) readonly buffer Values { float values[]; };
layout(std430, binding = 3) readonly buffer XIn { float xin[]; };
ACC entry_product(int k) {
    uint j = 3u * uint(columns[k]);
    uint e = 3u * uint(k);
    return ACC(values[e], values[e + 1u], values[e + 2u]) * ACC(xin[j], xin[j + 1u], xin[j + 2u]);
}
// s - a_ik x_k, rounded twice (product, then difference; `precise`: no fused multiply-add), as the
// CPU's float V-cycle computes it.
ACC subtract_entry(ACC s, int k) {
    uint j = 3u * uint(columns[k]);
    uint e = 3u * uint(k);
    precise ACC product = ACC(values[e], values[e + 1u], values[e + 2u]) * ACC(xin[j], xin[j + 1u], xin[j + 2u]);
    precise ACC difference = s - product;
    return difference;
}
)";

const char* kCsr = R"(
int slot_row(uint t) { return int(t); }
ACC slot_product(uint t) {
    ACC s = ACC(0);
    for (int k = starts[t]; k < starts[t + 1u]; ++k) s += entry_product(k);
    return s;
}
ACC slot_residual(uint t, ACC s) {
    for (int k = starts[t]; k < starts[t + 1u]; ++k) s = subtract_entry(s, k);
    return s;
}
)";

const char* kSliced = R"(
layout(std430, binding = 9) readonly buffer SlotRows { int slot_rows[]; };
uniform uint slice_height;
int slot_row(uint t) { return slot_rows[t]; }
ACC slot_product(uint t) {
    uint slice = t / slice_height;
    int lane = int(t - slice * slice_height);
    int begin = starts[slice];
    int width = (starts[slice + 1u] - begin) / int(slice_height);
    ACC s = ACC(0);
    for (int k = 0; k < width; ++k) s += entry_product(begin + k * int(slice_height) + lane);
    return s;
}
// s - (each stored entry's product, in the row's order): the CPU's `sum = b; sum -= a_ij x_j`. A
// padding entry (value 0) subtracts 0 and leaves s as it is.
ACC slot_residual(uint t, ACC s) {
    uint slice = t / slice_height;
    int lane = int(t - slice * slice_height);
    int begin = starts[slice];
    int width = (starts[slice + 1u] - begin) / int(slice_height);
    for (int k = 0; k < width; ++k) s = subtract_entry(s, begin + k * int(slice_height) + lane);
    return s;
}
)";

// q = M p, sums p . q. n = slots.
const char* kMultiplyDot = R"(
layout(std430, binding = 4) writeonly buffer QOut { float q[]; };
void main() {
    float acc[3] = float[3](0.0, 0.0, 0.0);
    for (uint t = gl_GlobalInvocationID.x; t < n; t += STRIDE) {
        int row = slot_row(t);
        if (row < 0) continue;
        vec3 s = slot_product(t);
        uint i = 3u * uint(row);
        q[i] = s.x; q[i + 1u] = s.y; q[i + 2u] = s.z;
        acc[0] += xin[i] * s.x; acc[1] += xin[i + 1u] * s.y; acc[2] += xin[i + 2u] * s.z;
    }
    reduce_partials(acc);
}
)";

// r = b - M x in double, z = D^-1 r, sums r . z (of the stored float values). n = slots.
const char* kResidual = R"(
layout(std430, binding = 4) writeonly buffer ROut { float r[]; };
layout(std430, binding = 6) readonly buffer B { float b[]; };
layout(std430, binding = 7) writeonly buffer ZOut { float z[]; };
layout(std430, binding = 8) readonly buffer InvDiag { float inv_diag[]; };
uniform uvec3 mask;
void main() {
    float acc[3] = float[3](0.0, 0.0, 0.0);
    for (uint t = gl_GlobalInvocationID.x; t < n; t += STRIDE) {
        int row = slot_row(t);
        if (row < 0) continue;
        dvec3 s = slot_product(t);
        uint i = 3u * uint(row);
        for (uint c = 0u; c < 3u; ++c) {
            if (mask[c] == 0u) continue;
            float rc = float(double(b[i + c]) - s[c]);
            float zc = float(double(rc) * double(inv_diag[i + c]));
            r[i + c] = rc;
            z[i + c] = zc;
            acc[c] += rc * zc;
        }
    }
    reduce_partials(acc);
}
)";

// sum u v (w) per channel. n = rows.
const char* kDot = R"(
layout(std430, binding = 0) readonly buffer U { float u[]; };
layout(std430, binding = 1) readonly buffer V { float v[]; };
layout(std430, binding = 2) readonly buffer W { float w[]; };
uniform uint weighted;
void main() {
    float acc[3] = float[3](0.0, 0.0, 0.0);
    for (uint i = gl_GlobalInvocationID.x; i < n; i += STRIDE)
        for (uint c = 0u; c < 3u; ++c) {
            uint j = 3u * i + c;
            acc[c] += weighted != 0u ? u[j] * v[j] * w[j] : u[j] * v[j];
        }
    reduce_partials(acc);
}
)";

// y = a x + b y. n = rows.
const char* kAxpby = R"(
layout(std430, binding = 0) readonly buffer X { float x[]; };
layout(std430, binding = 1) buffer Y { float y[]; };
uniform vec3 a;
uniform vec3 b;
void main() {
    for (uint i = gl_GlobalInvocationID.x; i < n; i += STRIDE)
        for (uint c = 0u; c < 3u; ++c) {
            uint j = 3u * i + c;
            y[j] = a[c] * x[j] + b[c] * y[j];
        }
}
)";

// diag and its inverse from the stored diagonal positions. n = rows.
const char* kExtractDiagonal = R"(
layout(std430, binding = 0) readonly buffer Diagonal { int diagonal[]; };
layout(std430, binding = 2) readonly buffer Values { float values[]; };
layout(std430, binding = 3) writeonly buffer Diag { float diag[]; };
layout(std430, binding = 4) writeonly buffer InvDiag { float inv_diag[]; };
void main() {
    for (uint i = gl_GlobalInvocationID.x; i < n; i += STRIDE)
        for (uint c = 0u; c < 3u; ++c) {
            float d = values[3u * uint(diagonal[i]) + c];
            diag[3u * i + c] = d;
            // A zero or non-finite diagonal (possible on coarse multires levels) preconditions with 1;
            // the SPD level-0 matrix always has positive diagonals.
            bool usable = d != 0.0 && !isinf(d) && !isnan(d);
            inv_diag[3u * i + c] = usable ? float(1.0lf / double(d)) : 1.0;
        }
}
)";

// x += alpha p, r -= alpha q, z = D^-1 r; sums r . z and x . D x per channel. n = rows.
const char* kCgUpdate = R"(
layout(std430, binding = 0) readonly buffer P { float p[]; };
layout(std430, binding = 1) readonly buffer Q { float q[]; };
layout(std430, binding = 2) readonly buffer Diag { float diag[]; };
layout(std430, binding = 3) readonly buffer InvDiag { float inv_diag[]; };
layout(std430, binding = 4) buffer X { float x[]; };
layout(std430, binding = 6) buffer R { float r[]; };
layout(std430, binding = 7) writeonly buffer Z { float z[]; };
uniform vec3 alpha;
void main() {
    float acc[6] = float[6](0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (uint i = gl_GlobalInvocationID.x; i < n; i += STRIDE)
        for (uint c = 0u; c < 3u; ++c) {
            uint j = 3u * i + c;
            float xj = x[j] + alpha[c] * p[j];
            float rj = r[j] - alpha[c] * q[j];
            float zj = inv_diag[j] * rj;
            x[j] = xj; r[j] = rj; z[j] = zj;
            acc[2u * c] += rj * zj;
            acc[2u * c + 1u] += diag[j] * xj * xj;
        }
    reduce_partials(acc);
}
)";

// values[slot] = source, 3 channels. n = count.
const char* kScatter = R"(
layout(std430, binding = 0) readonly buffer Slots { int slots[]; };
layout(std430, binding = 1) readonly buffer Source { float source[]; };
layout(std430, binding = 2) buffer Values { float values[]; };
void main() {
    for (uint k = gl_GlobalInvocationID.x; k < n; k += STRIDE)
        for (uint c = 0u; c < 3u; ++c) values[3u * uint(slots[k]) + c] = source[3u * k + c];
}
)";

// y = w x elementwise (the Jacobi preconditioner applied to a vector). n = rows.
const char* kHadamard = R"(
layout(std430, binding = 0) readonly buffer W { float w[]; };
layout(std430, binding = 1) readonly buffer X { float x[]; };
layout(std430, binding = 2) writeonly buffer Y { float y[]; };
void main() {
    for (uint j = gl_GlobalInvocationID.x; j < 3u * n; j += STRIDE) y[j] = w[j] * x[j];
}
)";

// target[i] = source[index[i]] (rgb): restriction by injection (multires, Eq. 17). n = rows.
const char* kGather = R"(
layout(std430, binding = 0) readonly buffer Index { int index[]; };
layout(std430, binding = 1) readonly buffer Source { float source[]; };
layout(std430, binding = 2) writeonly buffer Target { float target[]; };
void main() {
    for (uint i = gl_GlobalInvocationID.x; i < n; i += STRIDE)
        for (uint c = 0u; c < 3u; ++c) target[3u * i + c] = source[3u * uint(index[i]) + c];
}
)";

// fine = P coarse (or fine += P coarse with `accumulate`) with a channel-independent compressed-row
// operator (multires Eq. 16; the multigrid V-cycle's prolongation, and with P^T its restriction). The
// sum is `precise` (no fused multiply-add), so it rounds as the CPU float V-cycle does. n = rows.
const char* kInterpolate = R"(
layout(std430, binding = 0) readonly buffer Offsets { int offsets[]; };
layout(std430, binding = 1) readonly buffer Columns { int columns[]; };
layout(std430, binding = 2) readonly buffer Weights { float weights[]; };
layout(std430, binding = 3) readonly buffer Coarse { float coarse[]; };
layout(std430, binding = 4) buffer Fine { float fine[]; };
uniform uint accumulate;
void main() {
    for (uint i = gl_GlobalInvocationID.x; i < n; i += STRIDE) {
        precise vec3 s = vec3(0.0);
        for (int k = offsets[i]; k < offsets[i + 1u]; ++k) {
            uint j = 3u * uint(columns[k]);
            precise vec3 term = weights[k] * vec3(coarse[j], coarse[j + 1u], coarse[j + 2u]);
            s += term;
        }
        if (accumulate != 0u) s += vec3(fine[3u * i], fine[3u * i + 1u], fine[3u * i + 2u]);
        fine[3u * i] = s.x; fine[3u * i + 1u] = s.y; fine[3u * i + 2u] = s.z;
    }
}
)";

// One pass of the multigrid V-cycle's Chebyshev smoother (multires/multigrid_preconditioner.h) in
// float, with the CPU apply_rgb's operations in its order and no fused multiply-add (`precise`), so
// the device V-cycle rounds as the CPU one does:
//   s = b - A x (b first, then each stored entry subtracted in order; x = 0 with ZERO_START)
//   mode 0: d = c_r D^-1 s (FIRST) or c_d d + c_r D^-1 s, and y = x + d (y = d from a zero start)
//   mode 1: y = s (the residual restricted to the next level)
// Rows read their neighbours' x, so y is another buffer. n = slots.
const char* kMultigridSmooth = R"(
layout(std430, binding = 4) buffer D { float d[]; };
layout(std430, binding = 6) readonly buffer B { float b[]; };
layout(std430, binding = 7) writeonly buffer Y { float y[]; };
layout(std430, binding = 8) readonly buffer InvDiag { float inv_diag[]; };
uniform vec3 c_d;
uniform vec3 c_r;
uniform uint flags;  // 1: zero start, 2: first step, 4: residual only
void main() {
    bool zero_start = (flags & 1u) != 0u, first = (flags & 2u) != 0u, residual_only = (flags & 4u) != 0u;
    for (uint t = gl_GlobalInvocationID.x; t < n; t += STRIDE) {
        int row = slot_row(t);
        if (row < 0) continue;
        uint i = 3u * uint(row);
        vec3 s = vec3(b[i], b[i + 1u], b[i + 2u]);
        if (!zero_start) s = slot_residual(t, s);
        if (residual_only) {
            y[i] = s.x; y[i + 1u] = s.y; y[i + 2u] = s.z;
            continue;
        }
        precise vec3 r = s * vec3(inv_diag[i], inv_diag[i + 1u], inv_diag[i + 2u]);
        precise vec3 scaled = c_r * r;
        precise vec3 dv = first ? scaled : c_d * vec3(d[i], d[i + 1u], d[i + 2u]) + scaled;
        precise vec3 yv = zero_start ? dv : vec3(xin[i], xin[i + 1u], xin[i + 2u]) + dv;
        d[i] = dv.x; d[i + 1u] = dv.y; d[i + 2u] = dv.z;
        y[i] = yv.x; y[i + 1u] = yv.y; y[i + 2u] = yv.z;
    }
}
)";

// The two sums of a multigrid-CG step (multires/gpu_multigrid_frame_solver.h) in one reduction:
// r . z and x . (b - r) (= x . M x, the energy of the iterate) per channel. n = rows.
const char* kRzEnergy = R"(
layout(std430, binding = 0) readonly buffer R { float r[]; };
layout(std430, binding = 1) readonly buffer Z { float z[]; };
layout(std430, binding = 2) readonly buffer X { float x[]; };
layout(std430, binding = 3) readonly buffer B { float b[]; };
void main() {
    float acc[6] = float[6](0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (uint i = gl_GlobalInvocationID.x; i < n; i += STRIDE)
        for (uint c = 0u; c < 3u; ++c) {
            uint j = 3u * i + c;
            acc[c] += r[j] * z[j];
            acc[3u + c] += x[j] * (b[j] - r[j]);
        }
    reduce_partials(acc);
}
)";

// E = max(a phi - c q, 0) per vertex and channel (Eq. 3 without F_t; a, c per vertex). n = rows.
const char* kRadiance = R"(
layout(std430, binding = 0) readonly buffer PhiWeight { float a[]; };
layout(std430, binding = 1) readonly buffer QWeight { float c[]; };
layout(std430, binding = 2) readonly buffer Phi { float phi[]; };
layout(std430, binding = 3) readonly buffer Q { float q[]; };
layout(std430, binding = 4) writeonly buffer E { float e[]; };
uniform uint clamp_negative;
void main() {
    for (uint i = gl_GlobalInvocationID.x; i < n; i += STRIDE)
        for (uint k = 0u; k < 3u; ++k) {
            float v = a[i] * phi[3u * i + k] - c[i] * q[3u * i + k];
            e[3u * i + k] = clamp_negative != 0u ? max(v, 0.0) : v;
        }
}
)";

// One workgroup adds the per-invocation sums of `groups` workgroups lane by lane: folded[lane * nsums + c].
const char* kFold = R"(#version 430
layout(local_size_x = 256) in;
layout(std430, binding = 5) readonly buffer ThreadSums { float thread_sums[]; };
layout(std430, binding = 10) writeonly buffer Folded { float folded[]; };
uniform uint groups;
uniform uint nsums;
void main() {
    uint lane = gl_LocalInvocationID.x;
    for (uint c = 0u; c < nsums; ++c) {
        float s = 0.0;
        for (uint g = 0u; g < groups; ++g) s += thread_sums[(g * 256u + lane) * nsums + c];
        folded[lane * nsums + c] = s;
    }
}
)";

// One kernel's source: the prelude (with NSUMS per-thread sums to reduce, if any), the sparse product
// for a matrix format (ACC: its accumulation type), and the body.
std::string kernel(int sums, const char* acc, const char* format, const char* body) {
    std::string s = kPrelude;
    if (sums > 0) s.insert(s.find('\n') + 1, "#define NSUMS " + std::to_string(sums) + "\n");
    if (acc) s += std::string("#define ACC ") + acc + "\n" + kMatrixCommon + format;
    return s + body;
}

}  // namespace

GpuKernels::GpuKernels(const GlApi& gl, std::initializer_list<GpuMatrixFormat> formats) : gl_(&gl) {
    require_compute_support(gl);
    for (GpuMatrixFormat f : formats) {
        const char* format = f == GpuMatrixFormat::Csr ? kCsr : kSliced;
        multiply_dot_.emplace(f, ComputeProgram(gl, "multiply_dot_" + to_string(f), kernel(3, "vec3", format, kMultiplyDot)));
        residual_.emplace(f, ComputeProgram(gl, "residual_" + to_string(f), kernel(3, "dvec3", format, kResidual)));
        multigrid_smooth_.emplace(
            f, ComputeProgram(gl, "multigrid_smooth_" + to_string(f), kernel(0, "vec3", format, kMultigridSmooth)));
    }
    dot_ = ComputeProgram(gl, "dot", kernel(3, nullptr, nullptr, kDot));
    axpby_ = ComputeProgram(gl, "axpby", kernel(0, nullptr, nullptr, kAxpby));
    extract_diagonal_ = ComputeProgram(gl, "extract_diagonal", kernel(0, nullptr, nullptr, kExtractDiagonal));
    cg_update_ = ComputeProgram(gl, "cg_update", kernel(6, nullptr, nullptr, kCgUpdate));
    scatter_ = ComputeProgram(gl, "scatter", kernel(0, nullptr, nullptr, kScatter));
    fold_ = ComputeProgram(gl, "fold", kFold);
    hadamard_ = ComputeProgram(gl, "hadamard", kernel(0, nullptr, nullptr, kHadamard));
    gather_ = ComputeProgram(gl, "gather", kernel(0, nullptr, nullptr, kGather));
    interpolate_ = ComputeProgram(gl, "interpolate", kernel(0, nullptr, nullptr, kInterpolate));
    radiance_ = ComputeProgram(gl, "radiance", kernel(0, nullptr, nullptr, kRadiance));
    rz_energy_ = ComputeProgram(gl, "rz_and_energy", kernel(6, nullptr, nullptr, kRzEnergy));
    partials_ = GpuBuffer(gl, kMaxGroups * kGroupSize * kMaxSums * sizeof(float));
    folded_ = GpuBuffer(gl, kGroupSize * kMaxSums * sizeof(float));
    check_gpu_error(gl, "compiling the kernels");
}

GpuBuffer GpuKernels::vector(size_t rows, const float* data) const {
    if (data) return GpuBuffer(*gl_, 3 * rows * sizeof(float), data);
    const std::vector<float> zeros(3 * rows, 0.0f);
    return GpuBuffer(*gl_, zeros.size() * sizeof(float), zeros.data());
}

template <size_t K>
std::array<double, K> GpuKernels::sum_partials(GLuint groups) {
    fold_.use();
    partials_.bind(5);
    folded_.bind(10);
    gl_->Uniform1ui(fold_.uniform("groups"), groups);
    gl_->Uniform1ui(fold_.uniform("nsums"), static_cast<GLuint>(K));
    fold_.dispatch(1);
    std::vector<float> lanes(kGroupSize * K);
    folded_.read(0, lanes.size() * sizeof(float), lanes.data());
    std::array<double, K> total{};
    for (GLuint lane = 0; lane < kGroupSize; ++lane)
        for (size_t c = 0; c < K; ++c) total[c] += lanes[lane * K + c];
    return total;
}

GLuint GpuKernels::launch(const ComputeProgram& program, size_t n, size_t threads, std::initializer_list<Binding> buffers,
                          const std::function<void()>& uniforms) {
    program.use();
    for (const Binding& binding : buffers) binding.buffer->bind(binding.index);
    partials_.bind(5);  // reduction kernels write their per-invocation sums here
    gl_->Uniform1ui(program.uniform("n"), static_cast<GLuint>(n));
    if (uniforms) uniforms();
    const GLuint groups = groups_for(threads);
    program.dispatch(groups);
    return groups;
}

GLuint GpuKernels::launch_matrix(const ComputeProgram& program, const GpuMatrix& m, std::initializer_list<Binding> buffers,
                                 const std::function<void()>& uniforms) {
    m.starts.bind(0);
    m.columns.bind(1);
    m.values.bind(2);
    m.slot_rows.bind(9);
    return launch(program, m.layout.slots, m.layout.slots, buffers, [&] {
        gl_->Uniform1ui(program.uniform("slice_height"), std::max<uint32_t>(m.layout.slice_height, 1));
        if (uniforms) uniforms();
    });
}

namespace {
void set_vec3(const GlApi& gl, const ComputeProgram& program, const char* name, const Rgbd& v) {
    const float f[3] = {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2])};
    gl.Uniform3fv(program.uniform(name), 1, f);
}
}  // namespace

Rgbd GpuKernels::multiply_dot(const GpuMatrix& m, const GpuBuffer& p, GpuBuffer& q) {
    return sum_partials<3>(launch_matrix(multiply_dot_.at(m.layout.format), m, {{3, &p}, {4, &q}}));
}

Rgbd GpuKernels::residual(const GpuMatrix& m, const GpuBuffer& b, const GpuBuffer& x, const GpuBuffer& inv_diag,
                          GpuBuffer& r, GpuBuffer& z, const std::array<bool, 3>& mask) {
    const ComputeProgram& program = residual_.at(m.layout.format);
    const GLuint bits[3] = {mask[0], mask[1], mask[2]};
    return sum_partials<3>(launch_matrix(program, m, {{3, &x}, {4, &r}, {6, &b}, {7, &z}, {8, &inv_diag}},
                                         [&] { gl_->Uniform3uiv(program.uniform("mask"), 1, bits); }));
}

Rgbd GpuKernels::dot(size_t rows, const GpuBuffer& u, const GpuBuffer& v) { return dot(rows, u, v, u); }

Rgbd GpuKernels::dot(size_t rows, const GpuBuffer& u, const GpuBuffer& v, const GpuBuffer& w) {
    const GLuint weighted = &w == &u ? 0u : 1u;
    return sum_partials<3>(launch(dot_, rows, rows, {{0, &u}, {1, &v}, {2, &w}},
                                  [&] { gl_->Uniform1ui(dot_.uniform("weighted"), weighted); }));
}

void GpuKernels::axpby(size_t rows, const Rgbd& a, const GpuBuffer& x, const Rgbd& b, GpuBuffer& y) {
    launch(axpby_, rows, rows, {{0, &x}, {1, &y}}, [&] {
        set_vec3(*gl_, axpby_, "a", a);
        set_vec3(*gl_, axpby_, "b", b);
    });
}

void GpuKernels::extract_diagonal(const GpuMatrix& m, GpuBuffer& diag, GpuBuffer& inv_diag) {
    launch(extract_diagonal_, m.layout.rows, m.layout.rows, {{0, &m.diagonal}, {2, &m.values}, {3, &diag}, {4, &inv_diag}});
}

std::array<double, 6> GpuKernels::cg_update(size_t rows, const Rgbd& alpha, const GpuBuffer& p, const GpuBuffer& q,
                                            const GpuBuffer& diag, const GpuBuffer& inv_diag, GpuBuffer& x,
                                            GpuBuffer& r, GpuBuffer& z) {
    return sum_partials<6>(launch(cg_update_, rows, rows,
                                  {{0, &p}, {1, &q}, {2, &diag}, {3, &inv_diag}, {4, &x}, {6, &r}, {7, &z}},
                                  [&] { set_vec3(*gl_, cg_update_, "alpha", alpha); }));
}

void GpuKernels::scatter(size_t count, const GpuBuffer& slots, const GpuBuffer& source, GpuBuffer& values) {
    launch(scatter_, count, count, {{0, &slots}, {1, &source}, {2, &values}});
}

void GpuKernels::upload_rows(GpuMatrix& target, const RgbCsrView& matrix, std::span<const int32_t> rows) {
    const size_t n = matrix.offsets.empty() ? 0 : matrix.offsets.size() - 1;
    if (n != target.layout.rows || matrix.columns.size() != target.layout.stored_index.size())
        throw InvalidArgumentError("GPU upload_rows: the matrix does not have the device matrix's pattern");
    // Stored positions and new values of the rows' entries, scattered by one dispatch: works for every
    // format (ELL/SELL spread a row's entries across the buffer).
    std::vector<int32_t> slots;
    std::vector<float> values;
    for (const int32_t row : rows) {
        if (row < 0 || static_cast<size_t>(row) >= n)
            throw InvalidArgumentError("GPU upload_rows: row " + std::to_string(row) + " out of range");
        for (int32_t k = matrix.offsets[row]; k < matrix.offsets[row + 1]; ++k) {
            slots.push_back(target.layout.stored_index[k]);
            for (int c = 0; c < 3; ++c) values.push_back(static_cast<float>(matrix.values[c][k]));
        }
    }
    if (slots.empty()) return;
    const GpuBuffer slot_buffer = GpuBuffer::from<int32_t>(gl(), slots);
    const GpuBuffer value_buffer = GpuBuffer::from<float>(gl(), values);
    scatter(slots.size(), slot_buffer, value_buffer, target.values);
}

void GpuKernels::hadamard(size_t rows, const GpuBuffer& w, const GpuBuffer& x, GpuBuffer& y) {
    launch(hadamard_, rows, 3 * rows, {{0, &w}, {1, &x}, {2, &y}});
}

void GpuKernels::gather(size_t rows, const GpuBuffer& index, const GpuBuffer& source, GpuBuffer& target) {
    launch(gather_, rows, rows, {{0, &index}, {1, &source}, {2, &target}});
}

GpuInterpolation::GpuInterpolation(const GlApi& gl, std::span<const int32_t> offsets_,
                                   std::span<const int32_t> columns_, std::span<const double> weights_)
    : rows(offsets_.empty() ? 0 : offsets_.size() - 1) {
    offsets = GpuBuffer::from<int32_t>(gl, offsets_);
    columns = GpuBuffer::from<int32_t>(gl, columns_);
    const std::vector<float> w(weights_.begin(), weights_.end());
    weights = GpuBuffer::from<float>(gl, w);
}

void GpuKernels::interpolate(const GpuInterpolation& p, const GpuBuffer& coarse, GpuBuffer& fine, bool accumulate) {
    launch(interpolate_, p.rows, p.rows, {{0, &p.offsets}, {1, &p.columns}, {2, &p.weights}, {3, &coarse}, {4, &fine}},
           [&] { gl_->Uniform1ui(interpolate_.uniform("accumulate"), accumulate ? 1u : 0u); });
}

void GpuKernels::multigrid_smooth(const GpuMatrix& m, const GpuBuffer& b, const GpuBuffer& x, const GpuBuffer& inv_diag,
                                  GpuBuffer& d, GpuBuffer& y, const SmoothingPass& pass) {
    const ComputeProgram& program = multigrid_smooth_.at(m.layout.format);
    const GLuint flags = (pass.zero_start ? 1u : 0u) | (pass.first_step ? 2u : 0u);
    launch_matrix(program, m, {{3, &x}, {4, &d}, {6, &b}, {7, &y}, {8, &inv_diag}}, [&] {
        set_vec3(*gl_, program, "c_d", pass.c_d);
        set_vec3(*gl_, program, "c_r", pass.c_r);
        gl_->Uniform1ui(program.uniform("flags"), flags);
    });
}

void GpuKernels::multigrid_residual(const GpuMatrix& m, const GpuBuffer& b, const GpuBuffer& x, GpuBuffer& r) {
    const ComputeProgram& program = multigrid_smooth_.at(m.layout.format);
    // d and inv_diag are not read in this mode; x and b stand in for them (read-only).
    launch_matrix(program, m, {{3, &x}, {4, &x}, {6, &b}, {7, &r}, {8, &b}},
                  [&] { gl_->Uniform1ui(program.uniform("flags"), 4u); });
}

std::array<double, 6> GpuKernels::rz_and_energy(size_t rows, const GpuBuffer& r, const GpuBuffer& z, const GpuBuffer& x,
                                                const GpuBuffer& b) {
    return sum_partials<6>(launch(rz_energy_, rows, rows, {{0, &r}, {1, &z}, {2, &x}, {3, &b}}));
}

void GpuKernels::radiance(size_t rows, const GpuBuffer& phi_weight, const GpuBuffer& q_weight, const GpuBuffer& phi,
                          const GpuBuffer& q, GpuBuffer& e, bool clamp_negative) {
    launch(radiance_, rows, rows, {{0, &phi_weight}, {1, &q_weight}, {2, &phi}, {3, &q}, {4, &e}},
           [&] { gl_->Uniform1ui(radiance_.uniform("clamp_negative"), clamp_negative ? 1u : 0u); });
}

}  // namespace waxwork
