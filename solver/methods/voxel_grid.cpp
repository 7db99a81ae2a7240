#include "solver/methods/voxel_grid.h"

#include "base/error.h"
#include "solver/reference/first_hit_grid.h"

#include <Eigen/Dense>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>

namespace waxwork {
namespace {

// Barycentric tolerance of the point location: a centre on a shared face (or a hair outside the
// volume's surface through rounding) still finds a tet.
constexpr double kInsideTolerance = 1e-10;
// The smallest crossing fraction stored: a centre exactly on the boundary would give 0.
constexpr double kMinFraction = 1e-6;

Eigen::Vector3f to_float(const Eigen::Vector3d& p) { return p.cast<float>(); }

struct Exit {
    int32_t tet;
    int local_face;
    double t;  // along the ray, in units of |direction|
};

// Walks from `start` (which contains `from`) along from + t direction, t > 0, through face
// neighbours until it leaves the volume: the tet and local face it leaves by. Every tet is entered by
// the same ray, so rounding does not accumulate; nullopt for a walk that stalls (a degenerate tet or a
// loop through an edge the ray grazes).
std::optional<Exit> walk_to_boundary(const TetMesh& mesh, const TetConnectivity& connectivity, int32_t start,
                                     const Eigen::Vector3d& from, const Eigen::Vector3d& direction) {
    constexpr int kMaxSteps = 4096;
    int32_t tet = start;
    double t_in = 0;
    for (int step = 0; step < kMaxSteps; ++step) {
        const Tet& v = mesh.tets[tet];
        const Eigen::Vector3d& a = mesh.positions[v[0]];
        Eigen::Matrix3d edges;
        edges << mesh.positions[v[1]] - a, mesh.positions[v[2]] - a, mesh.positions[v[3]] - a;
        const Eigen::Matrix3d inverse = edges.inverse();
        if (!inverse.allFinite()) return std::nullopt;
        const Eigen::Vector3d b = inverse * (from - a), db = inverse * direction;
        const std::array<double, 4> lambda = {1 - b.sum(), b[0], b[1], b[2]};
        const std::array<double, 4> rate = {-db.sum(), db[0], db[1], db[2]};
        int exit_face = -1;
        double t_exit = std::numeric_limits<double>::infinity();
        for (int k = 0; k < 4; ++k) {
            if (rate[k] >= 0) continue;
            const double t = -lambda[k] / rate[k];
            if (t < t_exit) {
                t_exit = t;
                exit_face = k;
            }
        }
        if (exit_face < 0) return std::nullopt;
        t_in = std::max(t_in, t_exit);
        const int32_t next = connectivity.tet_neighbors[tet][exit_face];
        if (next < 0) return Exit{tet, exit_face, t_in};
        tet = next;
    }
    return std::nullopt;
}

// Barycentric weights of the point on triangle `corners` nearest to `x` (clamped to the triangle).
std::array<double, 3> face_barycentrics(const TetMesh& mesh, const std::array<int32_t, 3>& corners,
                                        const Eigen::Vector3d& x) {
    const Eigen::Vector3d& a = mesh.positions[corners[0]];
    const Eigen::Vector3d e1 = mesh.positions[corners[1]] - a, e2 = mesh.positions[corners[2]] - a;
    Eigen::Matrix2d gram;
    gram << e1.dot(e1), e1.dot(e2), e1.dot(e2), e2.dot(e2);
    const Eigen::Vector2d uv = gram.ldlt().solve(Eigen::Vector2d(e1.dot(x - a), e2.dot(x - a)));
    double u = std::clamp(uv[0], 0.0, 1.0), w = std::clamp(uv[1], 0.0, 1.0);
    if (u + w > 1) {
        const double sum = u + w;
        u /= sum;
        w /= sum;
    }
    return {1 - u - w, u, w};
}

}  // namespace

VoxelGrid voxelize(const MethodProblem& problem, double cell_size_mm, size_t max_cells) {
    const TetMesh& mesh = problem.mesh;
    if (!(cell_size_mm > 0) || !std::isfinite(cell_size_mm))
        throw InvalidArgumentError("voxel grid: cell size " + number_text(cell_size_mm) +
                                   " mm must be a positive finite number");
    if (!(problem.mm_per_unit > 0) || !std::isfinite(problem.mm_per_unit))
        throw InvalidArgumentError("voxel grid: mm per unit " + number_text(problem.mm_per_unit) +
                                   " must be a positive finite number");
    if (mesh.tets.empty()) throw InvalidArgumentError("voxel grid: the volume has no tets");
    if (problem.q.size() != mesh.vertex_count() || problem.connectivity.tet_neighbors.size() != mesh.tet_count())
        throw InvalidArgumentError("voxel grid: " + std::to_string(problem.q.size()) + " q values and connectivity of " +
                                   std::to_string(problem.connectivity.tet_neighbors.size()) + " tets for " +
                                   std::to_string(mesh.vertex_count()) + " vertices and " +
                                   std::to_string(mesh.tet_count()) + " tets");

    VoxelGrid grid;
    const double h = cell_size_mm / problem.mm_per_unit;
    grid.cell_size = h;
    const auto [lo, hi] = bounding_box(mesh);
    const Eigen::Vector3d extent = hi - lo;
    // A cell size that brings `count` under `cap` (cells scale as the inverse cube of the size).
    const auto fitting_size = [&](double count, size_t cap) {
        return number_text(cell_size_mm * std::cbrt(count / static_cast<double>(cap)) * 1.01);
    };
    std::array<double, 3> counts{};
    for (int k = 0; k < 3; ++k) counts[k] = std::max(1.0, std::ceil(extent[k] / h));
    const double voxels = counts[0] * counts[1] * counts[2];  // in double: no overflow for tiny cells
    if (voxels > static_cast<double>(kMaxVoxelGridVoxels))
        throw InvalidArgumentError("voxel grid: cell size " + number_text(cell_size_mm) + " mm gives " +
                                   number_text(voxels) + " voxels over the volume's box, more than " +
                                   std::to_string(kMaxVoxelGridVoxels) + "; use " +
                                   fitting_size(voxels, kMaxVoxelGridVoxels) + " mm or more");
    for (int k = 0; k < 3; ++k) grid.dims[k] = static_cast<int>(counts[k]);
    grid.origin = 0.5 * (lo + hi) - 0.5 * h * Eigen::Vector3d(grid.dims[0], grid.dims[1], grid.dims[2]);
    const size_t voxel_count = static_cast<size_t>(grid.dims[0]) * grid.dims[1] * grid.dims[2];
    const auto voxel_index = [&](int i, int j, int k) {
        return static_cast<size_t>(i) + static_cast<size_t>(grid.dims[0]) * (j + static_cast<size_t>(grid.dims[1]) * k);
    };

    // Point location: every tet tests the centres inside its box; the lowest tet wins a shared centre.
    std::vector<int32_t> voxel_tet(voxel_count, std::numeric_limits<int32_t>::max());
    tbb::parallel_for(size_t{0}, mesh.tets.size(), [&](size_t t) {
        const Tet& tet = mesh.tets[t];
        const Eigen::Vector3d& a = mesh.positions[tet[0]];
        Eigen::Matrix3d edges;
        edges << mesh.positions[tet[1]] - a, mesh.positions[tet[2]] - a, mesh.positions[tet[3]] - a;
        const Eigen::Matrix3d to_barycentric = edges.inverse();
        if (!to_barycentric.allFinite()) return;
        Eigen::Vector3d box_lo = a, box_hi = a;
        for (int v = 1; v < 4; ++v) {
            box_lo = box_lo.cwiseMin(mesh.positions[tet[v]]);
            box_hi = box_hi.cwiseMax(mesh.positions[tet[v]]);
        }
        std::array<int, 3> first{}, last{};
        for (int k = 0; k < 3; ++k) {
            first[k] = std::max(0, static_cast<int>(std::ceil((box_lo[k] - grid.origin[k]) / h - 0.5)));
            last[k] = std::min(grid.dims[k] - 1, static_cast<int>(std::floor((box_hi[k] - grid.origin[k]) / h - 0.5)));
        }
        for (int k = first[2]; k <= last[2]; ++k)
            for (int j = first[1]; j <= last[1]; ++j)
                for (int i = first[0]; i <= last[0]; ++i) {
                    const Eigen::Vector3d centre = grid.origin + (Eigen::Vector3d(i, j, k) + Eigen::Vector3d::Constant(0.5)) * h;
                    const Eigen::Vector3d b = to_barycentric * (centre - a);
                    if (b.minCoeff() < -kInsideTolerance || b.sum() > 1 + kInsideTolerance) continue;
                    std::atomic_ref<int32_t> slot(voxel_tet[voxel_index(i, j, k)]);
                    int32_t current = slot.load(std::memory_order_relaxed);
                    const int32_t mine = static_cast<int32_t>(t);
                    while (mine < current && !slot.compare_exchange_weak(current, mine, std::memory_order_relaxed)) {
                    }
                }
    });
    check_cancelled(problem.progress);

    grid.cell_of_voxel.assign(voxel_count, -1);
    for (int k = 0; k < grid.dims[2]; ++k)
        for (int j = 0; j < grid.dims[1]; ++j)
            for (int i = 0; i < grid.dims[0]; ++i) {
                const size_t v = voxel_index(i, j, k);
                if (voxel_tet[v] == std::numeric_limits<int32_t>::max()) continue;
                grid.cell_of_voxel[v] = static_cast<int32_t>(grid.cell_tet.size());
                grid.cell_tet.push_back(voxel_tet[v]);
                grid.cell_coords.push_back({i, j, k});
            }
    voxel_tet = {};
    const size_t cells = grid.cell_tet.size();
    if (cells > max_cells)
        throw InvalidArgumentError("voxel grid: cell size " + number_text(cell_size_mm) + " mm gives " +
                                   std::to_string(cells) + " cells inside the volume, more than " +
                                   std::to_string(max_cells) + "; use " + fitting_size(static_cast<double>(cells), max_cells) +
                                   " mm or more");

    // The boundary faces, for segment tests (float BVH, any hit) and crossings (double, nearest hit).
    const std::vector<BoundaryFace>& faces = problem.connectivity.boundary_faces;
    std::vector<std::array<int32_t, 3>> triangles(faces.size());
    for (size_t f = 0; f < faces.size(); ++f) triangles[f] = faces[f].vertices;
    std::vector<Eigen::Vector3f> points(mesh.positions.size());
    for (size_t v = 0; v < points.size(); ++v) points[v] = to_float(mesh.positions[v]);
    grid.boundary_bvh = std::make_shared<const TriangleBvh>(points, triangles);
    const TriangleBvh& bvh = *grid.boundary_bvh;

    // Interior links, decided once per pair (from the cell on the negative side) so both ends agree.
    for (auto& n : grid.neighbor) n.assign(cells, -1);
    tbb::parallel_for(size_t{0}, cells, [&](size_t c) {
        const auto& coords = grid.cell_coords[c];
        const Eigen::Vector3f from = to_float(grid.cell_centre(static_cast<int32_t>(c)));
        for (int d = 0; d < 6; d += 2) {
            const auto& step = kVoxelDirections[d];
            const int32_t other = grid.cell_at(coords[0] + step[0], coords[1] + step[1], coords[2] + step[2]);
            if (other < 0) continue;
            const Eigen::Vector3f to = to_float(grid.cell_centre(other));
            if (bvh.occluded(from, to - from, 0.0f, 1.0f)) continue;
            grid.neighbor[d][c] = other;
            grid.neighbor[d + 1][other] = static_cast<int32_t>(c);
        }
    });
    check_cancelled(problem.progress);

    for (size_t c = 0; c < cells; ++c)
        for (int d = 0; d < 6; ++d)
            if (grid.neighbor[d][c] < 0) {
                VoxelLink link;
                link.cell = static_cast<int32_t>(c);
                link.direction = static_cast<int8_t>(d);
                grid.boundary_links.push_back(link);
            }

    // Crossings. The walk through the tets from the cell's own tet leaves its piece by the piece's
    // own face even where another piece's face coincides with it (a crack), which a nearest-hit query
    // could not tell apart; the nearest hit along the link is the fallback for a walk that fails. A
    // link the float segment test called blocked can cross a rounding beyond the neighbour's centre:
    // fraction 1. A link with neither (no face along it at all) keeps fraction 1, its cell's tet, no
    // incident light and a zero normal.
    std::vector<Eigen::Vector3d> double_points(mesh.positions.begin(), mesh.positions.end());
    const FirstHitGrid first_hit(double_points, triangles);
    std::vector<std::array<int32_t, 4>> face_index(mesh.tets.size(), {-1, -1, -1, -1});
    for (size_t f = 0; f < faces.size(); ++f) face_index[faces[f].tet][faces[f].local_face] = static_cast<int32_t>(f);
    tbb::parallel_for(size_t{0}, grid.boundary_links.size(), [&](size_t l) {
        VoxelLink& link = grid.boundary_links[l];
        link.tet = grid.cell_tet[link.cell];
        const auto& step = kVoxelDirections[link.direction];
        const Eigen::Vector3d from = grid.cell_centre(link.cell);
        const Eigen::Vector3d direction = h * Eigen::Vector3d(step[0], step[1], step[2]);
        int32_t face = -1;
        double t = 0;
        if (const auto exit = walk_to_boundary(mesh, problem.connectivity, link.tet, from, direction)) {
            face = face_index[exit->tet][exit->local_face];
            t = exit->t;
        }
        if (face < 0) {
            const auto hit = first_hit.first_hit(from, direction);
            if (!hit) return;
            face = hit->triangle;
            t = hit->t;
        }
        const BoundaryFace& crossed = faces[face];
        link.fraction = std::clamp(t, kMinFraction, 1.0);
        link.tet = crossed.tet;
        const Eigen::Vector3d& a = mesh.positions[crossed.vertices[0]];
        const Eigen::Vector3d n =
            (mesh.positions[crossed.vertices[1]] - a).cross(mesh.positions[crossed.vertices[2]] - a).normalized();
        if (n.allFinite()) link.normal = {n.x(), n.y(), n.z()};
        const std::array<double, 3> w = face_barycentrics(mesh, crossed.vertices, from + t * direction);
        for (int ch = 0; ch < 3; ++ch)
            for (int i = 0; i < 3; ++i) link.q[ch] += w[i] * problem.q[crossed.vertices[i]][ch];
    });
    return grid;
}

VertexSampling build_vertex_sampling(const VoxelGrid& grid, const MethodProblem& problem) {
    const TetMesh& mesh = problem.mesh;
    const TetConnectivity& connectivity = problem.connectivity;
    enum Case : uint8_t { kNone, kTrilinear, kFitted, kNearest, kUnsampled };
    std::vector<uint8_t> how(mesh.positions.size(), kNone);
    // Per vertex, up to 64 (cell, weight) pairs, gathered in parallel and packed below.
    std::vector<std::vector<std::pair<int32_t, double>>> stencils(mesh.positions.size());
    const double h = grid.cell_size;
    const TriangleBvh* bvh = grid.boundary_bvh.get();
    // Voxels that a boundary face's box overlaps: a segment inside voxels none of which is marked
    // crosses no face, and needs no ray (most vertices inside).
    std::vector<uint8_t> near_face(grid.voxel_count(), 0);
    tbb::parallel_for(size_t{0}, connectivity.boundary_faces.size(), [&](size_t f) {
        Eigen::Vector3d lo = mesh.positions[connectivity.boundary_faces[f].vertices[0]], hi = lo;
        for (int32_t w : connectivity.boundary_faces[f].vertices) {
            lo = lo.cwiseMin(mesh.positions[w]);
            hi = hi.cwiseMax(mesh.positions[w]);
        }
        std::array<int, 3> first{}, last{};
        for (int k = 0; k < 3; ++k) {
            first[k] = std::clamp(static_cast<int>(std::floor((lo[k] - grid.origin[k]) / h)) - 1, 0, grid.dims[k] - 1);
            last[k] = std::clamp(static_cast<int>(std::floor((hi[k] - grid.origin[k]) / h)) + 1, 0, grid.dims[k] - 1);
        }
        for (int k = first[2]; k <= last[2]; ++k)
            for (int j = first[1]; j <= last[1]; ++j)
                for (int i = first[0]; i <= last[0]; ++i)
                    std::atomic_ref<uint8_t>(near_face[i + static_cast<size_t>(grid.dims[0]) * (j + static_cast<size_t>(grid.dims[1]) * k)])
                        .store(1, std::memory_order_relaxed);
    });

    tbb::parallel_for(size_t{0}, mesh.positions.size(), [&](size_t v) {
        const auto tets = connectivity.vertex_tets.row(v);
        if (tets.empty()) return;
        const Eigen::Vector3d p = mesh.positions[v];
        // A point a hair inside the vertex's own tets: on a cut or crack the vertex sits on both
        // (coincident) faces, and segments from the far side must still be seen to cross them.
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (int32_t t : tets)
            for (int32_t w : mesh.tets[t]) centroid += mesh.positions[w];
        centroid /= 4.0 * static_cast<double>(tets.size());
        const Eigen::Vector3f target = to_float(p + 1e-3 * (centroid - p));
        const int32_t component = connectivity.tet_component[tets[0]];
        bool clear = false;  // the eight voxels around the vertex are away from every face
        const auto usable = [&](int32_t cell) {
            if (cell < 0 || connectivity.tet_component[grid.cell_tet[cell]] != component) return false;
            if (!bvh || clear) return true;
            const Eigen::Vector3f from = to_float(grid.cell_centre(cell));
            return !bvh->occluded(from, target - from, 0.0f, 1.0f);
        };

        const Eigen::Vector3d u = (p - grid.origin) / h - Eigen::Vector3d::Constant(0.5);
        const std::array<int, 3> base = {static_cast<int>(std::floor(u[0])), static_cast<int>(std::floor(u[1])),
                                         static_cast<int>(std::floor(u[2]))};
        const Eigen::Vector3d f = u - Eigen::Vector3d(base[0], base[1], base[2]);

        std::vector<std::pair<int32_t, double>>& stencil = stencils[v];
        clear = (target.cast<double>() - p).norm() < 0.25 * h;
        for (int corner = 0; corner < 8 && clear; ++corner) {
            const int i = base[0] + (corner & 1), j = base[1] + ((corner >> 1) & 1), k = base[2] + ((corner >> 2) & 1);
            clear = i >= 0 && j >= 0 && k >= 0 && i < grid.dims[0] && j < grid.dims[1] && k < grid.dims[2] &&
                    !near_face[i + static_cast<size_t>(grid.dims[0]) * (j + static_cast<size_t>(grid.dims[1]) * k)];
        }
        // Trilinear over the eight surrounding cells when all count.
        bool all = true;
        for (int corner = 0; corner < 8 && all; ++corner) {
            const int di = corner & 1, dj = (corner >> 1) & 1, dk = (corner >> 2) & 1;
            const int32_t cell = grid.cell_at(base[0] + di, base[1] + dj, base[2] + dk);
            if (!usable(cell)) {
                all = false;
                break;
            }
            const double w = (di ? f[0] : 1 - f[0]) * (dj ? f[1] : 1 - f[1]) * (dk ? f[2] : 1 - f[2]);
            stencil.emplace_back(cell, w);
        }
        if (all) {
            how[v] = kTrilinear;
            return;
        }
        stencil.clear();
        clear = false;

        // A weighted linear fit over the usable cells of a block: first the 3x3x3 block around the
        // nearest voxel (clamped into the grid), then, where that does not determine a plane, the
        // 4x4x4 block around the vertex. The fitted value at the vertex is linear in the cell values:
        // cell k's weight is w_k e0^T N^-1 (1, offset_k) with N the weighted normal matrix. Where no
        // block determines a plane, the weighted mean of the larger block's cells.
        const auto fit = [&](const std::array<int, 3>& first, int size, bool accept_mean) {
            Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
            std::vector<std::pair<int32_t, Eigen::Vector4d>> rows;
            double weight_sum = 0;
            Eigen::Vector3d mean_offset = Eigen::Vector3d::Zero();
            for (int dk = 0; dk < size; ++dk)
                for (int dj = 0; dj < size; ++dj)
                    for (int di = 0; di < size; ++di) {
                        const int32_t cell = grid.cell_at(first[0] + di, first[1] + dj, first[2] + dk);
                        if (!usable(cell)) continue;
                        const Eigen::Vector3d offset = (grid.cell_centre(cell) - p) / h;  // in cells
                        const double w = (1 - std::abs(offset[0]) / 2.5) * (1 - std::abs(offset[1]) / 2.5) *
                                         (1 - std::abs(offset[2]) / 2.5);
                        const Eigen::Vector4d row(1, offset[0], offset[1], offset[2]);
                        normal += w * row * row.transpose();
                        rows.emplace_back(cell, w * row);
                        weight_sum += w;
                        mean_offset += w * offset;
                    }
            if (rows.empty()) return false;
            // The spread of the cells (weighted covariance, in cells^2) decides whether a plane is
            // determined.
            mean_offset /= weight_sum;
            const Eigen::Matrix3d spread =
                normal.bottomRightCorner<3, 3>() / weight_sum - mean_offset * mean_offset.transpose();
            const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(spread, Eigen::EigenvaluesOnly)
                                        .eigenvalues()
                                        .minCoeff();
            if (rows.size() >= 4 && smallest > 0.05) {
                const Eigen::Vector4d e0 = normal.ldlt().solve(Eigen::Vector4d::UnitX());  // N symmetric
                for (const auto& [cell, row] : rows) stencil.emplace_back(cell, e0.dot(row));
                return true;
            }
            if (!accept_mean) return false;
            for (const auto& [cell, row] : rows) stencil.emplace_back(cell, row[0] / weight_sum);
            return true;
        };
        std::array<int, 3> around_nearest{}, around_base{};
        for (int k = 0; k < 3; ++k) {
            around_nearest[k] = std::clamp(static_cast<int>(std::lround(u[k])), 0, grid.dims[k] - 1) - 1;
            around_base[k] = base[k] - 1;
        }
        if (fit(around_nearest, 3, false) || fit(around_base, 4, true)) {
            how[v] = kFitted;
            return;
        }

        // The nearest inside cell of the same component within 8 cells, by growing shells.
        constexpr int kReach = 8;
        for (int r = 1; r <= kReach; ++r) {
            int32_t best = -1;
            double best_distance = std::numeric_limits<double>::infinity();
            for (int dk = -r + 1; dk <= r; ++dk)
                for (int dj = -r + 1; dj <= r; ++dj)
                    for (int di = -r + 1; di <= r; ++di) {
                        if (std::max({std::abs(di - 0.5), std::abs(dj - 0.5), std::abs(dk - 0.5)}) < r - 1) continue;
                        const int32_t cell = grid.cell_at(base[0] + di, base[1] + dj, base[2] + dk);
                        if (cell < 0 || connectivity.tet_component[grid.cell_tet[cell]] != component) continue;
                        const double distance = (grid.cell_centre(cell) - p).squaredNorm();
                        if (distance < best_distance) {
                            best_distance = distance;
                            best = cell;
                        }
                    }
            if (best >= 0) {
                stencil.emplace_back(best, 1.0);
                how[v] = kNearest;
                return;
            }
        }
        how[v] = kUnsampled;
    });

    VertexSampling sampling;
    sampling.cell_count = grid.cell_count();
    sampling.offsets.assign(mesh.positions.size() + 1, 0);
    for (size_t v = 0; v < stencils.size(); ++v) {
        sampling.offsets[v + 1] = sampling.offsets[v] + static_cast<int32_t>(stencils[v].size());
        for (const auto& [cell, weight] : stencils[v]) {
            sampling.cells.push_back(cell);
            sampling.weights.push_back(weight);
        }
    }
    for (uint8_t c : how) {
        sampling.stats.trilinear += c == kTrilinear;
        sampling.stats.fitted += c == kFitted;
        sampling.stats.nearest += c == kNearest;
        sampling.stats.unsampled += c == kUnsampled;
    }
    return sampling;
}

std::vector<std::array<double, 3>> apply_vertex_sampling(const VertexSampling& sampling,
                                                         const std::vector<std::array<double, 3>>& cell_values) {
    if (cell_values.size() != sampling.cell_count)
        throw InvalidArgumentError("voxel grid: " + std::to_string(cell_values.size()) + " cell values for " +
                                   std::to_string(sampling.cell_count) + " cells");
    std::vector<std::array<double, 3>> phi(sampling.offsets.size() - 1, std::array<double, 3>{});
    tbb::parallel_for(size_t{0}, phi.size(), [&](size_t v) {
        for (int32_t k = sampling.offsets[v]; k < sampling.offsets[v + 1]; ++k)
            for (int ch = 0; ch < 3; ++ch) phi[v][ch] += sampling.weights[k] * cell_values[sampling.cells[k]][ch];
        // A linear fit can extrapolate below zero next to a steep boundary layer; phi >= 0.
        for (int ch = 0; ch < 3; ++ch) phi[v][ch] = std::max(0.0, phi[v][ch]);
    });
    return phi;
}

std::vector<std::array<double, 3>> sample_at_vertices(const VoxelGrid& grid, const MethodProblem& problem,
                                                      const std::vector<std::array<double, 3>>& cell_values,
                                                      VertexSamplingStats* stats) {
    const VertexSampling sampling = build_vertex_sampling(grid, problem);
    if (stats) *stats = sampling.stats;
    return apply_vertex_sampling(sampling, cell_values);
}

}  // namespace waxwork
