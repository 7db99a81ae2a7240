#include "solver/reference/monte_carlo.h"

#include "solver/reference/monte_carlo_medium.h"

#include "base/error.h"
#include "solver/material.h"
#include "solver/sampling.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

namespace waxwork {

namespace {

// Rounds of this many batches run in parallel; fixed, so that the batches a trace runs (and so its
// result) do not depend on the thread count.
constexpr int kRoundBatches = 8;
// A photon below roulette_threshold of its initial weight survives with this probability.
constexpr double kRouletteSurvival = 0.1;

// Where photons enter: per channel, a table over (source, boundary face) of the power that enters
// there, area (mm^2) times the face's mean q.
struct EntryTable {
    struct Entry {
        int32_t source;
        int32_t face;
    };
    std::vector<Entry> entries;
    std::array<std::vector<double>, 3> cumulative;  // per channel, over entries
    std::array<double, 3> power{};                  // per channel, units of q times mm^2
};

EntryTable build_entry_table(const BoundarySurface& surface, const std::vector<PhotonSource>& sources,
                             const std::vector<double>& face_area) {
    EntryTable table;
    for (size_t s = 0; s < sources.size(); ++s)
        for (size_t f = 0; f < surface.triangles.size(); ++f)
            table.entries.push_back({static_cast<int32_t>(s), static_cast<int32_t>(f)});
    for (int c = 0; c < 3; ++c) {
        auto& cdf = table.cumulative[c];
        cdf.reserve(table.entries.size());
        double sum = 0;
        for (const auto& e : table.entries) {
            const auto& tri = surface.triangles[e.face];
            const auto& q = sources[e.source].q;
            sum += face_area[e.face] * (q[tri[0]][c] + q[tri[1]][c] + q[tri[2]][c]) / 3.0;
            cdf.push_back(sum);
        }
        table.power[c] = sum;
    }
    return table;
}

// Per batch: the track length per tet, the escaped weight per boundary face, and the totals; weights
// are relative (mean 1 per photon at entry) and scaled to power when batches are combined.
struct BatchTally {
    std::vector<double> track;    // 3 per tet
    std::vector<double> escaped;  // 3 per boundary face
    std::array<double, 3> injected{}, absorbed{}, escaped_total{};
    int64_t lost = 0;
};

struct Tracer {
    const TetMesh& mesh;
    const TetConnectivity& connectivity;
    const BoundarySurface& surface;
    const std::vector<PhotonSource>& sources;
    const MonteCarloOptions& options;
    const MonteCarloMedium& medium;
    const EntryTable& table;

    void trace_batch(uint64_t batch, BatchTally& tally) const {
        MonteCarloRandom random(options.seed, batch);
        tally.track.assign(3 * mesh.tet_count(), 0.0);
        tally.escaped.assign(3 * connectivity.boundary_faces.size(), 0.0);
        tally.injected = tally.absorbed = tally.escaped_total = {};
        tally.lost = 0;
        for (int c = 0; c < 3; ++c) {
            if (!(table.power[c] > 0)) continue;
            for (int i = 0; i < options.batch_photons; ++i) trace_photon(c, random, tally);
        }
    }

