// The rgb diffusion matrix triple laid out for the GPU, in one of three sparse formats, and its
// device-resident copy.
//
//   Csr         row per thread, rows stored one after the other (the CPU layout). Neighbouring threads
//               read far-apart entries: uncoalesced on a GPU, cache-friendly on a CPU (llvmpipe).
//   Ell         ELLPACK: every row padded to the longest row, stored column-major (entry k of row i at
//               k * rows + i), so a warp reads consecutive words. Pays for padding: TransCut rows hold
//               the vertex and its one-ring (10-30 entries), the longest row sets the width.
//   SellCSigma  SELL-C-sigma (Kreutzer et al. 2014): ELLPACK per slice of C rows, rows sorted by length
//               within windows of sigma rows so a slice's rows have similar lengths; little padding,
//               coalesced reads. Output rows keep the original order (each slot knows its row).
// Values are interleaved by channel (r, g, b per stored entry) so one gather of a column serves the
// three systems, as in the CPU float path (solver/diffusion_solve.cpp). bench/gpu_solver_bench.cpp
// measures the three formats.
#pragma once

#include "gl/gpu_compute.h"
#include "solver/diffusion_matrix.h"

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace waxwork {

enum class GpuMatrixFormat { Csr, Ell, SellCSigma };

std::string to_string(GpuMatrixFormat format);

// The pattern and rgb values of a compressed-row matrix triple: a DiffusionMatrix, or a level of the
// multi-resolution hierarchy (multires/hierarchy.h). diagonal[i] is the position of (i, i).
struct RgbCsrView {
    std::span<const int32_t> offsets, columns, diagonal;
    std::array<std::span<const double>, 3> values;

    size_t rows() const { return diagonal.size(); }
    size_t nonzeros() const { return columns.size(); }
};

RgbCsrView rgb_csr_view(const DiffusionMatrix& matrix);

// Host-side description of the stored matrix (format independent for the kernels: ELL is SELL with one
// slice of all rows and no sorting).
struct GpuMatrixLayout {
    GpuMatrixFormat format = GpuMatrixFormat::Csr;
    uint32_t rows = 0;
    uint32_t slots = 0;         // threads of a product: rows (Csr, Ell) or rows rounded up to C (Sell)
    uint32_t slice_height = 0;  // C (Sell), rows (Ell), unused (Csr)
    // Csr: row offsets (rows + 1). Ell/Sell: first stored entry of each slice (slices + 1).
    std::vector<int32_t> starts;
    std::vector<int32_t> columns;    // per stored entry (padding: column 0 with value 0)
    std::vector<int32_t> slot_rows;  // Ell/Sell: the row a slot computes, -1 for padding; empty for Csr
    std::vector<int32_t> stored_index;  // per CSR entry of the DiffusionMatrix, its stored position
    std::vector<int32_t> diagonal;      // per row, the stored position of (i, i)

    size_t stored_entries() const { return columns.size(); }
};

// slice_height C and sigma apply to SellCSigma only (sigma is rounded up to a multiple of C).
GpuMatrixLayout make_gpu_matrix_layout(const RgbCsrView& matrix, GpuMatrixFormat format,
                                       uint32_t slice_height = 32, uint32_t sigma = 512);

// The three channels' values in stored order, interleaved (3 floats per stored entry, padding 0).
std::vector<float> gpu_matrix_values(const GpuMatrixLayout& layout, const RgbCsrView& matrix);

// A layout and its values on the device.
struct GpuMatrix {
    GpuMatrixLayout layout;
    GpuBuffer starts, columns, slot_rows, diagonal, values;

    GpuMatrix(const GlApi& gl, const RgbCsrView& matrix, GpuMatrixFormat format);
};

}  // namespace waxwork
