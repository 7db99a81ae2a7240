#include "solver/reference/first_hit_grid.h"

#include "base/error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace waxwork {

namespace {

constexpr double kCellsPerTriangle = 2.0;
constexpr int kMaxCellsPerAxis = 256;

// Möller-Trumbore in double: t, u, v when the ray hits the triangle.
bool intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, const Eigen::Vector3d& v0,
               const Eigen::Vector3d& v1, const Eigen::Vector3d& v2, double& t, double& u, double& v) {
    const Eigen::Vector3d e1 = v1 - v0, e2 = v2 - v0;
    const Eigen::Vector3d p = direction.cross(e2);
    const double det = e1.dot(p);
    if (det == 0) return false;
    const Eigen::Vector3d s = origin - v0;
    u = s.dot(p) / det;
    if (u < 0 || u > 1) return false;
    const Eigen::Vector3d q = s.cross(e1);
    v = direction.dot(q) / det;
    if (v < 0 || u + v > 1) return false;
    t = e2.dot(q) / det;
    return t > 0;
}

}  // namespace

FirstHitGrid::FirstHitGrid(const std::vector<Eigen::Vector3d>& points, const std::vector<std::array<int32_t, 3>>& triangles)
    : points_(points), triangles_(triangles) {
    for (const Eigen::Vector3d& p : points_)
        if (!p.allFinite()) throw InvalidArgumentError("first-hit grid: a point is not finite");
    for (size_t t = 0; t < triangles_.size(); ++t)
        for (int32_t v : triangles_[t])
            if (v < 0 || static_cast<size_t>(v) >= points_.size())
                throw InvalidArgumentError("first-hit grid: triangle " + std::to_string(t) + " indexes outside the points");
    for (const auto& tri : triangles_)
        for (int32_t v : tri) box_.extend(points_[v]);
    if (triangles_.empty()) return;
    // Pad so that flat boxes (a single plane) still have a thickness to divide.
    const double pad = 1e-9 * std::max(1.0, box_.diagonal().norm());
    box_.min().array() -= pad;
    box_.max().array() += pad;
    const Eigen::Vector3d extent = box_.diagonal();
    const double volume = std::max(extent.prod(), 1e-300);
    const double h = std::cbrt(volume / (kCellsPerTriangle * triangles_.size()));
    for (int k = 0; k < 3; ++k) {
        cells_[k] = std::clamp(static_cast<int>(std::ceil(extent[k] / h)), 1, kMaxCellsPerAxis);
        cell_size_[k] = extent[k] / cells_[k];
    }
    auto cell_range = [&](const std::array<int32_t, 3>& tri, std::array<int, 3>& lo, std::array<int, 3>& hi) {
        Eigen::AlignedBox3d b;
        for (int32_t v : tri) b.extend(points_[v]);
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::clamp(static_cast<int>(std::floor((b.min()[k] - box_.min()[k]) / cell_size_[k])), 0, cells_[k] - 1);
            hi[k] = std::clamp(static_cast<int>(std::floor((b.max()[k] - box_.min()[k]) / cell_size_[k])), 0, cells_[k] - 1);
        }
    };
    const size_t cell_count = static_cast<size_t>(cells_[0]) * cells_[1] * cells_[2];
    cell_start_.assign(cell_count + 1, 0);
    auto for_cells = [&](const std::array<int32_t, 3>& tri, auto&& visit) {
        std::array<int, 3> lo, hi;
        cell_range(tri, lo, hi);
        for (int z = lo[2]; z <= hi[2]; ++z)
            for (int y = lo[1]; y <= hi[1]; ++y)
                for (int x = lo[0]; x <= hi[0]; ++x) visit((static_cast<size_t>(z) * cells_[1] + y) * cells_[0] + x);
    };
    for (const auto& tri : triangles_) for_cells(tri, [&](size_t cell) { ++cell_start_[cell + 1]; });
    for (size_t c = 0; c < cell_count; ++c) cell_start_[c + 1] += cell_start_[c];
    cell_items_.resize(cell_start_.back());
    std::vector<int32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (size_t t = 0; t < triangles_.size(); ++t)
        for_cells(triangles_[t], [&](size_t cell) { cell_items_[fill[cell]++] = static_cast<int32_t>(t); });
}

std::optional<FirstHitGrid::Hit> FirstHitGrid::first_hit(const Eigen::Vector3d& origin,
                                                         const Eigen::Vector3d& direction) const {
    if (triangles_.empty()) return std::nullopt;
    // The part of the ray inside the grid's box (slab test).
    double t_enter = 0, t_leave = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
        if (direction[k] == 0) {
            if (origin[k] < box_.min()[k] || origin[k] > box_.max()[k]) return std::nullopt;
            continue;
        }
        double a = (box_.min()[k] - origin[k]) / direction[k], b = (box_.max()[k] - origin[k]) / direction[k];
        if (a > b) std::swap(a, b);
        t_enter = std::max(t_enter, a);
        t_leave = std::min(t_leave, b);
    }
    if (!(t_enter <= t_leave)) return std::nullopt;

    const Eigen::Vector3d start = origin + t_enter * direction;
    std::array<int, 3> cell, step;
    std::array<double, 3> t_next, t_delta;
    for (int k = 0; k < 3; ++k) {
        cell[k] = std::clamp(static_cast<int>(std::floor((start[k] - box_.min()[k]) / cell_size_[k])), 0, cells_[k] - 1);
        if (direction[k] > 0) {
            step[k] = 1;
            t_next[k] = (box_.min()[k] + (cell[k] + 1) * cell_size_[k] - origin[k]) / direction[k];
            t_delta[k] = cell_size_[k] / direction[k];
        } else if (direction[k] < 0) {
            step[k] = -1;
            t_next[k] = (box_.min()[k] + cell[k] * cell_size_[k] - origin[k]) / direction[k];
            t_delta[k] = -cell_size_[k] / direction[k];
        } else {
            step[k] = 0;
            t_next[k] = t_delta[k] = std::numeric_limits<double>::infinity();
        }
    }
    std::optional<Hit> best;
    while (true) {
        const size_t index = (static_cast<size_t>(cell[2]) * cells_[1] + cell[1]) * cells_[0] + cell[0];
        for (int32_t i = cell_start_[index]; i < cell_start_[index + 1]; ++i) {
            const auto& tri = triangles_[cell_items_[i]];
            double t, u, v;
            if (intersect(origin, direction, points_[tri[0]], points_[tri[1]], points_[tri[2]], t, u, v) &&
                (!best || t < best->t))
                best = Hit{cell_items_[i], t, u, v};
        }
        const int axis = t_next[0] < t_next[1] ? (t_next[0] < t_next[2] ? 0 : 2) : (t_next[1] < t_next[2] ? 1 : 2);
        // A hit before the cell's far side cannot be beaten by a later cell.
        if (best && best->t <= t_next[axis]) return best;
        if (t_next[axis] > t_leave) return best;
        cell[axis] += step[axis];
        if (cell[axis] < 0 || cell[axis] >= cells_[axis]) return best;
        t_next[axis] += t_delta[axis];
    }
}

}  // namespace waxwork
