#include "solver/methods/dipole.h"

#include "base/error.h"
#include "base/timing.h"
#include "solver/material.h"
#include "solver/methods/dipole_profile.h"
#include "solver/ray_caster.h"
#include "tetops/point_kd_tree.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <string>

namespace waxwork {
namespace {

// The boundary as the method sees it: one sample per boundary vertex, in mm.
struct SurfaceSamples {
    std::vector<int32_t> vertex;          // volume vertex of each sample
    std::vector<Eigen::Vector3d> x;       // position, mm
    std::vector<Eigen::Vector3d> n;       // area-weighted outward normal, unit
    std::vector<double> area;             // a third of the area of its boundary triangles, mm^2 (Eq. 16)
    std::vector<double> rho;              // radius of the disk of that area
    std::vector<double> a;                // boundary reflection parameter A
    std::vector<DipoleProfile> profile;   // 3 per sample (rgb)
    std::vector<uint8_t> grey;            // the three channels' coefficients are equal (one profile serves)
    // Face-connected component (connectivity.h): light diffuses only within one, as in TransCut's
    // matrix, so pieces of a fractured or cut volume do not light each other through their shared faces.
    std::vector<int32_t> component;
};

// The 7-point degree-5 rule on a disk (Radon): the centre weighs 1/4 and six points on the circle of
// radius sqrt(2/3) rho weigh 1/8 each. It averages a profile over a source's area (the form factor of
// Eq. 11 over the source's fan) where the profile varies across it.
constexpr double kDiskRingRadius = 0.816496580927726;  // sqrt(2/3)
// Pairs closer than this many disk radii of the source use the disk rule; farther ones the centre.
constexpr double kNearField = 4.0;

void tangent_basis(const Eigen::Vector3d& n, Eigen::Vector3d& t1, Eigen::Vector3d& t2) {
    t1 = (std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY()).cross(n).normalized();
    t2 = n.cross(t1);
}

template <class Kernel>
double disk_mean(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, double rho, const Kernel& kernel) {
    Eigen::Vector3d t1, t2;
    tangent_basis(normal, t1, t2);
    double sum = 0.25 * kernel(centre);
    for (int k = 0; k < 6; ++k) {
        const double angle = k * std::numbers::pi / 3;
        sum += 0.125 * kernel(centre + kDiskRingRadius * rho * (std::cos(angle) * t1 + std::sin(angle) * t2));
    }
    return sum;
}

void validate(const MethodProblem& problem, const DipoleOptions& options) {
    const TetMesh& mesh = problem.mesh;
    if (!(options.profile_tolerance > 0 && options.profile_tolerance <= 0.5))
        throw InvalidArgumentError("dipole: profile_tolerance must be in (0, 0.5] (got " +
                                   std::to_string(options.profile_tolerance) + ")");
    if (!(options.thin_diffusion_lengths > 0 && std::isfinite(options.thin_diffusion_lengths)))
        throw InvalidArgumentError("dipole: thin_diffusion_lengths must be positive and finite");
    if (options.back_side_samples < 0)
        throw InvalidArgumentError("dipole: back_side_samples must be 0 (all) or a positive count");
    if (!(options.warning_fraction >= 0 && options.warning_fraction <= 1))
        throw InvalidArgumentError("dipole: warning_fraction must be in [0, 1]");
    if (problem.materials.size() != mesh.tet_count())
        throw InvalidArgumentError("dipole: " + std::to_string(problem.materials.size()) + " materials for " +
                                   std::to_string(mesh.tet_count()) + " tets");
    if (problem.q.size() != mesh.vertex_count())
        throw InvalidArgumentError("dipole: " + std::to_string(problem.q.size()) + " light values for " +
                                   std::to_string(mesh.vertex_count()) + " vertices");
    validate_mm_per_unit(problem.mm_per_unit, "dipole: mm_per_unit");
    for (const TetMaterial& m : problem.materials) validate_material(m, "dipole: material");
    if (problem.connectivity.boundary_vertices.empty())
        throw InvalidArgumentError("dipole: the volume has no boundary (the method lives on the surface)");
    for (int32_t v : problem.connectivity.boundary_vertices)
        for (double c : problem.q[v])
            if (!std::isfinite(c)) throw InvalidArgumentError("dipole: the incident light q is not finite");
}

SurfaceSamples surface_samples(const MethodProblem& problem) {
    const TetMesh& mesh = problem.mesh;
    const TetConnectivity& conn = problem.connectivity;
    const double mm = problem.mm_per_unit;
    const size_t n = conn.boundary_vertices.size();
    std::vector<int32_t> sample_of(mesh.vertex_count(), -1);
    for (size_t s = 0; s < n; ++s) sample_of[conn.boundary_vertices[s]] = static_cast<int32_t>(s);

    // Area-weighted means of the materials of the tets owning each vertex's boundary faces.
    std::vector<Eigen::Vector3d> normal(n, Eigen::Vector3d::Zero());
    std::vector<double> area(n, 0.0), eta(n, 0.0);
    std::vector<std::array<double, 3>> mua(n, {0, 0, 0}), musp(n, {0, 0, 0});
    std::vector<int32_t> component(n, 0);
    for (const BoundaryFace& f : conn.boundary_faces) {
        for (int32_t v : f.vertices) component[sample_of[v]] = conn.tet_component[f.tet];
        const auto& p = mesh.positions;
        const Eigen::Vector3d cross =
            (p[f.vertices[1]] - p[f.vertices[0]]).cross(p[f.vertices[2]] - p[f.vertices[0]]) * (mm * mm);
        const double face_area = 0.5 * cross.norm();
        const TetMaterial& m = problem.materials[f.tet];
        for (int32_t v : f.vertices) {
            const int32_t s = sample_of[v];
            normal[s] += cross;
            area[s] += face_area / 3;
            eta[s] += face_area * m.eta;
            for (int c = 0; c < 3; ++c) mua[s][c] += face_area * m.mua[c], musp[s][c] += face_area * m.musp[c];
        }
    }
    SurfaceSamples out;
    out.vertex = conn.boundary_vertices;
    out.x.resize(n);
    out.n.resize(n);
    out.area = area;
    out.component = std::move(component);
    out.rho.resize(n);
    out.a.resize(n);
    out.profile.reserve(3 * n);
    for (size_t s = 0; s < n; ++s) {
        out.x[s] = mesh.positions[out.vertex[s]] * mm;
        const double norm = normal[s].norm();
        out.n[s] = norm > 0 ? Eigen::Vector3d(normal[s] / norm) : Eigen::Vector3d::UnitZ();
        out.rho[s] = std::sqrt(area[s] / std::numbers::pi);
        const double weight = 3 * area[s];  // the sum of the face areas
        const double e = weight > 0 ? eta[s] / weight : 1.0;
        out.a[s] = boundary_reflection_parameter(e);
        for (int c = 0; c < 3; ++c)
            out.profile.emplace_back(weight > 0 ? mua[s][c] / weight : 0.0, weight > 0 ? musp[s][c] / weight : 1.0, e);
        out.grey.push_back(mua[s][0] == mua[s][1] && mua[s][0] == mua[s][2] && musp[s][0] == musp[s][1] &&
                           musp[s][0] == musp[s][2]);
    }
    return out;
}

// Whether the light between a point inside the volume and boundary sample i would cross air: the
// segment from the point to the dipole's real source (z_r below x_i) leaves the volume. A ray cast
// against the boundary (the chord of a concave region can leave and re-enter anywhere along it).
bool crosses_air(const SurfaceSamples& s, const Eigen::Vector3d& from, size_t i, const TriangleBvh& bvh) {
    const Eigen::Vector3d to = s.x[i] - s.profile[3 * i].depth_real() * s.n[i];
    return bvh.occluded(from.cast<float>(), (to - from).cast<float>(), 1e-4f, 1 - 1e-4f);
}

// Only the pairs carrying more than this share of a vertex's light are ray cast for air crossings: the
// casts cost more than the profile, and the many weak pairs cannot change the result visibly.
constexpr double kAirTestShare = 1e-4;

bool surface_is_convex(const SurfaceSamples& s, const PointKdTree& tree, double radius_sq) {
    std::atomic<bool> convex{true};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, s.x.size()), [&](const auto& range) {
        std::vector<std::pair<uint32_t, double>> matches;
        for (size_t o = range.begin(); o != range.end() && convex.load(std::memory_order_relaxed); ++o) {
            matches.clear();
            tree.radiusSearch(s.x[o].data(), radius_sq, matches, nanoflann::SearchParams(32, 0, false));
            for (const auto& [i, distance_sq] : matches)
                if (s.component[i] == s.component[o] && (s.x[i] - s.x[o]).dot(s.n[o]) > 0.05 * std::sqrt(distance_sq)) {
                    convex = false;
                    break;
                }
        }
    });
    return convex.load();
}

