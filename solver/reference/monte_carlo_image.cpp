#include "solver/reference/monte_carlo_image.h"

#include "base/error.h"
#include "solver/material.h"
#include "solver/reference/monte_carlo_medium.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

namespace waxwork {

namespace {

// Passes per round: the unit between progress reports and stopping checks. Fixed, so that the passes a
// trace runs (and so its result) do not depend on the thread count.
constexpr int kRoundPasses = 4;
// A path below roulette_threshold of its initial weight survives with this probability.
constexpr double kRouletteSurvival = 0.1;
// Beyond this optical depth a connection to a light carries less than e^-30 of it: not followed.
constexpr double kMaxConnectionDepth = 30;
// Refractions at the reached face tried before a connection is taken as it stands (only where the
// straight path ends next to an edge between faces of different normals).
constexpr int kRefractionIterations = 4;

struct ImageTracer {
    const TetMesh& mesh;
    const TetConnectivity& connectivity;
    const BoundarySurface& surface;
    const FirstHitGrid& grid;
    const std::vector<PhotonSource>& sources;
    const PixelCamera& camera;
    const MonteCarloOptions& options;
    const MonteCarloMedium& medium;
    const PhotonSource* diffuse = nullptr;

    // The straight path from x along unit w to the boundary: the tet and face it leaves through, the
    // point there and the optical depth int mu_t on the way.
    struct Reach {
        bool reached = false;
        int32_t tet = -1;
        int face = -1;
        Eigen::Vector3d y = Eigen::Vector3d::Zero();
        double tau = 0;
    };

    Reach march(int c, int32_t tet, Eigen::Vector3d x, const Eigen::Vector3d& w) const {
        Reach reach;
        int skip = -1;
        for (int64_t step = 0; step < options.max_steps; ++step) {
            const TetExit exit = tet_exit(medium.planes[tet], x, w, skip);
            if (exit.face < 0) return reach;
            reach.tau += (medium.mua[tet][c] + medium.mus[tet][c]) * exit.distance;
            if (reach.tau > kMaxConnectionDepth) return reach;
            x += exit.distance * w;
            const int32_t next = connectivity.tet_neighbors[tet][exit.face];
            if (next < 0) {
                reach.reached = true;
                reach.tet = tet;
                reach.face = exit.face;
                reach.y = x;
                return reach;
            }
            skip = shared_face(connectivity, next, tet);
            tet = next;
        }
        return reach;
    }

    // Channel c of a per-surface-vertex value at point y (rest frame, mm) of boundary face bf, linear
    // over the triangle as the photon tracer reads q.
    double at_face_point(const std::vector<Rgb>& values, int32_t bf, const Eigen::Vector3d& y, int c) const {
        const auto& tri = surface.triangles[bf];
        const double scale = options.mm_per_unit;
        const Eigen::Vector3d p0 = mesh.positions[surface.vertices[tri[0]]] * scale;
        const Eigen::Vector3d e1 = mesh.positions[surface.vertices[tri[1]]] * scale - p0;
        const Eigen::Vector3d e2 = mesh.positions[surface.vertices[tri[2]]] * scale - p0;
        const Eigen::Vector3d r = y - p0;
        const double d11 = e1.dot(e1), d12 = e1.dot(e2), d22 = e2.dot(e2);
        const double det = d11 * d22 - d12 * d12;
        if (!(det > 0)) return (values[tri[0]][c] + values[tri[1]][c] + values[tri[2]][c]) / 3.0;
        const double b1 = std::clamp((d22 * r.dot(e1) - d12 * r.dot(e2)) / det, 0.0, 1.0);
        const double b2 = std::clamp((d11 * r.dot(e2) - d12 * r.dot(e1)) / det, 0.0, 1.0 - b1);
        return (1 - b1 - b2) * values[tri[0]][c] + b1 * values[tri[1]][c] + b2 * values[tri[2]][c];
    }

    // Next-event estimation from a scattering event at x in `tet` of a path travelling along d: the
    // radiance scattered back along -d from the direct light `source`, per unit path weight.
    double connect(int c, int32_t tet, const Eigen::Vector3d& x, const Eigen::Vector3d& d,
                   const PhotonSource& source) const {
        const RigidTransform& piece = mesh.piece_transforms[mesh.piece_ids[tet]];
        const bool collimated = source.entry == PhotonEntry::Collimated;
        Eigen::Vector3d out = collimated ? Eigen::Vector3d(piece.rotation.transpose() * source.vector.normalized())
                                         : Eigen::Vector3d::Zero();
        const Eigen::Vector3d light =
            collimated ? Eigen::Vector3d::Zero()
                       : Eigen::Vector3d(piece.rotation.transpose() * (source.vector - piece.translation) * options.mm_per_unit);
        Eigen::Vector3d w = collimated ? Eigen::Vector3d(-out) : Eigen::Vector3d((light - x).normalized());
        Reach reach;
        Eigen::Vector3d refracted;
        Eigen::Vector3d normal;
        for (int iteration = 0; iteration < kRefractionIterations; ++iteration) {
            reach = march(c, tet, x, w);
            if (!reach.reached) return 0;
            normal = medium.planes[reach.tet].normal[reach.face];
            if (!collimated) out = (reach.y - light).normalized();
            if (!(out.dot(normal) < 0)) return 0;  // the light is behind the face it would enter by
            refracted = refract_in(out, normal, medium.eta[reach.tet]);
            if (-refracted.dot(w) >= 1 - 1e-12) break;
            w = -refracted;
        }
        const double cos_t = -refracted.dot(normal);
        if (!(cos_t > 0)) return 0;
        const double q = at_face_point(source.q, medium.boundary_face[reach.tet][reach.face], reach.y, c);
        if (!(q > 0)) return 0;
        // q is the light transmitted per unit area of the face; the refracted beam's irradiance across
        // its own direction is q / cos theta_t.
        return henyey_greenstein(-refracted.dot(d), options.anisotropy) * q / cos_t * std::exp(-reach.tau);
    }

