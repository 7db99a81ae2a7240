#include "tetops/spatial_order.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <numeric>

namespace waxwork {
namespace {

// Spreads the low 21 bits of x so that two zero bits separate consecutive bits (3D Morton code).
uint64_t spread_bits(uint64_t x) {
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffULL;
    x = (x | x << 16) & 0x1f0000ff0000ffULL;
    x = (x | x << 8) & 0x100f00f00f00f00fULL;
    x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
    x = (x | x << 2) & 0x1249249249249249ULL;
    return x;
}

template <typename T>
void permute(std::vector<T>& values, const std::vector<int32_t>& new_to_old) {
    if (values.empty()) return;
    std::vector<T> permuted(new_to_old.size());
    for (size_t i = 0; i < new_to_old.size(); ++i) permuted[i] = values[new_to_old[i]];
    values = std::move(permuted);
}

}  // namespace

void sort_spatially(TetMesh& mesh) {
    if (mesh.tets.empty()) return;
    const auto [lo, hi] = bounding_box(mesh);
    const Eigen::Vector3d extent = (hi - lo).cwiseMax(1e-300);
    constexpr double kCells = double((1 << 21) - 1);
    std::vector<std::pair<uint64_t, int32_t>> keys(mesh.tets.size());
    tbb::parallel_for(size_t{0}, mesh.tets.size(), [&](size_t t) {
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (int32_t v : mesh.tets[t]) centroid += mesh.positions[v];
        const Eigen::Vector3d unit = ((centroid / 4.0 - lo).cwiseQuotient(extent) * kCells).cwiseMax(0.0).cwiseMin(kCells);
        keys[t] = {spread_bits(static_cast<uint64_t>(unit.x())) | spread_bits(static_cast<uint64_t>(unit.y())) << 1 |
                       spread_bits(static_cast<uint64_t>(unit.z())) << 2,
                   static_cast<int32_t>(t)};
    });
    tbb::parallel_sort(keys.begin(), keys.end());  // ties broken by tet index: deterministic

    std::vector<int32_t> tet_order(keys.size());
    for (size_t i = 0; i < keys.size(); ++i) tet_order[i] = keys[i].second;
    permute(mesh.tets, tet_order);
    permute(mesh.materials, tet_order);
    permute(mesh.piece_ids, tet_order);

    std::vector<int32_t> new_index(mesh.positions.size(), -1), vertex_order;
    vertex_order.reserve(mesh.positions.size());
    for (Tet& tet : mesh.tets)
        for (int32_t& v : tet) {
            if (new_index[v] < 0) {
                new_index[v] = static_cast<int32_t>(vertex_order.size());
                vertex_order.push_back(v);
            }
            v = new_index[v];
        }
    for (size_t v = 0; v < new_index.size(); ++v)  // keep unreferenced vertices, at the end
        if (new_index[v] < 0) vertex_order.push_back(static_cast<int32_t>(v));
    permute(mesh.positions, vertex_order);
    std::iota(mesh.original_ids.begin(), mesh.original_ids.end(), 0);
}

}  // namespace waxwork
