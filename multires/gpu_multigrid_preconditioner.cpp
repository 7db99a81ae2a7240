#include "multires/gpu_multigrid_preconditioner.h"

#include "base/error.h"

#include <string>
#include <utility>

namespace waxwork {
namespace {

// Level l of the CPU preconditioner as the rgb compressed-row view a GpuMatrix is made from.
RgbCsrView level_view(const MultigridPreconditioner& pre, size_t l) {
    const size_t n = pre.rows(l), nnz = pre.nonzeros(l);
    std::array<std::span<const double>, 3> values;
    for (int c = 0; c < 3; ++c) values[static_cast<size_t>(c)] = {pre.view(l, c).values, nnz};
    const CsrMatrixView<double> v = pre.view(l, 0);
    return {{v.offsets, n + 1}, {v.columns, nnz}, pre.diagonal(l), values};
}

std::unique_ptr<GpuInterpolation> upload(const GlApi& gl, const InterpolationOperator& p) {
    return std::make_unique<GpuInterpolation>(gl, p.offsets, p.columns, p.weights);
}

}  // namespace

struct GpuMultigridPreconditioner::Level {
    size_t rows = 0;
    GpuMatrix a;
    GpuBuffer inv_diag;
    std::unique_ptr<GpuInterpolation> p, pt;  // to this level from the next, and its transpose (none: coarsest)
    // b: the right-hand side (level 0 reads the caller's r), x and y: the smoother's iterate and the
    // next one (level 0 uses the caller's z for x), r: the residual, d: the Chebyshev direction.
    GpuBuffer b, x, y, r, d;
    MultigridPreconditioner::Chebyshev chebyshev;