    void trace_photon(int c, MonteCarloRandom& random, BatchTally& tally) const {
        // Entry: a (source, face) by its power, a point uniform on the face, weight q(x) / mean q.
        const auto& cdf = table.cumulative[c];
        const double pick = random.uniform() * table.power[c];
        size_t e = static_cast<size_t>(std::upper_bound(cdf.begin(), cdf.end(), pick) - cdf.begin());
        e = std::min(e, cdf.size() - 1);
        while (e > 0 && cdf[e] == cdf[e - 1]) --e;  // never a face of zero power
        const auto [s, f] = table.entries[e];
        const auto& tri = surface.triangles[f];
        const auto& q = sources[s].q;
        const double r1 = std::sqrt(random.uniform()), r2 = random.uniform();
        const std::array<double, 3> bary = {1 - r1, r1 * (1 - r2), r1 * r2};
        const double mean_q = (q[tri[0]][c] + q[tri[1]][c] + q[tri[2]][c]) / 3.0;
        const double q_here = bary[0] * q[tri[0]][c] + bary[1] * q[tri[1]][c] + bary[2] * q[tri[2]][c];
        double weight = q_here / mean_q;
        tally.injected[c] += weight;
        if (!(weight > 0)) return;
        const double initial_weight = weight;

        const BoundaryFace& face = connectivity.boundary_faces[f];
        int32_t tet = face.tet;
        const double scale = options.mm_per_unit;
        Eigen::Vector3d x = Eigen::Vector3d::Zero(), world = Eigen::Vector3d::Zero();
        for (int k = 0; k < 3; ++k) {
            x += bary[k] * mesh.positions[surface.vertices[tri[k]]] * scale;
            world += bary[k] * surface.positions[tri[k]];
        }
        const Eigen::Vector3d normal = medium.planes[tet].normal[face.local_face];
        const Eigen::Matrix3d& rotation = mesh.piece_transforms[mesh.piece_ids[tet]].rotation;
        Eigen::Vector3d d;
        const PhotonSource& source = sources[s];
        if (source.entry == PhotonEntry::Diffuse) {
            // Cosine-distributed incoming direction about the inward normal.
            const Eigen::Vector2d disk = concentric_disk(random.uniform(), random.uniform());
            Eigen::Vector3d t, b;
            orthonormal_basis(-normal, t, b);
            d = disk.x() * t + disk.y() * b - std::sqrt(std::max(0.0, 1 - disk.squaredNorm())) * normal;
        } else {
            const Eigen::Vector3d w =
                source.entry == PhotonEntry::Collimated ? source.vector : Eigen::Vector3d(world - source.vector);
            d = rotation.transpose() * w.normalized();
        }
        // q uses the vertex normals, the refraction the face's own: light that grazes the face from
        // behind enters along the inward normal.
        if (!(d.dot(normal) < 0)) d = -normal;
        d = refract_in(d.normalized(), normal, medium.eta[tet]);

        const double g = options.anisotropy;
        int skip = face.local_face;  // the face the photon sits on
        double tau = -std::log(random.open_uniform());  // optical depth to the next scattering
        for (int64_t step = 0;; ++step) {
            if (step >= options.max_steps) {
                ++tally.lost;
                return;
            }
            const MonteCarloMedium::TetPlanes& planes = medium.planes[tet];
            const TetExit leave = tet_exit(planes, x, d, skip);
            const int exit_face = leave.face;
            const double exit = leave.distance;
            if (exit_face < 0) {  // only from a degenerate direction: drop rather than loop
                ++tally.lost;
                return;
            }
            const double mus = medium.mus[tet][c], mua = medium.mua[tet][c];
            const double to_scatter = tau / mus;
            const bool scatters = to_scatter < exit;
            const double segment = scatters ? to_scatter : exit;
            // Continuous absorption along the segment: the track-length estimator integrates the
            // weight w exp(-mu_a s) over it, and mu_a times that is what was absorbed.
            const double kept = std::exp(-mua * segment);
            tally.track[3 * tet + c] += mua > 0 ? weight * (-std::expm1(-mua * segment)) / mua : weight * segment;
            tally.absorbed[c] += weight * (1 - kept);
            weight *= kept;
            x += segment * d;
            if (scatters) {
                d = sample_henyey_greenstein(d, g, random);
                skip = -1;
                tau = -std::log(random.open_uniform());
                if (weight < options.roulette_threshold * initial_weight) {
                    if (random.uniform() >= kRouletteSurvival) return;
                    weight /= kRouletteSurvival;
                }
                continue;
            }
            tau -= mus * segment;
            const int32_t next = connectivity.tet_neighbors[tet][exit_face];
            if (next >= 0) {
                skip = shared_face(connectivity, next, tet);
                tet = next;
                continue;
            }
            // A boundary face: leave with the Fresnel transmittance from inside, else reflect.
            const Eigen::Vector3d& n = planes.normal[exit_face];
            const double cos_out = n.dot(d);
            if (random.uniform() < fresnel_transmittance(cos_out, 1.0 / medium.eta[tet])) {
                const int32_t bf = medium.boundary_face[tet][exit_face];
                tally.escaped[3 * bf + c] += weight;
                tally.escaped_total[c] += weight;
                return;
            }
            d = (d - 2 * cos_out * n).normalized();
            skip = exit_face;
        }
    }
};

}  // namespace

std::vector<PhotonSource> photon_sources(const BoundarySurface& surface, const TriangleBvh& bvh,
                                         const Lighting& lighting) {
    std::vector<PhotonSource> sources;
    const std::vector<Rgb> total = incident_light(surface, bvh, lighting);
    std::vector<Rgb> rest = total;
    for (const Light& light : direct_lights(lighting)) {
        Lighting alone;
        alone.lights = {light};
        alone.shadows = lighting.shadows;
        PhotonSource source;
        source.entry = light.type == LightType::Directional ? PhotonEntry::Collimated : PhotonEntry::FromPoint;
        source.vector = light.vector;
        source.q = incident_light(surface, bvh, alone);
        for (size_t v = 0; v < rest.size(); ++v)
            for (int c = 0; c < 3; ++c) rest[v][c] -= source.q[v][c];
        sources.push_back(std::move(source));
    }
    PhotonSource diffuse;
    diffuse.entry = PhotonEntry::Diffuse;
    diffuse.q = std::move(rest);
    bool any = false;
    for (auto& value : diffuse.q)
        for (double& channel : value) {
            channel = std::max(0.0, channel);  // rounding of the subtraction
            any = any || channel > 0;
        }
    if (any) sources.push_back(std::move(diffuse));
    return sources;
}

void validate(const MonteCarloOptions& o) {
    auto fail = [](const std::string& what) { throw InvalidArgumentError("monte carlo: " + what); };
    validate_mm_per_unit(o.mm_per_unit, "monte carlo: mm_per_unit");
    if (!(o.anisotropy > -1 && o.anisotropy < 1)) fail("the anisotropy g must lie in (-1, 1)");
    if (o.batch_photons <= 0) fail("photons per batch must be positive");
    if (o.max_photons < 0) fail("the photon budget must not be negative");
    if (!(o.max_seconds >= 0 && std::isfinite(o.max_seconds))) fail("the time budget must be finite and not negative");
    if (!(o.target_relative_error >= 0 && std::isfinite(o.target_relative_error)))
        fail("the error target must be finite and not negative");
    if (o.max_photons == 0 && o.max_seconds == 0 && o.target_relative_error == 0)
        fail("needs a photon budget, a time budget or an error target");
    if (o.min_batches < 2) fail("at least two batches are needed for a standard error");
    if (!(o.roulette_threshold >= 0 && o.roulette_threshold < 1)) fail("the roulette threshold must lie in [0, 1)");
    if (o.max_steps <= 0) fail("the step limit must be positive");
}

void validate_trace_input(const TetMesh& mesh, const TetConnectivity& connectivity,
                          const std::vector<TetMaterial>& materials, const BoundarySurface& surface,
                          const std::vector<PhotonSource>& sources, const MonteCarloOptions& options) {
    validate(options);
    if (materials.size() != mesh.tet_count())
        throw InvalidArgumentError("monte carlo: " + std::to_string(materials.size()) + " materials for " +
                                   std::to_string(mesh.tet_count()) + " tets");
    if (surface.triangles.size() != connectivity.boundary_faces.size())
        throw InvalidArgumentError("monte carlo: the boundary surface does not match the connectivity");
    for (const PhotonSource& source : sources)
        if (source.q.size() != surface.positions.size())
            throw InvalidArgumentError("monte carlo: a source's q does not have one value per surface vertex");
    for (size_t t = 0; t < materials.size(); ++t) {
        const std::string problem = material_problem(materials[t]);
        if (!problem.empty()) throw InvalidArgumentError("monte carlo: tet " + std::to_string(t) + ": " + problem);
    }
}

MonteCarloFluence trace_fluence(const TetMesh& mesh, const TetConnectivity& connectivity,
                                const std::vector<TetMaterial>& materials, const BoundarySurface& surface,
                                const std::vector<PhotonSource>& sources, const MonteCarloOptions& options,
                                const std::function<void(const MonteCarloProgress&)>& progress,
                                const Progress* cancel) {
    validate_trace_input(mesh, connectivity, materials, surface, sources, options);

    const auto start = std::chrono::steady_clock::now();
    const double scale = options.mm_per_unit;
    const MonteCarloMedium medium = build_monte_carlo_medium(mesh, connectivity, materials, scale, options.anisotropy);
    std::vector<double> face_area(surface.triangles.size());
    for (size_t f = 0; f < face_area.size(); ++f) {
        const auto& v = connectivity.boundary_faces[f].vertices;
        face_area[f] = 0.5 * scale * scale *
                       (mesh.positions[v[1]] - mesh.positions[v[0]]).cross(mesh.positions[v[2]] - mesh.positions[v[0]]).norm();
    }
    const EntryTable table = build_entry_table(surface, sources, face_area);
    const Tracer tracer{mesh, connectivity, surface, sources, options, medium, table};

    // The lumped volume of each vertex's tets (sum over its tets of V_t): phi_v = track / volume.
    const size_t vertex_count = mesh.vertex_count();
    std::vector<double> vertex_volume(vertex_count, 0.0);
    for (size_t v = 0; v < vertex_count; ++v)
        for (int32_t t : connectivity.vertex_tets.row(v)) vertex_volume[v] += medium.volume[t];

    MonteCarloFluence result;
    result.phi.assign(vertex_count, {0, 0, 0});
    result.phi_error.assign(vertex_count, {0, 0, 0});
    result.tet_phi.assign(mesh.tet_count(), {0, 0, 0});
    result.face_exitance.assign(connectivity.boundary_faces.size(), {0, 0, 0});
    if (!(table.power[0] > 0 || table.power[1] > 0 || table.power[2] > 0)) {
        result.stop_reason = "no light";
        return result;
    }

    // Running sums over batches, in batch order: per vertex the batch estimate and its square (for
    // the standard error), per tet and face the tallies.
    std::vector<std::array<double, 3>> vertex_sum(vertex_count, {0, 0, 0}), vertex_square(vertex_count, {0, 0, 0});
    std::vector<double> track_sum(3 * mesh.tet_count(), 0.0), escaped_sum(3 * face_area.size(), 0.0);
    std::vector<BatchTally> round(kRoundBatches);
    std::array<double, 3> photon_power{};  // power of one photon of unit weight in one batch
    for (int c = 0; c < 3; ++c) photon_power[c] = table.power[c] / options.batch_photons;

    auto compute_error = [&](int64_t batches) {
        std::array<double, 3> error{};
        const double b = static_cast<double>(batches);
        for (int c = 0; c < 3; ++c) {
            double phi2 = 0, err2 = 0;
            for (int32_t v : connectivity.boundary_vertices) {
                const double mean = vertex_sum[v][c] / b;
                const double variance = std::max(0.0, vertex_square[v][c] / b - mean * mean) / (b - 1);
                phi2 += mean * mean;
                err2 += variance;
            }
            error[c] = phi2 > 0 ? std::sqrt(err2 / phi2) : 0.0;
        }
        return error;
    };

    int64_t batches = 0;
    while (true) {
        check_cancelled(cancel);
        tbb::parallel_for(0, kRoundBatches, [&](int k) { tracer.trace_batch(static_cast<uint64_t>(batches + k), round[k]); });
        // Per vertex, the batches in order: bit-identical whatever ran them.
        tbb::parallel_for(tbb::blocked_range<size_t>(0, vertex_count, 1024), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t v = r.begin(); v != r.end(); ++v) {
                if (!(vertex_volume[v] > 0)) continue;
                const auto tets = connectivity.vertex_tets.row(v);
                for (const BatchTally& tally : round) {
                    for (int c = 0; c < 3; ++c) {
                        double track = 0;
                        for (int32_t t : tets) track += tally.track[3 * t + c];
                        const double estimate = photon_power[c] * track / vertex_volume[v];
                        vertex_sum[v][c] += estimate;
                        vertex_square[v][c] += estimate * estimate;
                    }
                }
            }
        });
        tbb::parallel_for(tbb::blocked_range<size_t>(0, track_sum.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i != r.end(); ++i)
                for (const BatchTally& tally : round) track_sum[i] += tally.track[i];
        });
        for (const BatchTally& tally : round) {
            for (size_t i = 0; i < escaped_sum.size(); ++i) escaped_sum[i] += tally.escaped[i];
            for (int c = 0; c < 3; ++c) {
                result.injected[c] += tally.injected[c];
                result.absorbed[c] += tally.absorbed[c];
                result.escaped[c] += tally.escaped_total[c];
            }
            result.lost_photons += tally.lost;
        }
        batches += kRoundBatches;

        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const int64_t photons = batches * options.batch_photons;
        const std::array<double, 3> error = compute_error(batches);
        if (progress) progress({photons, batches, seconds, error});
        result.relative_error = error;
        result.seconds = seconds;
        if (options.max_photons > 0 && photons >= options.max_photons) {
            result.stop_reason = "photons";
            break;
        }
        if (options.max_seconds > 0 && seconds >= options.max_seconds) {
            result.stop_reason = "seconds";
            break;
        }
        if (options.target_relative_error > 0 && batches >= options.min_batches &&
            *std::max_element(error.begin(), error.end()) <= options.target_relative_error) {
            result.stop_reason = "error";
            break;
        }
    }

    result.batches = batches;
    result.photons = batches * options.batch_photons;
    const double b = static_cast<double>(batches);
    for (size_t v = 0; v < vertex_count; ++v) {
        for (int c = 0; c < 3; ++c) {
            const double mean = vertex_sum[v][c] / b;
            result.phi[v][c] = mean;
            result.phi_error[v][c] = std::sqrt(std::max(0.0, vertex_square[v][c] / b - mean * mean) / (b - 1));
        }
    }
    for (int c = 0; c < 3; ++c) {
        const double unit = photon_power[c] / b;  // power of one unit-weight photon over the whole trace
        for (size_t t = 0; t < mesh.tet_count(); ++t) result.tet_phi[t][c] = unit * track_sum[3 * t + c] / medium.volume[t];
        for (size_t f = 0; f < face_area.size(); ++f)
            result.face_exitance[f][c] = face_area[f] > 0 ? unit * escaped_sum[3 * f + c] / face_area[f] : 0.0;
        result.injected[c] *= unit;
        result.absorbed[c] *= unit;
        result.escaped[c] *= unit;
    }
    return result;
}

}  // namespace waxwork
