#include "solver/warm_start.h"

#include "base/error.h"

#include <string>

namespace waxwork {

CarriedValues carry_through_vertex_map(const std::array<std::vector<double>, 3>& before,
                                       std::span<const int32_t> new_of_old, size_t vertices_after) {
    if (new_of_old.size() != before[0].size())
        throw InvalidArgumentError("warm start: a vertex map of " + std::to_string(new_of_old.size()) + " entries for " +
                                   std::to_string(before[0].size()) + " values");
    CarriedValues after;
    for (auto& channel : after.values) channel.assign(vertices_after, 0.0);
    after.known.assign(vertices_after, 0);
    for (size_t v = 0; v < new_of_old.size(); ++v) {
        const int32_t to = new_of_old[v];
        if (to < 0 || static_cast<size_t>(to) >= vertices_after) continue;
        for (size_t c = 0; c < 3; ++c) after.values[c][static_cast<size_t>(to)] = before[c][v];
        after.known[static_cast<size_t>(to)] = 1;
    }
    return after;
}

CarriedValues carry_through_origins(const std::array<std::vector<double>, 3>& before,
                                    std::span<const VertexOrigin> origins) {
    const size_t n_before = before[0].size(), n = origins.size();
    CarriedValues after;
    for (auto& channel : after.values) channel.assign(n, 0.0);
    after.known.assign(n, 0);
    for (size_t v = 0; v < n; ++v) {
        const auto [a, b, t] = origins[v];
        const auto known = [&](int32_t i) {
            return i >= 0 && (static_cast<size_t>(i) < n_before || (static_cast<size_t>(i) < v && after.known[static_cast<size_t>(i)]));
        };
        if (!known(a) || !known(b) || !(t >= 0.0 && t <= 1.0)) continue;
        for (size_t c = 0; c < 3; ++c) {
            const auto value = [&](int32_t i) {
                const auto u = static_cast<size_t>(i);
                return u < n_before ? before[c][u] : after.values[c][u];
            };
            after.values[c][v] = (1 - t) * value(a) + t * value(b);
        }
        after.known[v] = 1;
    }
    return after;
}

size_t extend_to_unknown_vertices(const DiffusionMatrix& matrix, std::span<const uint8_t> known,
                                  std::array<std::vector<double>, 3>& values) {
    const size_t n = matrix.size();
    if (known.size() != n)
        throw InvalidArgumentError("warm start: " + std::to_string(known.size()) + " flags for a " + std::to_string(n) +
                                   "-row matrix");
    for (const auto& channel : values)
        if (channel.size() != n)
            throw InvalidArgumentError("warm start: " + std::to_string(channel.size()) + " values for a " +
                                       std::to_string(n) + "-row matrix");
    // level[v]: 0 known, k > 0 filled in the k-th pass, -1 not reached yet.
    std::vector<int32_t> level(n);
    std::vector<int32_t> frontier;
    for (size_t v = 0; v < n; ++v) level[v] = known[v] ? 0 : -1;
    for (size_t v = 0; v < n; ++v) {
        if (level[v] == 0) continue;
        for (int32_t k = matrix.offsets[v]; k < matrix.offsets[v + 1]; ++k)
            if (level[static_cast<size_t>(matrix.columns[static_cast<size_t>(k)])] == 0) {
                frontier.push_back(static_cast<int32_t>(v));
                break;
            }
    }
    size_t filled = 0;
    for (int32_t pass = 1; !frontier.empty(); ++pass) {
        // Means over the neighbours of earlier passes only, so the order within a pass does not matter.
        for (const int32_t v : frontier) level[static_cast<size_t>(v)] = pass;
        for (const int32_t v : frontier) {
            std::array<double, 3> sum{};
            int count = 0;
            for (int32_t k = matrix.offsets[static_cast<size_t>(v)]; k < matrix.offsets[static_cast<size_t>(v) + 1]; ++k) {
                const auto j = static_cast<size_t>(matrix.columns[static_cast<size_t>(k)]);
                if (level[j] < 0 || level[j] >= pass) continue;
                for (size_t c = 0; c < 3; ++c) sum[c] += values[c][j];
                ++count;
            }
            for (size_t c = 0; c < 3; ++c) values[c][static_cast<size_t>(v)] = sum[c] / count;  // count >= 1
        }
        filled += frontier.size();
        std::vector<int32_t> next;
        for (const int32_t v : frontier)
            for (int32_t k = matrix.offsets[static_cast<size_t>(v)]; k < matrix.offsets[static_cast<size_t>(v) + 1]; ++k) {
                const int32_t j = matrix.columns[static_cast<size_t>(k)];
                if (level[static_cast<size_t>(j)] != -1) continue;
                level[static_cast<size_t>(j)] = -2;  // queued for the next pass
                next.push_back(j);
            }
        frontier = std::move(next);
    }
    return filled;
}

}  // namespace waxwork