// A source's contribution to one receiver, per channel, before the air test.
struct Contribution {
    uint32_t sample;
    std::array<double, 3> value;
    bool back_side;
};

// Sums the contributions into `total`, leaving out (and adding to `dropped`, channel 0) those of
// weight above kAirTestShare of the sum whose path from `from` crosses air.
void sum_contributions(const SurfaceSamples& s, std::span<const Contribution> contributions, const Eigen::Vector3d& from,
                       const TriangleBvh* bvh, std::array<double, 3>& total, double& back, double& dropped) {
    std::array<double, 3> sum{};
    for (const Contribution& c : contributions)
        for (int k = 0; k < 3; ++k) sum[k] += c.value[k];
    const double threshold = kAirTestShare * (sum[0] + sum[1] + sum[2]);
    for (const Contribution& c : contributions) {
        if (bvh && c.value[0] + c.value[1] + c.value[2] > threshold && crosses_air(s, from, c.sample, *bvh)) {
            dropped += c.value[0];
            continue;
        }
        for (int k = 0; k < 3; ++k) total[k] += c.value[k];
        if (c.back_side) back += c.value[0];
    }
}

}  // namespace

MethodSolution solve_dipole(const MethodProblem& problem, const DipoleOptions& options, DipoleDiagnostics* diagnostics) {
    validate(problem, options);
    const auto setup_start = std::chrono::steady_clock::now();
    report_stage(problem.progress, "dipole: profiles and kd-tree");
    const TetMesh& mesh = problem.mesh;
    const TetConnectivity& conn = problem.connectivity;
    const double mm = problem.mm_per_unit;
    const SurfaceSamples s = surface_samples(problem);
    const size_t n = s.x.size();

    // The cut-off radius: the largest over the samples' profiles (capped at the volume's extent, which
    // no pair exceeds), and the thin-part test radius: the longest diffusion length.
    Eigen::Vector3d lo = s.x[0], hi = s.x[0];
    for (const Eigen::Vector3d& p : s.x) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const double extent = std::max((hi - lo).norm(), 1e-9);
    double radius = 0, diffusion_length = 0;
    for (const DipoleProfile& p : s.profile) {
        radius = std::max(radius, p.cutoff_radius(options.profile_tolerance, extent));
        diffusion_length = std::max(diffusion_length, p.sigma_tr() > 0 ? 1.0 / p.sigma_tr() : extent);
    }
    const double thin_length = options.thin_diffusion_lengths * diffusion_length;
    const double search_radius = std::max(radius, std::min(thin_length, extent));

    const PointCloud cloud{s.x};
    const PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    std::vector<Eigen::Vector3f> bvh_points(mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) bvh_points[v] = (mesh.positions[v] * mm).cast<float>();
    std::vector<std::array<int32_t, 3>> triangles;
    triangles.reserve(conn.boundary_faces.size());
    for (const BoundaryFace& f : conn.boundary_faces) triangles.push_back(f.vertices);
    const TriangleBvh bvh(bvh_points, triangles);
    // A path between two points of a convex volume never crosses air; a chord that leaves the volume at
    // p and re-enters at p' puts p' in front of p's tangent plane. So the ray casts are needed only when
    // some boundary vertex has another, within the search radius, in front of its tangent plane (by more
    // than 3 degrees, above the faceting of a curved surface).
    const bool convex = surface_is_convex(s, tree, search_radius * search_radius);
    const bool sam = options.back_side_samples > 0;
    const TriangleBvh* air_test = options.leave_out_air_crossings && !convex ? &bvh : nullptr;

    MethodSolution solution;
    solution.phi.assign(mesh.vertex_count(), {0, 0, 0});
    solution.unknowns = n;
    solution.setup_ms = milliseconds_since(setup_start);
    const auto solve_start = std::chrono::steady_clock::now();

    // Exitance at every boundary sample (Eqs. 8-11), with its front/back split (Eqs. 13-14).
    report_stage(problem.progress, "dipole: exitance between surface vertices");
    std::vector<std::array<double, 3>> exitance(n, {0, 0, 0});
    std::vector<double> back(n, 0.0), dropped(n, 0.0), thickness(n, std::numeric_limits<double>::infinity());
    std::atomic<size_t> pairs{0};
    const double radius_sq = radius * radius, search_sq = search_radius * search_radius;
    const size_t batch = 2048;
    const size_t interior_count = mesh.vertex_count() - n;
    const double total_work = static_cast<double>(n + interior_count);
    for (size_t begin = 0; begin < n; begin += batch) {
        check_cancelled(problem.progress);
        if (problem.progress) problem.progress->set_fraction(static_cast<float>(begin / total_work));
        tbb::parallel_for(tbb::blocked_range<size_t>(begin, std::min(begin + batch, n)), [&](const auto& range) {
            std::vector<std::pair<uint32_t, double>> matches;
            std::vector<Contribution> contributions;
            std::vector<std::pair<double, Contribution>> back_candidates;  // (form factor, contribution)
            size_t local_pairs = 0;
            for (size_t o = range.begin(); o != range.end(); ++o) {
                matches.clear();
                contributions.clear();
                back_candidates.clear();
                tree.radiusSearch(s.x[o].data(), search_sq, matches, nanoflann::SearchParams(32, 0, false));
                local_pairs += matches.size();
                for (const auto& [i, distance_sq] : matches) {
                    if (s.component[i] != s.component[o]) continue;
                    const bool back_side = (s.x[i] - s.x[o]).dot(s.n[o]) < 0 && s.n[i].dot(s.n[o]) < 0;
                    const double distance = std::sqrt(distance_sq);
                    if (back_side) thickness[o] = std::min(thickness[o], distance);
                    const std::array<double, 3>& qi = problem.q[s.vertex[i]];
                    // The SAM picks its back-side samples by form factor alone, lit or not (Eq. 12).
                    const bool sam_candidate = sam && back_side && i != o;
                    if (distance_sq >= radius_sq || (!sam_candidate && qi[0] == 0 && qi[1] == 0 && qi[2] == 0)) continue;
                    std::array<double, 3> k{};
                    for (int c = 0; c < 3; ++c) {
                        const DipoleProfile& p = s.profile[3 * i + c];
                        if (c > 0 && s.grey[i])
                            k[c] = k[0];
                        else if (i == o)
                            k[c] = s.area[i] * p.disk_mean_reflectance(s.rho[i]);
                        else if (distance < kNearField * s.rho[i])
                            k[c] = s.area[i] * disk_mean(s.x[i], s.n[i], s.rho[i], [&](const Eigen::Vector3d& y) {
                                       return p.reflectance((y - s.x[o]).norm());
                                   });
                        else
                            k[c] = s.area[i] * p.reflectance(distance);
                    }
                    const double form_factor = k[0] + k[1] + k[2];
                    for (int c = 0; c < 3; ++c) k[c] *= qi[c];
                    if (sam_candidate) {
                        back_candidates.push_back({form_factor, {i, k, true}});
                        continue;
                    }
                    if (i == o || distance <= 2 * s.rho[o]) {  // the vertex itself and its neighbours: no air between
                        for (int c = 0; c < 3; ++c) exitance[o][c] += k[c];
                        continue;
                    }
                    contributions.push_back({i, k, back_side});
                }
                if (sam) {
                    const size_t keep = std::min(back_candidates.size(), static_cast<size_t>(options.back_side_samples));
                    const auto middle = back_candidates.begin() + static_cast<std::ptrdiff_t>(keep);
                    std::partial_sort(back_candidates.begin(), middle, back_candidates.end(),
                                      [](const auto& a, const auto& b) { return a.first > b.first; });
                    for (size_t k = 0; k < keep; ++k) contributions.push_back(back_candidates[k].second);
                }
                sum_contributions(s, contributions, s.x[o] - s.profile[3 * o].depth_real() * s.n[o],
                                  air_test, exitance[o], back[o], dropped[o]);
            }
            pairs += local_pairs;
        });
    }
    // phi = 2 (A M + q): the exitance as the flux (1 - F_dr) J+ that leaves through the Robin boundary
    // (header comment).
    for (size_t o = 0; o < n; ++o)
        for (int c = 0; c < 3; ++c)
            solution.phi[s.vertex[o]][c] = 2 * (s.a[o] * exitance[o][c] + problem.q[s.vertex[o]][c]);

    // Interior vertices: the dipoles' fluence at depth, each source's dipole along its inward normal.
    report_stage(problem.progress, "dipole: fluence at interior vertices");
    std::vector<int32_t> interior;
    interior.reserve(interior_count);
    for (size_t v = 0; v < mesh.vertex_count(); ++v)
        if (!conn.is_boundary_vertex[v] && !conn.vertex_tets.row(v).empty()) interior.push_back(static_cast<int32_t>(v));
    for (size_t begin = 0; begin < interior.size(); begin += batch) {
        check_cancelled(problem.progress);
        if (problem.progress) problem.progress->set_fraction(static_cast<float>((n + begin) / total_work));
        const size_t end = std::min(begin + batch, interior.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(begin, end), [&](const auto& range) {
            std::vector<std::pair<uint32_t, double>> matches;
            std::vector<Contribution> contributions;
            size_t local_pairs = 0;
            for (size_t k = range.begin(); k != range.end(); ++k) {
                const int32_t v = interior[k];
                const Eigen::Vector3d x = mesh.positions[v] * mm;
                // The cut-off holds for the lateral spread under the surface; at depth z the fluence of a
                // lit plane falls with the distance minus z, so the search reaches z further.
                uint32_t nearest = 0;
                double nearest_sq = 0;
                tree.knnSearch(x.data(), 1, &nearest, &nearest_sq);
                const double reach = radius + std::sqrt(nearest_sq);
                matches.clear();
                tree.radiusSearch(x.data(), reach * reach, matches, nanoflann::SearchParams(32, 0, false));
                local_pairs += matches.size();
                std::array<double, 3> phi{};
                contributions.clear();
                const int32_t component = conn.tet_component[conn.vertex_tets.row(v)[0]];
                for (const auto& [i, distance_sq] : matches) {
                    const std::array<double, 3>& qi = problem.q[s.vertex[i]];
                    if (s.component[i] != component || (qi[0] == 0 && qi[1] == 0 && qi[2] == 0)) continue;
                    std::array<double, 3> value{};
                    for (int c = 0; c < 3; ++c) {
                        const DipoleProfile& p = s.profile[3 * i + c];
                        // A source's fluence diverges at its real source; spreading the source over its
                        // vertex's area bounds it (the distance is floored at half the disk radius).
                        const auto kernel = [&](const Eigen::Vector3d& y) {
                            const double d_real = std::max((x - (y - p.depth_real() * s.n[i])).norm(), 0.5 * s.rho[i]);
                            const double d_virtual = (x - (y + p.height_virtual() * s.n[i])).norm();
                            return p.fluence(d_real, d_virtual);
                        };
                        value[c] = c > 0 && s.grey[i] ? value[0]
                                   : s.area[i] * (std::sqrt(distance_sq) < kNearField * s.rho[i] + p.depth_real()
                                                      ? disk_mean(s.x[i], s.n[i], s.rho[i], kernel)
                                                      : kernel(s.x[i]));
                    }
                    for (int c = 0; c < 3; ++c) value[c] *= qi[c];
                    contributions.push_back({i, value, false});
                }
                double unused_back = 0, unused_dropped = 0;
                sum_contributions(s, contributions, x, air_test, phi, unused_back, unused_dropped);
                solution.phi[v] = phi;
            }
            pairs += local_pairs;
        });
    }
    solution.solve_ms = milliseconds_since(solve_start);
    if (problem.progress) problem.progress->set_fraction(1.0f);

    // Diagnostics and warnings: thin parts and light crossing air.
    double total_area = 0, thin_area = 0, kept = 0, lost = 0, from_back = 0;
    for (size_t o = 0; o < n; ++o) {
        total_area += s.area[o];
        if (thickness[o] < thin_length) thin_area += s.area[o];
        kept += s.area[o] * exitance[o][0];
        lost += s.area[o] * dropped[o];
        from_back += s.area[o] * back[o];
    }
    DipoleDiagnostics d;
    d.cutoff_radius_mm = radius;
    d.thin_length_mm = thin_length;
    d.thin_area_fraction = total_area > 0 ? thin_area / total_area : 0;
    d.back_side_share = kept > 0 ? from_back / kept : 0;
    d.through_air_share = kept + lost > 0 ? lost / (kept + lost) : 0;
    d.pairs = pairs.load();
    const auto percent = [](double f) { return std::to_string(static_cast<int>(std::lround(100 * f))) + "%"; };
    if (d.thin_area_fraction > options.warning_fraction)
        solution.warnings.push_back(
            "dipole: " + percent(d.thin_area_fraction) + " of the surface is thinner than " +
            std::to_string(options.thin_diffusion_lengths).substr(0, 4) + " diffusion lengths (" +
            std::to_string(thin_length).substr(0, 5) +
            " mm); the dipole assumes a semi-infinite medium, so light through those parts is wrong (compare with "
            "--method transcut)");
    if (d.through_air_share > options.warning_fraction)
        solution.warnings.push_back("dipole: " + percent(d.through_air_share) +
                                    " of the exitance would cross air between facing surfaces (concave regions) and "
                                    "was left out; the light around those regions is too dark");
    if (diagnostics) *diagnostics = d;
    return solution;
}

}  // namespace waxwork
