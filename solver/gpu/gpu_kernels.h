// The compute kernels of the GPU solvers (OpenGL 4.3 compute shaders, GLSL 4.30): sparse products in
// the three storage formats of gpu_matrix.h, reductions, axpy, the Jacobi preconditioner and the fused
// conjugate-gradient steps. Vectors are rgb-interleaved float buffers (3 floats per vertex), so one
// dispatch advances the three channel systems, as the CPU float path does.
//
// Reductions. Each reduction kernel runs at most 512 workgroups that stride over the rows, sums per
// invocation in float and writes one sum per invocation and channel; a second dispatch folds them to
// 256 lane sums, which the host adds in double in a fixed order. The result is deterministic (same
// input, same bits) and the read-back is at most 6 KB, the only host round-trip of an iteration.
// The true residual of the CG confirmation step accumulates its row products in double (GLSL 4.00
// doubles, core since OpenGL 4.0) as the CPU path does: that is what lets float CG reach ~1e-6.
#pragma once

#include "gl/gpu_compute.h"
#include "solver/gpu/gpu_matrix.h"

#include <array>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <map>
#include <span>

namespace waxwork {

using Rgbd = std::array<double, 3>;

// A channel-independent compressed-row operator on the device (multires interpolation, Eq. 16).
struct GpuInterpolation {
    size_t rows = 0;
    GpuBuffer offsets, columns, weights;  // weights in float

    GpuInterpolation(const GlApi& gl, std::span<const int32_t> offsets, std::span<const int32_t> columns,
                     std::span<const double> weights);
};

class GpuKernels {
public:
    // Compiles every kernel (the products for the given matrix formats) now, so a driver problem
    // surfaces as GpuError before any solving starts. Needs a current OpenGL >= 4.3 context.
    explicit GpuKernels(const GlApi& gl, std::initializer_list<GpuMatrixFormat> formats = {
                                             GpuMatrixFormat::Csr, GpuMatrixFormat::Ell, GpuMatrixFormat::SellCSigma});

    const GlApi& gl() const { return *gl_; }
    // An rgb vector of `rows` vertices (3 floats each), zero-filled or from `data` (3 * rows floats).
    GpuBuffer vector(size_t rows, const float* data = nullptr) const;

    // q = M p; returns p . q per channel.
    Rgbd multiply_dot(const GpuMatrix& m, const GpuBuffer& p, GpuBuffer& q);
    // r = b - M x (row sums in double), z = D^-1 r for the channels whose mask is set (the others'
    // r and z are left alone); returns r . z per channel.
    Rgbd residual(const GpuMatrix& m, const GpuBuffer& b, const GpuBuffer& x, const GpuBuffer& inv_diag, GpuBuffer& r,
                  GpuBuffer& z, const std::array<bool, 3>& mask = {true, true, true});
    // sum_i u_i v_i per channel, or sum_i u_i v_i w_i with a weight vector.
    Rgbd dot(size_t rows, const GpuBuffer& u, const GpuBuffer& v);
    Rgbd dot(size_t rows, const GpuBuffer& u, const GpuBuffer& v, const GpuBuffer& w);
    // y = a x + b y per channel.
    void axpby(size_t rows, const Rgbd& a, const GpuBuffer& x, const Rgbd& b, GpuBuffer& y);
    // diag = diag(M), inv_diag = 1 / diag (per channel; the division in double, as on the CPU; 1 where
    // the diagonal is zero or not finite).
    void extract_diagonal(const GpuMatrix& m, GpuBuffer& diag, GpuBuffer& inv_diag);
    // Fused CG update, per channel c with alpha[c] (0 freezes a channel):
    //   x += alpha p, r -= alpha q, z = D^-1 r; returns (r . z, x . D x) for r, g, b in that order.
    std::array<double, 6> cg_update(size_t rows, const Rgbd& alpha, const GpuBuffer& p, const GpuBuffer& q,
                                    const GpuBuffer& diag, const GpuBuffer& inv_diag, GpuBuffer& x, GpuBuffer& r,
                                    GpuBuffer& z);
    // y = w x elementwise (e.g. the Jacobi preconditioner z = D^-1 r).
    void hadamard(size_t rows, const GpuBuffer& w, const GpuBuffer& x, GpuBuffer& y);
    // target[i] = source[index[i]] per channel (restriction by injection).
    void gather(size_t rows, const GpuBuffer& index, const GpuBuffer& source, GpuBuffer& target);
    // fine = P coarse; with `accumulate`, fine += P coarse (rounded as the CPU's x[i] += sum).
    void interpolate(const GpuInterpolation& p, const GpuBuffer& coarse, GpuBuffer& fine, bool accumulate = false);

