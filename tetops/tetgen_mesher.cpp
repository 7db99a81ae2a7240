#include "tetops/tetgen_mesher.h"

#include "base/error.h"
#include "base/progress.h"
#include "tetops/mesher_scale.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tetgen.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <new>
#include <random>
#include <string>
#include <vector>

namespace waxwork {

namespace {

// Ratio of TetGen's -a bound to the volume of the regular tet whose edge is the mean edge it produces
// (measured: -a 1e-5 on spot gives a mean edge of 0.031).
constexpr double kVolumeBoundPerRegularVolume = 2.85;
// TetGen's -m metric bounds the circumradius of each tet; this maps a wanted mean edge to it (a
// regular tet has circumradius 0.61 L; Delaunay refinement leaves tets smaller than the bound).
constexpr double kMetricPerEdge = 0.9;
// A graded run refines less than its quality bound asks: TetGen rejects a refinement point inside the
// size ball of a vertex, so slivers stay where the surface's triangles meet the interior. TetGen's
// optimisation after refinement (flips and vertex smoothing) works on tets with a dihedral angle over
// this bound (165 by default); 150 also reaches most slivers at the surface (docs/meshing.md).
constexpr double kGradedOptimizeAboveDihedralDeg = 150;
// The grid of interior points the background mesh is made of: half the largest edge apart, and
// between these many cells along the bounding box's diagonal (the size grows 0.5 per unit of depth,
// so a cell of half the largest edge resolves it where it is not capped).
constexpr double kMinGridCellsPerDiagonal = 16;
constexpr double kMaxGridCellsPerDiagonal = 64;

std::string tetgen_reason(int code) {
    switch (code) {
    case 1: return "out of memory";
    case 2: return "internal error";
    case 3: return "the surface intersects itself";
    case 4: return "a very small input feature (nearly coincident vertices or edges)";
    case 5: return "two nearly coincident input facets";
    case 10: return "invalid input";
    default: return "error code " + std::to_string(code);
    }
}

// The surface as a TetGen piecewise linear complex: its points and one triangular facet per triangle.
void fill_plc(const TriangleSurface& surface, tetgenio& in) {
    in.firstnumber = 0;
    in.numberofpoints = static_cast<int>(surface.points.size());
    in.pointlist = new REAL[3 * surface.points.size()];
    for (size_t i = 0; i < surface.points.size(); ++i) {
        for (int k = 0; k < 3; ++k) in.pointlist[3 * i + k] = surface.points[i][k];
    }
    in.numberoffacets = static_cast<int>(surface.triangles.size());
    in.facetlist = new tetgenio::facet[surface.triangles.size()];
    for (size_t i = 0; i < surface.triangles.size(); ++i) {
        tetgenio::facet& facet = in.facetlist[i];
        tetgenio::init(&facet);
        facet.numberofpolygons = 1;
        facet.polygonlist = new tetgenio::polygon[1];
        tetgenio::init(&facet.polygonlist[0]);
        facet.polygonlist[0].numberofvertices = 3;
        facet.polygonlist[0].vertexlist = new int[3];
        for (int k = 0; k < 3; ++k) facet.polygonlist[0].vertexlist[k] = surface.triangles[i][k];
    }
}

// A switch value in plain decimals with nine significant digits: TetGen's switch parser reads
// "1e-05" or "4.2949673e+09" as the number before the 'e' and then unknown switches '-', '+', '0'...
// (a radius-edge bound of 1e9 became 1, which refines for ever).
std::string format_number(double value) {
    const int magnitude = value != 0 ? static_cast<int>(std::floor(std::log10(std::abs(value)))) : 0;
    const int decimals = std::max(0, 8 - magnitude);
    char buffer[512];
    std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
    std::string text = buffer;
    if (text.find('.') != std::string::npos) {
        text.erase(text.find_last_not_of('0') + 1);
        if (text.back() == '.') text.pop_back();
    }
    return text;
}

// -p: the input is a PLC; -z: zero-based indices; -q: quality; -a: volume bound; -m: sizes from the
// metric of the background mesh, with -o/: flips and smoothing for every tet with a dihedral angle over
// kGradedOptimizeAboveDihedralDeg; -S: a limit on added points. No -V (verbose) ever: TetGen would
// print per element.
std::string make_switches(const TetGenSettings& settings, bool volume_bound, bool metric) {
    std::string switches = "pz";
    if (settings.quality) {
        switches += "q" + format_number(settings.max_radius_edge_ratio) + "/" +
                    format_number(settings.min_dihedral_deg);
    }
    if (volume_bound) switches += "a" + format_number(tetgen_volume_bound_for_edge(settings.size.max_edge));
    if (metric) switches += "mo/" + format_number(kGradedOptimizeAboveDihedralDeg);
    if (settings.max_added_points >= 0) switches += "S" + std::to_string(settings.max_added_points);
    if (settings.quiet) switches += "Q";
    return switches;
}

// Runs TetGen and turns what it throws into Waxwork errors. TetGen built as a library (TETLIBRARY)
// throws an int from terminatetetgen() instead of calling exit().
void run_tetgen(const std::string& switches, tetgenio& in, tetgenio& out, tetgenio* background) {
    std::string mutable_switches = switches;  // TetGen's signature takes a non-const char*
    try {
        tetrahedralize(mutable_switches.data(), &in, &out, nullptr, background);
    } catch (int code) {
        throw AlgorithmError("TetGen (-" + switches + ") failed: " + tetgen_reason(code));
    } catch (const std::bad_alloc&) {
        throw AlgorithmError("TetGen (-" + switches + ") failed: out of memory");
    }
    if (out.numberoftetrahedra <= 0 || out.numberofcorners != 4) {
        throw AlgorithmError("TetGen (-" + switches + ") produced no tetrahedra");
    }
}

// TetGen's output without the points no tet uses (input duplicates, removed Steiner points), with
// every tet positively oriented.
TetMesh to_tet_mesh(const tetgenio& out) {
    std::vector<int32_t> new_index(out.numberofpoints, -1);
    std::vector<Eigen::Vector3d> positions;
    std::vector<Tet> tets(out.numberoftetrahedra);
    for (int t = 0; t < out.numberoftetrahedra; ++t) {
        for (int k = 0; k < 4; ++k) {
            const int old_index = out.tetrahedronlist[4 * t + k];
            if (old_index < 0 || old_index >= out.numberofpoints) {
                throw AlgorithmError("TetGen produced a tet with an invalid vertex index");
            }
            if (new_index[old_index] < 0) {
                new_index[old_index] = static_cast<int32_t>(positions.size());
                const REAL* p = &out.pointlist[3 * old_index];
                positions.emplace_back(p[0], p[1], p[2]);
            }
            tets[t][k] = new_index[old_index];
        }
        // TetGen 1.5 emits positively oriented tets in Waxwork's convention; checked rather than
        // assumed so that a different TetGen build cannot flip the whole mesh.
        Tet& tet = tets[t];
        if (signed_volume(positions[tet[0]], positions[tet[1]], positions[tet[2]], positions[tet[3]]) < 0) {
            std::swap(tet[2], tet[3]);
        }
    }
    return make_tet_mesh(std::move(positions), std::move(tets));
}

// The background mesh of a graded run: the Delaunay tetrahedralization of the surface's points, a
// grid of points inside it and the corners of a box around it, each point carrying
// kMetricPerEdge edge(depth) (points outside carry the surface edge); TetGen interpolates it linearly
// inside its tets. It is convex on purpose: TetGen locates every point of the graded run in it by
// a walk that falls back to a scan of all its tets when the walk leaves the mesh, which it does at
// every concavity of a background mesh shaped like the object (docs/meshing.md measures it). A point
// set also costs no quality run: the Delaunay tetrahedralization of a few thousand points takes
// milliseconds where a quality mesh of the surface takes as long as the graded run itself.
void make_background_mesh(const TriangleSurface& surface, const SizeField& size, tetgenio& background) {
    const SurfaceDistance distance(surface);
    Eigen::Vector3d lo = surface.points.front();
    Eigen::Vector3d hi = lo;
    for (const auto& p : surface.points) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    const double diagonal = (hi - lo).norm();
    const double spacing = std::clamp(size.max_edge / 2, diagonal / kMaxGridCellsPerDiagonal,
                                      diagonal / kMinGridCellsPerDiagonal);
    const Eigen::Array3i cells = ((hi - lo) / spacing).array().ceil().cast<int>().max(1);

    // Each grid point is moved by up to a fifth of a cell, the same way on every run: a regular grid
    // is the most degenerate input Delaunay has (eight cospherical points per cell), and TetGen's
    // point location falls back to inexact orientation tests that assert on the flat tets it leaves.
    std::vector<Eigen::Vector3d> grid;
    grid.reserve(size_t(cells.x() + 1) * (cells.y() + 1) * (cells.z() + 1));
    std::mt19937 random(12345);
    std::uniform_real_distribution<double> jitter(-0.2 * spacing, 0.2 * spacing);
    for (int i = 0; i <= cells.x(); ++i) {
        for (int j = 0; j <= cells.y(); ++j) {
            for (int k = 0; k <= cells.z(); ++k) {
                const Eigen::Vector3d offset(jitter(random), jitter(random), jitter(random));
                grid.push_back(lo + spacing * Eigen::Vector3d(i, j, k) + offset);
            }
        }
    }
    // The depth of each grid point inside the surface; points outside, or nearer the surface than a
    // quarter cell (they add nothing the surface's own points do not, and make needle tets), are
    // left out (negative).
    std::vector<double> grid_depth(grid.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, grid.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
            const double depth = distance(grid[i]);
            grid_depth[i] = depth >= spacing / 4 && distance.contains(grid[i]) ? depth : -1.0;
        }
    });