    // The radiance inside the medium arriving at the entry point against d (the path's direction after
    // refraction in), channel c: a collision estimator with next-event estimation.
    double walk(int c, int32_t tet, int skip, Eigen::Vector3d x, Eigen::Vector3d d, MonteCarloRandom& random,
                int64_t& lost) const {
        double radiance = 0;
        double weight = 1;
        double tau = -std::log(random.open_uniform());
        for (int64_t step = 0;; ++step) {
            if (step >= options.max_steps) {
                ++lost;
                return radiance;
            }
            const MonteCarloMedium::TetPlanes& planes = medium.planes[tet];
            const TetExit exit = tet_exit(planes, x, d, skip);
            if (exit.face < 0) {
                ++lost;
                return radiance;
            }
            const double mus = medium.mus[tet][c], mua = medium.mua[tet][c];
            const double to_scatter = tau / mus;
            const bool scatters = to_scatter < exit.distance;
            const double segment = scatters ? to_scatter : exit.distance;
            // Free paths are sampled by mu_s and absorption weights the path, as in the photon
            // tracer; the in-scattered radiance mu_s int p L_i over that density leaves int p L_i.
            weight *= std::exp(-mua * segment);
            x += segment * d;
            if (scatters) {
                for (const PhotonSource& source : sources)
                    if (&source != diffuse) radiance += weight * connect(c, tet, x, d, source);
                d = sample_henyey_greenstein(d, options.anisotropy, random);
                skip = -1;
                tau = -std::log(random.open_uniform());
            } else {
                tau -= mus * segment;
                const int32_t next = connectivity.tet_neighbors[tet][exit.face];
                if (next >= 0) {
                    skip = shared_face(connectivity, next, tet);
                    tet = next;
                    continue;
                }
                const Eigen::Vector3d& n = planes.normal[exit.face];
                const double cos_out = n.dot(d);
                const double eta = medium.eta[tet];
                const double transmittance = fresnel_transmittance(cos_out, 1.0 / eta);
                if (diffuse && transmittance > 0) {
                    const double q = at_face_point(diffuse->q, medium.boundary_face[tet][exit.face], x, c);
                    radiance += weight * eta * eta * q / std::numbers::pi;
                }
                weight *= 1 - transmittance;
                if (!(weight > 0)) return radiance;
                d = (d - 2 * cos_out * n).normalized();
                skip = exit.face;
            }
            if (weight < options.roulette_threshold) {
                if (random.uniform() >= kRouletteSurvival) return radiance;
                weight /= kRouletteSurvival;
            }
        }
    }

