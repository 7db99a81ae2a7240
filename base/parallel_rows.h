// Parallel loops over independent rows (of a matrix, a vector, a mesh's tets): TBB splits the range
// into chunks of `grain` rows, large enough that scheduling costs less than the rows themselves.
// Sums use fixed chunks and a fixed combination order, so the same input gives bit-identical sums
// (and solver iterates) on any thread count: tests, `info` and frame-to-frame results rely on it.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace waxwork {

template <typename Body>
void for_rows(size_t n, size_t grain, const Body& body) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) body(i);
    });
}

// N sums over rows, body(i, sums) adding row i's terms: fixed chunks of `grain` rows and a fixed
// combination order, so the sums are bit-identical on any thread count.
template <size_t N, typename Body>
std::array<double, N> reduce_rows(size_t n, size_t grain, const Body& body) {
    using Sums = std::array<double, N>;
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<size_t>(0, n, grain), Sums{},
        [&](const tbb::blocked_range<size_t>& r, Sums acc) {
            // A fresh local per chunk, added once: the compiler keeps it in registers, where adding
            // into `acc` (which TBB passes through memory) made one-channel CG a fifth slower.
            Sums chunk{};
            for (size_t i = r.begin(); i != r.end(); ++i) body(i, chunk);
            for (size_t k = 0; k < N; ++k) acc[k] += chunk[k];
            return acc;
        },
        [](Sums a, const Sums& b) {
            for (size_t k = 0; k < N; ++k) a[k] += b[k];
            return a;
        },
        tbb::simple_partitioner());
}

// One sum over rows, body(i) giving row i's term.
template <typename Body>
double sum_rows(size_t n, size_t grain, const Body& body) {
    return reduce_rows<1>(n, grain, [&](size_t i, std::array<double, 1>& sum) { sum[0] += body(i); })[0];
}

// Compressed rows whose lengths are only known once each row is built, in one pass: rows are built
// in fixed chunks of `chunk_rows` (so the result does not depend on the thread count), each chunk
// appending its rows to its own Buffer with append_row(row, buffer), which returns the row's length;
// once `offsets` (rows + 1 prefix sums) are known, size_entries(total) sizes the destination and
// place_chunk(chunk, buffer) copies each chunk's entries into place, from offsets[chunk * chunk_rows]
// on. Building every row twice (count, then fill) would walk it twice; this walks it once and copies
// the entries once.
template <typename Buffer, typename AppendRow, typename SizeEntries, typename PlaceChunk>
void build_rows_in_chunks(size_t rows, size_t chunk_rows, std::vector<int32_t>& offsets, const AppendRow& append_row,
                          const SizeEntries& size_entries, const PlaceChunk& place_chunk) {
    const size_t chunks = (rows + chunk_rows - 1) / chunk_rows;
    std::vector<Buffer> buffers(chunks);
    offsets.assign(rows + 1, 0);
    tbb::parallel_for(size_t{0}, chunks, [&](size_t chunk) {
        for (size_t row = chunk * chunk_rows; row < std::min(rows, (chunk + 1) * chunk_rows); ++row)
            offsets[row + 1] = static_cast<int32_t>(append_row(row, buffers[chunk]));
    });
    for (size_t row = 0; row < rows; ++row) offsets[row + 1] += offsets[row];
    size_entries(static_cast<size_t>(offsets[rows]));
    tbb::parallel_for(size_t{0}, chunks,
                      [&](size_t chunk) { place_chunk(chunk, static_cast<const Buffer&>(buffers[chunk])); });
}

// The same when each row's entries are one array: append_row(row, buffer) appends the row's entries
// to a std::vector<T>.
template <typename T, typename AppendRow>
void build_rows_in_chunks(size_t rows, size_t chunk_rows, std::vector<int32_t>& offsets, std::vector<T>& entries,
                          const AppendRow& append_row) {
    build_rows_in_chunks<std::vector<T>>(
        rows, chunk_rows, offsets,
        [&](size_t row, std::vector<T>& buffer) {
            const size_t before = buffer.size();
            append_row(row, buffer);
            return buffer.size() - before;
        },
        [&](size_t total) { entries.resize(total); },
        [&](size_t chunk, const std::vector<T>& buffer) {
            std::copy(buffer.begin(), buffer.end(), entries.begin() + static_cast<std::ptrdiff_t>(offsets[chunk * chunk_rows]));
        });
}

}  // namespace waxwork