    std::vector<Eigen::Vector3d> points = surface.points;
    std::vector<double> sizes(points.size(), size.surface_edge);
    for (size_t i = 0; i < grid.size(); ++i) {
        if (grid_depth[i] < 0) continue;
        points.push_back(grid[i]);
        sizes.push_back(size.edge_at_depth(grid_depth[i]));
    }
    for (int corner = 0; corner < 8; ++corner) {
        points.emplace_back(corner & 1 ? hi.x() + spacing : lo.x() - spacing,
                            corner & 2 ? hi.y() + spacing : lo.y() - spacing,
                            corner & 4 ? hi.z() + spacing : lo.z() - spacing);
        sizes.push_back(size.surface_edge);
    }

    tetgenio in;
    in.firstnumber = 0;
    in.numberofpoints = static_cast<int>(points.size());
    in.pointlist = new REAL[3 * points.size()];
    for (size_t i = 0; i < points.size(); ++i) {
        for (int k = 0; k < 3; ++k) in.pointlist[3 * i + k] = points[i][k];
    }
    run_tetgen("zQ", in, background, nullptr);  // Delaunay of the points: no -p, no refinement
    // Without -p TetGen adds no points and keeps the input's order (duplicates included, unused).
    if (background.numberofpoints != in.numberofpoints)
        throw AlgorithmError("TetGen's background mesh has " + std::to_string(background.numberofpoints) +
                             " points for " + std::to_string(in.numberofpoints) + " given");
    background.numberofpointmtrs = 1;
    background.pointmtrlist = new REAL[background.numberofpoints];
    for (size_t i = 0; i < sizes.size(); ++i) background.pointmtrlist[i] = kMetricPerEdge * sizes[i];
}

}  // namespace