    // One jittered sample of pixel (column, row): false when the ray misses the object.
    bool sample(int column, int row, MonteCarloRandom& random, std::array<double, 3>& radiance, int64_t& lost) const {
        const double px = column + random.uniform(), py = row + random.uniform();
        const Eigen::Vector3d world = pixel_direction(camera, px, py);
        const auto hit = grid.first_hit(camera.eye, world);
        if (!hit) return false;
        const BoundaryFace& face = connectivity.boundary_faces[hit->triangle];
        const int32_t tet = face.tet;
        const auto& tri = surface.triangles[hit->triangle];
        const double w[3] = {1.0 - hit->u - hit->v, hit->u, hit->v};
        Eigen::Vector3d x = Eigen::Vector3d::Zero();
        for (int k = 0; k < 3; ++k) x += w[k] * mesh.positions[surface.vertices[tri[k]]] * options.mm_per_unit;
        const Eigen::Vector3d d = mesh.piece_transforms[mesh.piece_ids[tet]].rotation.transpose() * world;
        const Eigen::Vector3d& n = medium.planes[tet].normal[face.local_face];
        radiance = {0, 0, 0};
        const double cos_view = -d.dot(n);
        if (!(cos_view > 0)) return true;  // a face seen from inside: the camera is in the object
        const double eta = medium.eta[tet];
        const double exit_factor = fresnel_transmittance(cos_view, eta) / (eta * eta);
        const Eigen::Vector3d inside = refract_in(d, n, eta);
        for (int c = 0; c < 3; ++c)
            radiance[c] = exit_factor * walk(c, tet, face.local_face, x, inside, random, lost);
        return true;
    }
};

}  // namespace

MonteCarloImage trace_camera_image(const TetMesh& mesh, const TetConnectivity& connectivity,
                                   const std::vector<TetMaterial>& materials, const BoundarySurface& surface,
                                   const FirstHitGrid& grid, const std::vector<PhotonSource>& sources,
                                   const PixelCamera& camera, const MonteCarloOptions& options,
                                   const std::function<void(const MonteCarloProgress&)>& progress,
                                   const Progress* cancel) {
    validate_trace_input(mesh, connectivity, materials, surface, sources, options);
    if (grid.triangle_count() != surface.triangles.size())
        throw InvalidArgumentError("monte carlo: the ray grid does not match the boundary surface");
    if (camera.width <= 0 || camera.height <= 0) throw InvalidArgumentError("monte carlo: the image size must be positive");

    const auto start = std::chrono::steady_clock::now();
    const MonteCarloMedium medium =
        build_monte_carlo_medium(mesh, connectivity, materials, options.mm_per_unit, options.anisotropy);
    ImageTracer tracer{mesh, connectivity, surface, grid, sources, camera, options, medium};
    bool lit = false;
    for (const PhotonSource& source : sources) {
        if (source.entry == PhotonEntry::Diffuse) tracer.diffuse = &source;
        for (const Rgb& q : source.q) lit = lit || q[0] > 0 || q[1] > 0 || q[2] > 0;
    }

    const int width = camera.width, height = camera.height;
    const size_t pixels = static_cast<size_t>(width) * height;
    std::vector<std::array<double, 3>> sum(pixels, {0, 0, 0}), square(pixels, {0, 0, 0});
    std::vector<int64_t> hits(pixels, 0), lost_per_row(height, 0);

    MonteCarloImage result;
    auto finish = [&](int64_t passes) {
        RadianceImage& image = result.image;
        image.width = width;
        image.height = height;
        image.radiance.assign(pixels, {0, 0, 0});
        image.coverage.assign(pixels, 0.0f);
        result.radiance_error.assign(pixels, {0, 0, 0});
        std::array<double, 3> radiance2{}, error2{};
        int64_t paths = 0;
        for (size_t p = 0; p < pixels; ++p) {
            const int64_t n = hits[p];
            paths += n;
            if (n == 0) continue;
            image.coverage[p] = static_cast<float>(static_cast<double>(n) / passes);
            for (int c = 0; c < 3; ++c) {
                const double mean = sum[p][c] / n;
                image.radiance[p][c] = mean;
                const double variance = n > 1 ? std::max(0.0, square[p][c] / n - mean * mean) / (n - 1) : 0.0;
                result.radiance_error[p][c] = std::sqrt(variance);
                radiance2[c] += mean * mean;
                error2[c] += variance;
            }
        }
        for (int c = 0; c < 3; ++c) result.relative_error[c] = radiance2[c] > 0 ? std::sqrt(error2[c] / radiance2[c]) : 0.0;
        result.passes = passes;
        result.paths = paths;
        result.lost_paths = 0;
        for (int64_t lost : lost_per_row) result.lost_paths += lost;
        result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };

    int64_t passes = 0;
    while (true) {
        check_cancelled(cancel);
        tbb::parallel_for(0, height, [&](int row) {
            // A round over a large image can take many seconds: a cancelled one skips its remaining
            // rows (its partial sums are thrown away with the CancelledError below).
            if (cancel && cancel->cancel_requested()) return;
            for (int column = 0; column < width; ++column) {
                const size_t p = static_cast<size_t>(row) * width + column;
                for (int k = 0; k < kRoundPasses; ++k) {
                    MonteCarloRandom random(options.seed, static_cast<uint64_t>(passes + k) * pixels + p);
                    std::array<double, 3> radiance{};
                    if (!tracer.sample(column, row, random, radiance, lost_per_row[row])) continue;
                    ++hits[p];
                    for (int c = 0; c < 3; ++c) {
                        sum[p][c] += radiance[c];
                        square[p][c] += radiance[c] * radiance[c];
                    }
                }
            }
        });
        check_cancelled(cancel);
        passes += kRoundPasses;
        finish(passes);
        if (progress) progress({result.paths, passes, result.seconds, result.relative_error});
        if (!lit) {
            result.stop_reason = "no light";
            break;
        }
        if (options.max_photons > 0 && result.paths >= options.max_photons) {
            result.stop_reason = "photons";
            break;
        }
        if (options.max_seconds > 0 && result.seconds >= options.max_seconds) {
            result.stop_reason = "seconds";
            break;
        }
        if (options.target_relative_error > 0 && passes >= options.min_batches &&
            *std::max_element(result.relative_error.begin(), result.relative_error.end()) <=
                options.target_relative_error) {
            result.stop_reason = "error";
            break;
        }
        if (result.paths == 0 && passes >= options.min_batches) {
            result.stop_reason = "no light";  // the object is not in view
            break;
        }
    }
    return result;
}

}  // namespace waxwork