    // The multigrid V-cycle's passes (multires/gpu_multigrid_preconditioner.h), in float with the CPU
    // float V-cycle's operations in its order and without fused multiply-adds, so they round alike.
    // One Chebyshev pass: s = b - M x (x = 0 with zero_start), d = c_r D^-1 s (first_step) or
    // c_d d + c_r D^-1 s, y = x + d. y must not be x (rows read their neighbours' x).
    struct SmoothingPass {
        bool zero_start = false, first_step = false;
        Rgbd c_d{}, c_r{};
    };
    void multigrid_smooth(const GpuMatrix& m, const GpuBuffer& b, const GpuBuffer& x, const GpuBuffer& inv_diag,
                          GpuBuffer& d, GpuBuffer& y, const SmoothingPass& pass);
    // r = b - M x in float, b first and each stored entry subtracted in the row's order.
    void multigrid_residual(const GpuMatrix& m, const GpuBuffer& b, const GpuBuffer& x, GpuBuffer& r);
    // (r . z, x . (b - r)) per channel in that order: a multigrid-CG step's two sums in one reduction.
    std::array<double, 6> rz_and_energy(size_t rows, const GpuBuffer& r, const GpuBuffer& z, const GpuBuffer& x,
                                        const GpuBuffer& b);
    // e = max(a phi - c q, 0) (or unclamped) with per-vertex scalars a, c: gpu_radiance.h.
    void radiance(size_t rows, const GpuBuffer& phi_weight, const GpuBuffer& q_weight, const GpuBuffer& phi,
                  const GpuBuffer& q, GpuBuffer& e, bool clamp_negative);
    // values[3 * slot[k] + c] = source[3 * k + c] for k < count: row updates after painting.
    void scatter(size_t count, const GpuBuffer& slots, const GpuBuffer& source, GpuBuffer& values);
    // The rows `rows` of `matrix` (its CSR entries, same pattern as `target` was built from) into
    // target's stored values, converted to float as at upload: equal to uploading the whole matrix
    // again, for O(the rows' entries). Throws InvalidArgumentError on a row out of range or a size
    // mismatch. The caller refreshes the Jacobi diagonal (extract_diagonal) afterwards.
    void upload_rows(GpuMatrix& target, const RgbCsrView& matrix, std::span<const int32_t> rows);

private:
    struct Binding {
        GLuint index;
        const GpuBuffer* buffer;
    };
    // Binds, sets the uniform n (and whatever `uniforms` sets), dispatches enough workgroups for
    // `threads` (capped: grid-stride loops) and returns their number.
    GLuint launch(const ComputeProgram& program, size_t n, size_t threads, std::initializer_list<Binding> buffers,
                  const std::function<void()>& uniforms = {});
    // The same for a sparse-product kernel: the matrix at bindings 0, 1, 2, 9; n = its slots.
    GLuint launch_matrix(const ComputeProgram& program, const GpuMatrix& m, std::initializer_list<Binding> buffers,
                         const std::function<void()>& uniforms = {});
    // Folds the per-invocation sums of the last reduction (`groups` workgroups) and adds them up.
    template <size_t K>
    std::array<double, K> sum_partials(GLuint groups);

    const GlApi* gl_;
    std::map<GpuMatrixFormat, ComputeProgram> multiply_dot_, residual_, multigrid_smooth_;
    ComputeProgram dot_, axpby_, extract_diagonal_, cg_update_, scatter_, fold_, hadamard_, gather_, interpolate_,
        radiance_, rz_energy_;
    GpuBuffer partials_, folded_;
};

}  // namespace waxwork