    Level(const GlApi& gl, const RgbCsrView& view, GpuMatrixFormat format) : rows(view.rows()), a(gl, view, format) {}
};

GpuMultigridPreconditioner::GpuMultigridPreconditioner(GpuKernels& kernels, MultigridPreconditioner& preconditioner,
                                                       GpuMatrixFormat format)
    : kernels_(kernels), preconditioner_(preconditioner) {
    const GlApi& gl = kernels.gl();
    const size_t count = preconditioner.level_count();
    for (size_t l = 0; l < count; ++l) {
        auto level = std::make_unique<Level>(gl, level_view(preconditioner, l), format);
        level->inv_diag = kernels.vector(level->rows);
        const bool coarsest = l + 1 == count;
        if (!coarsest) {
            level->p = upload(gl, preconditioner.interpolation(l));
            level->pt = upload(gl, preconditioner.transposed_interpolation(l));
            level->chebyshev = preconditioner.chebyshev(l);
            for (GpuBuffer* v : {&level->y, &level->r, &level->d}) *v = kernels.vector(level->rows);
        }
        if (l > 0) {
            level->b = kernels.vector(level->rows);
            level->x = kernels.vector(level->rows);
        }
        levels_.push_back(std::move(level));
        std::vector<int32_t> all(levels_.back()->rows);
        for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int32_t>(i);
        upload_inverse_diagonal(l, all);
    }
    coarse_b_.resize(3 * levels_.back()->rows);
    coarse_x_.resize(3 * levels_.back()->rows);
    check_gpu_error(gl, "uploading the multigrid levels");
}

GpuMultigridPreconditioner::~GpuMultigridPreconditioner() = default;

size_t GpuMultigridPreconditioner::size() const { return levels_.front()->rows; }

const GpuMatrix& GpuMultigridPreconditioner::matrix(size_t level) const { return levels_.at(level)->a; }
const GpuBuffer& GpuMultigridPreconditioner::inverse_diagonal(size_t level) const { return levels_.at(level)->inv_diag; }

// 1 / a_ii in double rounded to float, as the CPU preconditioner's float smoother stores it (the
// device's extract_diagonal would divide by the float diagonal instead). The rows' values only: a
// scatter by row, O(rows) of transfer.
void GpuMultigridPreconditioner::upload_inverse_diagonal(size_t l, std::span<const int32_t> rows) {
    if (rows.empty()) return;
    Level& level = *levels_[l];
    const std::span<const int32_t> diagonal = preconditioner_.diagonal(l);
    std::vector<float> values(3 * rows.size());
    for (int c = 0; c < 3; ++c) {
        const double* a = preconditioner_.view(l, c).values;
        for (size_t k = 0; k < rows.size(); ++k)
            values[3 * k + static_cast<size_t>(c)] =
                static_cast<float>(1.0 / a[diagonal[static_cast<size_t>(rows[k])]]);
    }
    if (rows.size() == level.rows) {  // every row in order (at upload): a plain write
        level.inv_diag.write(0, values.size() * sizeof(float), values.data());
        return;
    }
    const GlApi& gl = kernels_.gl();
    const GpuBuffer slots = GpuBuffer::from<int32_t>(gl, rows);
    const GpuBuffer source = GpuBuffer::from<float>(gl, values);
    kernels_.scatter(rows.size(), slots, source, level.inv_diag);
}

void GpuMultigridPreconditioner::apply(const GpuBuffer& r, GpuBuffer& z) {
    const size_t bytes = 3 * size() * sizeof(float);
    if (r.bytes() != bytes || z.bytes() != bytes)
        throw InvalidArgumentError("GPU multigrid: vectors of " + std::to_string(r.bytes()) + " and " +
                                   std::to_string(z.bytes()) + " bytes for " + std::to_string(size()) + " vertices");
    if (r.id() == z.id()) throw InvalidArgumentError("GPU multigrid: z = B r needs distinct buffers r and z");
    const GpuBuffer* result = vcycle(0, r, &z, &levels_[0]->y);
    if (result != &z) z.copy_from(*result);
}

GpuBuffer* GpuMultigridPreconditioner::vcycle(size_t l, const GpuBuffer& b, GpuBuffer* x, GpuBuffer* other) {
    Level& level = *levels_[l];
    if (l + 1 == levels_.size()) {
        // The exact coarsest solve on the host (see the header for why).
        b.read(0, coarse_b_.size() * sizeof(float), coarse_b_.data());
        preconditioner_.solve_coarsest_rgb(coarse_b_, coarse_x_);
        x->write(0, coarse_x_.size() * sizeof(float), coarse_x_.data());
        return x;
    }
    const MultigridPreconditioner::Chebyshev& cheb = level.chebyshev;
    GpuKernels& K = kernels_;
    // Pre-smoothing from a zero start: x = d = inv_theta D^-1 b (x is not read, so y may be x).
    GpuKernels::SmoothingPass pass;
    pass.zero_start = pass.first_step = true;
    pass.c_r = cheb.inv_theta;
    K.multigrid_smooth(level.a, b, *x, level.inv_diag, level.d, *x, pass);
    auto chebyshev_steps = [&] {
        for (size_t s = 0; s < cheb.c_d.size(); ++s) {
            GpuKernels::SmoothingPass step;
            step.c_d = cheb.c_d[s];
            step.c_r = cheb.c_r[s];
            K.multigrid_smooth(level.a, b, *x, level.inv_diag, level.d, *other, step);
            std::swap(x, other);
        }
    };
    chebyshev_steps();
    // r = b - A x, restricted with P^T to the next level's right-hand side.
    K.multigrid_residual(level.a, b, *x, level.r);
    Level& next = *levels_[l + 1];
    K.interpolate(*level.pt, level.r, next.b);
    const GpuBuffer* coarse = vcycle(l + 1, next.b, &next.x, &next.y);
    K.interpolate(*level.p, *coarse, *x, /*accumulate=*/true);
    // Post-smoothing: the same polynomial from the corrected iterate.
    GpuKernels::SmoothingPass first;
    first.first_step = true;
    first.c_r = cheb.inv_theta;
    K.multigrid_smooth(level.a, b, *x, level.inv_diag, level.d, *other, first);
    std::swap(x, other);
    chebyshev_steps();
    return x;
}

void GpuMultigridPreconditioner::update_values(std::span<const int32_t> changed_rows) {
    const std::vector<std::vector<int32_t>> level_rows = preconditioner_.update_values(changed_rows);
    for (size_t l = 0; l < levels_.size() && l < level_rows.size(); ++l) {
        if (level_rows[l].empty()) continue;
        Level& level = *levels_[l];
        kernels_.upload_rows(level.a, level_view(preconditioner_, l), level_rows[l]);
        upload_inverse_diagonal(l, level_rows[l]);
        // The Gershgorin bound is a maximum over all rows: any changed row may move it.
        if (l + 1 < levels_.size()) level.chebyshev = preconditioner_.chebyshev(l);
    }
    check_gpu_error(kernels_.gl(), "updating the multigrid levels");
}

}  // namespace waxwork