double tetgen_volume_bound_for_edge(double edge) {
    return kVolumeBoundPerRegularVolume * edge * edge * edge / (6 * std::sqrt(2.0));
}

TetMesh tetgen_tetrahedralize(const TriangleSurface& surface, const TetGenSettings& settings,
                              bool* stopped_at_point_limit) {
    if (const int exponent = mesher_scale_exponent(surface); exponent != 0) {
        TetGenSettings scaled = settings;
        scaled.size = scaled_size_field(settings.size, exponent);
        TetMesh mesh = tetgen_tetrahedralize(scaled_surface(surface, exponent), scaled, stopped_at_point_limit);
        scale_positions(mesh, -exponent);
        return mesh;
    }
    const SizeField& size = settings.size;
    if (stopped_at_point_limit) *stopped_at_point_limit = false;
    if (!size.is_bounded() || size.is_uniform()) {
        TetGenSettings uniform = settings;
        uniform.size.max_edge = std::min(size.surface_edge, size.max_edge);
        tetgenio in;
        tetgenio out;
        fill_plc(surface, in);
        run_tetgen(make_switches(uniform, std::isfinite(uniform.size.max_edge), false), in, out, nullptr);
        if (stopped_at_point_limit && settings.max_added_points >= 0)
            *stopped_at_point_limit = out.numberofpoints - in.numberofpoints >= settings.max_added_points;
        return to_tet_mesh(out);
    }

    // The point limit bounds both runs; the background mesh only carries sizes, so when it is cut
    // short the run goes on with it, and only the graded run's stop is reported.
    const TetGenSettings& graded = settings;
    report_stage(settings.progress, "meshing (TetGen, sizing field)");
    tetgenio background;
    make_background_mesh(surface, size, background);
    tetgenio in;
    tetgenio out;
    fill_plc(surface, in);
    in.numberofpointmtrs = 1;
    in.pointmtrlist = new REAL[in.numberofpoints];
    for (int i = 0; i < in.numberofpoints; ++i) in.pointmtrlist[i] = kMetricPerEdge * size.surface_edge;
    report_stage(settings.progress, "meshing (TetGen, graded)");
    run_tetgen(make_switches(graded, false, true), in, out, &background);
    if (stopped_at_point_limit && settings.max_added_points >= 0)
        *stopped_at_point_limit = out.numberofpoints - in.numberofpoints >= settings.max_added_points;
    return to_tet_mesh(out);
}

}  // namespace waxwork
