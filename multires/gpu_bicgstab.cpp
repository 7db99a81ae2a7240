#include "multires/gpu_bicgstab.h"

#include <cmath>

namespace waxwork {
namespace {

bool tiny(double inner, double norm_product, double tolerance) {
    return !(std::abs(inner) > tolerance * norm_product);  // also true for NaN
}

constexpr int kMaxReplacements = 5;

Rgbd sqrt3(const Rgbd& v) { return {std::sqrt(v[0]), std::sqrt(v[1]), std::sqrt(v[2])}; }

}  // namespace

std::array<BicgstabResult, 3> solve_gpu_bicgstab(GpuKernels& K, const GpuMatrix& a, const GpuBuffer& inv_diag,
                                                 const GpuBuffer& b, GpuBuffer& x, const BicgstabOptions& options) {
    const size_t n = a.layout.rows;
    std::array<BicgstabResult, 3> result;
    GpuBuffer x0 = K.vector(n), r = K.vector(n), r0 = K.vector(n), p = K.vector(n), v = K.vector(n),
              y = K.vector(n), s = K.vector(n), z = K.vector(n), t = K.vector(n);
    x0.copy_from(x);
    // Channels: `active` iterate; `done` stopped after iterating (judged by the final true residual);
    // channels with a zero or non-finite b are settled at once (x = 0) and never judged.
    std::array<bool, 3> active{}, judged{};
    const Rgbd b_norm = sqrt3(K.dot(n, b, b));
    Rgbd keep{1, 1, 1};
    for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(b_norm[c])) {
            result[c].status = BicgstabStatus::NonFinite;
            keep[c] = 0;
        } else if (b_norm[c] == 0) {
            keep[c] = 0;  // the solution is zero
        } else {
            active[c] = judged[c] = true;
        }
    }
    if (keep != Rgbd{1, 1, 1}) {
        K.axpby(n, {0, 0, 0}, x, keep, x);
        x0.copy_from(x);
    }
    // out = b - A x with the row sums in double (GpuKernels::residual; z is scratch here): in float the
    // cancellation in b - A x alone costs ~1e-5 relative, the coarsest level's target.
    auto true_residual = [&](GpuBuffer& out) {
        K.residual(a, b, x, inv_diag, out, z);
        return sqrt3(K.dot(n, out, out));
    };
    Rgbd r_norm = true_residual(r);
    const Rgbd initial = r_norm;
    Rgbd target{}, best = r_norm;
    std::array<int, 3> best_iteration{}, replacements{};
    for (int c = 0; c < 3; ++c) {
        if (!judged[c]) continue;
        result[c].initial_relative_residual = initial[c] / b_norm[c];
        target[c] = options.relative_tolerance * b_norm[c];
        result[c].status = BicgstabStatus::IterationLimit;
        if (!std::isfinite(r_norm[c])) {
            result[c].status = BicgstabStatus::NonFinite;
            active[c] = false;
        } else if (r_norm[c] <= target[c]) {
            result[c].status = BicgstabStatus::Converged;
            active[c] = false;
        }
    }
    r0.copy_from(r);
    const Rgbd r0_norm = r_norm;
    Rgbd rho{1, 1, 1}, alpha{1, 1, 1}, omega{1, 1, 1};
    for (int k = 0; k < options.max_iterations && (active[0] || active[1] || active[2]); ++k) {
        const Rgbd rho_new = K.dot(n, r0, r);
        Rgbd pa{}, pb{1, 1, 1}, pr{};
        for (int c = 0; c < 3; ++c) {
            if (!active[c]) continue;
            if (tiny(rho_new[c], r0_norm[c] * r_norm[c], options.breakdown_tolerance)) {
                result[c].status = std::isfinite(rho_new[c]) ? BicgstabStatus::RhoBreakdown : BicgstabStatus::NonFinite;
                active[c] = false;
                continue;
            }
            const double beta = (rho_new[c] / rho[c]) * (alpha[c] / omega[c]);
            rho[c] = rho_new[c];
            pa[c] = -beta * omega[c];  // p = r + beta (p - omega v)
            pb[c] = beta;
            pr[c] = 1;
        }
        if (!(active[0] || active[1] || active[2])) break;
        K.axpby(n, pa, v, pb, p);
        K.axpby(n, pr, r, {1, 1, 1}, p);
        K.hadamard(n, inv_diag, p, y);
        K.multiply_dot(a, y, v);
        const Rgbd r0v = K.dot(n, r0, v), vv = K.dot(n, v, v);
        Rgbd sa{};
        for (int c = 0; c < 3; ++c) {
            if (!active[c]) continue;
            if (tiny(r0v[c], r0_norm[c] * std::sqrt(vv[c]), options.breakdown_tolerance)) {
                result[c].status = std::isfinite(r0v[c]) ? BicgstabStatus::RhoBreakdown : BicgstabStatus::NonFinite;
                active[c] = false;
                continue;
            }
            alpha[c] = rho[c] / r0v[c];
            sa[c] = -alpha[c];
            result[c].iterations = k + 1;
        }
        if (!(active[0] || active[1] || active[2])) break;
        s.copy_from(r);
        K.axpby(n, sa, v, {1, 1, 1}, s);  // s = r - alpha v
        K.hadamard(n, inv_diag, s, z);
        const Rgbd s_norm = sqrt3(K.dot(n, s, s));
        K.multiply_dot(a, z, t);
        const Rgbd tt = K.dot(n, t, t), ts = K.dot(n, t, s);
        // Per channel: x += xa y + xo z; r = (take_s ? s : r) - ro t.
        Rgbd xa{}, xo{}, take_s{}, ro{};
        std::array<bool, 3> continuing{}, converging{};
        for (int c = 0; c < 3; ++c) {
            if (!active[c]) continue;
            xa[c] = alpha[c];
            take_s[c] = 1;
            if (s_norm[c] <= target[c]) {  // the half step already converged
                r_norm[c] = s_norm[c];
                converging[c] = true;
                continue;
            }
            if (!(tt[c] > 0) || tiny(ts[c], std::sqrt(tt[c]) * s_norm[c], options.breakdown_tolerance)) {
                // omega would be ~0: keep the half step, which is still valid.
                r_norm[c] = s_norm[c];
                result[c].status = std::isfinite(ts[c]) && std::isfinite(tt[c]) ? BicgstabStatus::OmegaBreakdown
                                                                                 : BicgstabStatus::NonFinite;
                active[c] = false;
                continue;
            }
            omega[c] = ts[c] / tt[c];
            xo[c] = omega[c];
            ro[c] = -omega[c];
            continuing[c] = true;
        }
        K.axpby(n, xa, y, {1, 1, 1}, x);
        K.axpby(n, xo, z, {1, 1, 1}, x);
        K.axpby(n, take_s, s, {1 - take_s[0], 1 - take_s[1], 1 - take_s[2]}, r);
        K.axpby(n, ro, t, {1, 1, 1}, r);
        const Rgbd rn = continuing[0] || continuing[1] || continuing[2] ? sqrt3(K.dot(n, r, r)) : Rgbd{};
        for (int c = 0; c < 3; ++c) {
            if (!continuing[c]) continue;
            r_norm[c] = rn[c];
            if (!std::isfinite(rn[c])) {
                result[c].status = BicgstabStatus::NonFinite;
                active[c] = false;
            } else if (rn[c] > options.divergence_factor * initial[c]) {
                result[c].status = BicgstabStatus::Divergence;
                active[c] = false;
            } else if (rn[c] < 0.99 * best[c]) {
                best[c] = rn[c];
                best_iteration[c] = k;
            } else if (k - best_iteration[c] >= options.stagnation_window) {
                result[c].status = BicgstabStatus::Stagnation;
                active[c] = false;
            }
            if (active[c] && rn[c] <= target[c]) converging[c] = true;
        }
        // Residual replacement (van der Vorst and Ye 2000): in float the recursive residual drifts from
        // b - A x, so convergence is confirmed with the true residual; where that is still above the
        // target, the true residual replaces the recursive one and the channel goes on (a few times).
        if (converging[0] || converging[1] || converging[2]) {
            const Rgbd true_norm = true_residual(t);
            Rgbd replace{};
            for (int c = 0; c < 3; ++c) {
                if (!converging[c]) continue;
                if (true_norm[c] <= target[c] || ++replacements[c] > kMaxReplacements || !std::isfinite(true_norm[c])) {
                    active[c] = false;  // judged below
                    continue;
                }
                replace[c] = 1;
                r_norm[c] = true_norm[c];
                active[c] = true;
            }
            if (replace != Rgbd{0, 0, 0})
                K.axpby(n, replace, t, {1 - replace[0], 1 - replace[1], 1 - replace[2]}, r);
        }
    }
    // Judge the returned point by its true residual; hand back the start vector when it is no better.
    const Rgbd final_norm = true_residual(r);
    Rgbd revert{};
    for (int c = 0; c < 3; ++c) {
        if (!judged[c]) continue;
        BicgstabResult& res = result[c];
        double norm = final_norm[c];
        if (!std::isfinite(norm) || norm > initial[c] || (res.failed() && norm >= initial[c])) {
            if (!res.failed()) res.status = std::isfinite(norm) ? BicgstabStatus::Divergence : BicgstabStatus::NonFinite;
            revert[c] = 1;
            norm = initial[c];
            res.reverted = true;
        } else if (res.status == BicgstabStatus::IterationLimit && norm <= target[c]) {
            res.status = BicgstabStatus::Converged;
        } else if (res.status == BicgstabStatus::Converged && norm > 10 * target[c]) {
            res.status = BicgstabStatus::IterationLimit;
        }
        res.relative_residual = norm / b_norm[c];
    }
    if (revert != Rgbd{0, 0, 0}) K.axpby(n, revert, x0, {1 - revert[0], 1 - revert[1], 1 - revert[2]}, x);
    return result;
}

}  // namespace waxwork
