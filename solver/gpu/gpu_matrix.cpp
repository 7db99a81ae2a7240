#include "solver/gpu/gpu_matrix.h"

#include <algorithm>
#include <numeric>

namespace waxwork {

std::string to_string(GpuMatrixFormat format) {
    switch (format) {
        case GpuMatrixFormat::Csr: return "csr";
        case GpuMatrixFormat::Ell: return "ell";
        case GpuMatrixFormat::SellCSigma: return "sell-c-sigma";
    }
    return "?";
}

RgbCsrView rgb_csr_view(const DiffusionMatrix& m) {
    return {m.offsets, m.columns, m.diagonal, {m.values[0], m.values[1], m.values[2]}};
}

GpuMatrixLayout make_gpu_matrix_layout(const RgbCsrView& m, GpuMatrixFormat format, uint32_t slice_height,
                                       uint32_t sigma) {
    const auto n = static_cast<uint32_t>(m.rows());
    GpuMatrixLayout layout;
    layout.format = format;
    layout.rows = n;
    layout.stored_index.resize(m.nonzeros());
    layout.diagonal.resize(n);
    if (format == GpuMatrixFormat::Csr) {
        layout.slots = n;
        layout.starts.assign(m.offsets.begin(), m.offsets.end());
        layout.columns.assign(m.columns.begin(), m.columns.end());
        std::iota(layout.stored_index.begin(), layout.stored_index.end(), 0);
        layout.diagonal.assign(m.diagonal.begin(), m.diagonal.end());
        return layout;
    }
    if (format == GpuMatrixFormat::Ell) {
        slice_height = std::max<uint32_t>(n, 1);
        sigma = 1;
    } else {
        if (slice_height == 0) throw InvalidArgumentError("SELL-C-sigma: the slice height C must be positive");
        sigma = std::max(slice_height, (sigma + slice_height - 1) / slice_height * slice_height);
    }
    const uint32_t slices = (n + slice_height - 1) / slice_height;
    layout.slice_height = slice_height;
    layout.slots = slices * slice_height;
    auto length = [&](int32_t row) { return m.offsets[row + 1] - m.offsets[row]; };
    // Slot order: rows sorted by decreasing length within each sigma window (stable: ties keep order).
    std::vector<int32_t> order(n);
    std::iota(order.begin(), order.end(), 0);
    if (sigma > 1)
        for (uint32_t w = 0; w < n; w += sigma)
            std::stable_sort(order.begin() + w, order.begin() + std::min(n, w + sigma),
                             [&](int32_t a, int32_t b) { return length(a) > length(b); });
    layout.slot_rows.assign(layout.slots, -1);
    std::copy(order.begin(), order.end(), layout.slot_rows.begin());
    layout.starts.assign(slices + 1, 0);
    for (uint32_t s = 0; s < slices; ++s) {
        int32_t width = 0;
        for (uint32_t lane = 0; lane < slice_height; ++lane) {
            const int32_t row = layout.slot_rows[s * slice_height + lane];
            if (row >= 0) width = std::max(width, length(row));
        }
        layout.starts[s + 1] = layout.starts[s] + width * static_cast<int32_t>(slice_height);
    }
    layout.columns.assign(static_cast<size_t>(layout.starts[slices]), 0);
    for (uint32_t t = 0; t < layout.slots; ++t) {
        const int32_t row = layout.slot_rows[t];
        if (row < 0) continue;
        const uint32_t s = t / slice_height, lane = t % slice_height;
        for (int32_t k = m.offsets[row]; k < m.offsets[row + 1]; ++k) {
            const int32_t stored = layout.starts[s] + (k - m.offsets[row]) * static_cast<int32_t>(slice_height) +
                                   static_cast<int32_t>(lane);
            layout.columns[stored] = m.columns[k];
            layout.stored_index[k] = stored;
        }
        layout.diagonal[row] = layout.stored_index[m.diagonal[row]];
    }
    return layout;
}

std::vector<float> gpu_matrix_values(const GpuMatrixLayout& layout, const RgbCsrView& m) {
    std::vector<float> values(3 * layout.stored_entries(), 0.0f);
    for (size_t k = 0; k < m.nonzeros(); ++k)
        for (int c = 0; c < 3; ++c)
            values[3 * static_cast<size_t>(layout.stored_index[k]) + c] = static_cast<float>(m.values[c][k]);
    return values;
}

GpuMatrix::GpuMatrix(const GlApi& gl, const RgbCsrView& matrix, GpuMatrixFormat format)
    : layout(make_gpu_matrix_layout(matrix, format)) {
    starts = GpuBuffer::from<int32_t>(gl, layout.starts);
    columns = GpuBuffer::from<int32_t>(gl, layout.columns);
    slot_rows = GpuBuffer::from<int32_t>(gl, layout.slot_rows);
    diagonal = GpuBuffer::from<int32_t>(gl, layout.diagonal);
    values = GpuBuffer::from<float>(gl, gpu_matrix_values(layout, matrix));
}

}  // namespace waxwork
