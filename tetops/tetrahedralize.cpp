#include "tetops/tetrahedralize.h"

#include "base/error.h"
#include "base/progress.h"
#include "tetops/cgal_mesher.h"
#include "tetops/size_field.h"
#include "tetops/spatial_order.h"
#include "tetops/surface_check.h"
#include "tetops/surface_remesh.h"
#include "tetops/tetgen_mesher.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace waxwork {

namespace {

// Mean tet volume over the volume of the regular tet with the mean edge: 0.88 measured on TetGen's
// output (spot, 230K tets), so count ~ 1.14 V / regular_volume(edge); rounded up for the estimate.
constexpr double kTetsPerRegularVolume = 1.2;
// target_tets: stop as soon as a pass is this close, accept up to the promised 20% after the last.
constexpr double kTargetTolerance = 0.10;
constexpr double kTargetPromise = 0.20;
constexpr int kMaxTargetPasses = 4;
// TetGen's bare constrained Delaunay tetrahedralization (the surface's triangles, no quality bound)
// has 1.4-2.8 tets per surface triangle on the shared meshes; a target below this many per triangle
// may be out of reach and is checked against it, then against the coarsest quality mesh, first.
constexpr double kBareCheckTetsPerTriangle = 4.0;
// The quality floor check stops TetGen after this many added points per tet the target allows. Its
// quality meshes have 3.2 (skull, cut short) to 6 tets per vertex, so with fewer tets per point than
// any of them the run stopped there has more tets than allowed.
constexpr double kTetsPerAddedPointForFloorCheck = 3.0;

// TetGen cannot keep the surface's triangles within the size or budget asked for: an
// InvalidArgumentError for an explicit --mesher tetgen (what() says what it needs and suggests CGAL);
// Mesher::Auto catches it and remeshes the surface instead, giving `reason` as why.
class OutOfTetGenReach : public InvalidArgumentError {
public:
    OutOfTetGenReach(const std::string& message, std::string reason)
        : InvalidArgumentError(message), reason_(std::move(reason)) {}
    const std::string& reason() const { return reason_; }

private:
    std::string reason_;
};

// " (about T s at the measured N tets per second; the limit takes about M s)" for a mesh of `tets`.
std::string predicted_time(double tets) {
    return " (about " + number_text(std::round(tets / kMeasuredTetsPerSecond)) + " s at the measured " +
           number_text(kMeasuredTetsPerSecond) + " tets per second; the limit takes about " +
           number_text(std::round(double(kMaxMeshTets) / kMeasuredTetsPerSecond)) + " s)";
}

void validate_options(const MeshingOptions& options) {
    if (options.mesher != Mesher::TetGen && options.mesher != Mesher::Cgal && options.mesher != Mesher::Auto) {
        throw InvalidArgumentError("meshing option mesher: unknown mesher");
    }
    if (!(options.remesh_edge_ratio > 0) || !std::isfinite(options.remesh_edge_ratio)) {
        throw InvalidArgumentError("meshing option remesh_edge_ratio = " + number_text(options.remesh_edge_ratio) +
                                   ": must be positive and finite");
    }
    // TetGen's Delaunay refinement is proven to end for bounds of 2 and ends in practice down to
    // about 1.2; at 1.1 and under it refines for ever (spot: 1.2 takes 6 s, 1.1 did not end in 40 s).
    if (!(options.max_radius_edge_ratio >= kMinRadiusEdgeRatio) || !std::isfinite(options.max_radius_edge_ratio)) {
        throw InvalidArgumentError("meshing option max_radius_edge_ratio = " +
                                   number_text(options.max_radius_edge_ratio) + ": must be finite and >= 1.2");
    }
    if (!(options.min_dihedral_deg > 0 && options.min_dihedral_deg <= 30)) {
        throw InvalidArgumentError("meshing option min_dihedral_deg = " + number_text(options.min_dihedral_deg) +
                                   ": must be in (0, 30] degrees");
    }
    const MeshSizing& sizing = options.sizing;
    if (sizing.edge_length) {
        if (!(*sizing.edge_length > 0) || !std::isfinite(*sizing.edge_length)) {
            throw InvalidArgumentError("meshing option sizing.edge_length = " + number_text(*sizing.edge_length) +
                                       ": must be a positive length");
        }
    } else if (sizing.target_tets) {
        if (*sizing.target_tets == 0 || *sizing.target_tets > kMaxMeshTets) {
            throw InvalidArgumentError("meshing option sizing.target_tets = " +
                                       std::to_string(*sizing.target_tets) + ": must be in 1.." +
                                       std::to_string(kMaxMeshTets) + predicted_time(*sizing.target_tets));
        }
    } else {
        if (!(sizing.surface_edge > 0) || !std::isfinite(sizing.surface_edge)) {
            throw InvalidArgumentError("meshing option sizing.surface_edge = " + number_text(sizing.surface_edge) +
                                       ": must be a positive length (or set sizing.edge_length or "
                                       "sizing.target_tets)");
        }
        if (!(sizing.grading >= 0) || !std::isfinite(sizing.grading)) {
            throw InvalidArgumentError("meshing option sizing.grading = " + number_text(sizing.grading) +
                                       ": must be finite and >= 0");
        }
        if (!(sizing.max_edge == 0 || (sizing.max_edge >= sizing.surface_edge && std::isfinite(sizing.max_edge)))) {
            throw InvalidArgumentError("meshing option sizing.max_edge = " + number_text(sizing.max_edge) +
                                       ": must be 0 (no cap) or at least sizing.surface_edge");
        }
    }
}

// The widest span a surface may have, in median edge lengths. Real models span hundreds to a few
// thousand (TetrahedralizeTest.FillsEveryCleanSharedMesh meshes every shared one); a stray vertex far from the rest makes TetGen
// crash (1e9), hang (1e7 with a tet target) or drop most of the surface without a word (1e8).
constexpr double kMaxSpanPerMedianEdge = 1e5;

void check_surface_span(const TriangleSurface& surface) {
    std::vector<double> edges;
    edges.reserve(3 * surface.triangles.size());
    for (const auto& tri : surface.triangles)
        for (int k = 0; k < 3; ++k) edges.push_back((surface.points[tri[k]] - surface.points[tri[(k + 1) % 3]]).norm());
    const auto middle = edges.begin() + static_cast<std::ptrdiff_t>(edges.size() / 2);
    std::nth_element(edges.begin(), middle, edges.end());
    const double median_edge = *middle;
    // The centre of the bulk: the per-axis median of the points, which one far point cannot move.
    Eigen::Vector3d centre;
    std::vector<double> axis(surface.points.size());
    for (int k = 0; k < 3; ++k) {
        for (size_t i = 0; i < surface.points.size(); ++i) axis[i] = surface.points[i][k];
        const auto mid = axis.begin() + static_cast<std::ptrdiff_t>(axis.size() / 2);
        std::nth_element(axis.begin(), mid, axis.end());
        centre[k] = *mid;
    }
    size_t farthest = 0;
    double reach = 0;
    for (size_t i = 0; i < surface.points.size(); ++i)
        if (const double d = (surface.points[i] - centre).norm(); d > reach) reach = d, farthest = i;
    if (!(reach <= kMaxSpanPerMedianEdge * median_edge))
        throw InvalidMeshError("surface to mesh: point " + std::to_string(farthest) + " lies " + number_text(reach) +
                               " from the middle of the surface, " + number_text(reach / median_edge) +
                               " times its median edge length (" + number_text(median_edge) +
                               "); the meshers cannot span more than " + number_text(kMaxSpanPerMedianEdge) +
                               " (a stray vertex?)");
}

// The mesher asserts (and may crash) on malformed input, so the surface is checked first: indices in
// range, finite points, closed and consistently oriented (every directed edge has its reverse exactly
// once), positive enclosed volume.
void validate_surface(const TriangleSurface& surface) {
    if (const std::string problem = triangle_count_problem(surface.triangles.size(), kMaxSurfaceTriangles);
        !problem.empty())
        throw InvalidMeshError("surface to mesh: " + problem);
    if (surface.triangles.size() < 4) {
        throw InvalidMeshError("surface to mesh: " + std::to_string(surface.triangles.size()) +
                               " triangles cannot enclose a volume");
    }
    for (size_t i = 0; i < surface.points.size(); ++i) {
        if (!surface.points[i].allFinite()) {
            throw InvalidMeshError("surface to mesh: point " + std::to_string(i) + " is not finite");
        }
    }
    const auto n = static_cast<int64_t>(surface.points.size());
    std::vector<std::pair<int64_t, int64_t>> directed;
    directed.reserve(3 * surface.triangles.size());
    for (size_t t = 0; t < surface.triangles.size(); ++t) {
        const auto& tri = surface.triangles[t];
        for (int k = 0; k < 3; ++k) {
            if (tri[k] < 0 || tri[k] >= n) {
                throw InvalidMeshError("surface to mesh: triangle " + std::to_string(t) +
                                       " has an out-of-range vertex index " + std::to_string(tri[k]));
            }
        }
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) {
            throw InvalidMeshError("surface to mesh: triangle " + std::to_string(t) + " repeats a vertex");
        }
        for (int k = 0; k < 3; ++k) directed.emplace_back(tri[k], tri[(k + 1) % 3]);
    }
    std::sort(directed.begin(), directed.end());
    for (size_t i = 0; i < directed.size(); ++i) {
        const auto [a, b] = directed[i];
        if (i + 1 < directed.size() && directed[i + 1] == directed[i]) {
            throw InvalidMeshError("surface to mesh: edge (" + std::to_string(a) + ", " + std::to_string(b) +
                                   ") is used twice in the same direction (non-manifold or inconsistently "
                                   "oriented)");
        }
        if (!std::binary_search(directed.begin(), directed.end(), std::pair{b, a})) {
            throw InvalidMeshError("surface to mesh: edge (" + std::to_string(a) + ", " + std::to_string(b) +
                                   ") is on a hole (the surface is not closed)");
        }
    }
    if (!(enclosed_volume(surface) > 0)) {
        throw InvalidMeshError("surface to mesh: enclosed volume is not positive (inward-facing triangles?)");
    }
    check_surface_span(surface);
    for (size_t i = 0; i < surface.points.size(); ++i) {
        if (surface.points[i].cwiseAbs().maxCoeff() > kMaxCoordinate)
            throw InvalidMeshError("surface to mesh: point " + std::to_string(i) + " lies beyond " +
                                   kMaxCoordinateText + " (the renderer's float arithmetic would overflow)");
    }
}

// Predicted tet count of a size field: V / regular_volume(edge) for a uniform size; for a graded one
// the shell at depth d (area A, to first order) holds A dd / regular_volume(s + g d) tets, whose
// integral is bounded by A / (2 g s^2) * 6 sqrt 2, plus the interior at max_edge.
double predicted_tets(const SizeField& size, double volume, double area) {
    const double s = size.surface_edge;
    double per_regular_volume = volume / (s * s * s);
    if (!size.is_uniform()) {
        const double m = size.max_edge;
        const double graded = area / (2 * size.grading * s * s) + (std::isfinite(m) ? volume / (m * m * m) : 0.0);
        per_regular_volume = std::min(per_regular_volume, graded);
    }
    return kTetsPerRegularVolume * 6 * std::sqrt(2.0) * per_regular_volume;
}

void check_predicted_size(const SizeField& size, double volume, double area, const std::string& option) {
    const double predicted = predicted_tets(size, volume, area);
    if (predicted > double(kMaxMeshTets)) {
        throw InvalidArgumentError("meshing option " + option + ": about " + number_text(predicted) +
                                   " tets predicted for a volume of " + number_text(volume) +
                                   ", above the limit of " + number_text(double(kMaxMeshTets)) +
                                   predicted_time(predicted) + "; use a larger edge length");
    }
}

TetGenSettings tetgen_settings(const MeshingOptions& options, const SizeField& size) {
    TetGenSettings settings;
    settings.progress = options.progress;
    settings.size = size;
    settings.max_radius_edge_ratio = options.max_radius_edge_ratio;
    settings.min_dihedral_deg = options.min_dihedral_deg;
    settings.quiet = options.quiet;
    return settings;
}

// Mesh_3's vertex bound: this many times the vertices the size predicts, and never under the floor
// (small meshes vary most against the prediction). A cube with one corner moved to x = 1000 (a needle)
// never finished protecting its sharp edges; the bound stops it. Ordinary meshes stay far under it
// (TetrahedralizeTest.CgalStaysFarUnderItsVertexBound).
constexpr double kCgalVertexBoundPerPredicted = 10;
// TetGen's bound on added points for a bounded size, the same way (TetGen adds about 17,000 points a
// second here: skull, 150,000 in 8.7 s, so the floor is a few seconds' work).
constexpr double kTetGenAddedPointsPerPredicted = 10;
constexpr double kTetGenAddedPointFloor = 50'000;
constexpr double kCgalVertexBoundFloor = 50'000;

// Vertices of a mesh of this size: about one per 5 tets inside, plus the surface's at the surface
// edge (an equilateral triangle of edge h has area 0.433 h^2 and a closed surface half as many
// vertices as triangles).
double predicted_vertices(const SizeField& size, double volume, double area) {
    const double h = size.surface_edge;
    return predicted_tets(size, volume, area) / 5 + area / (2 * 0.433 * h * h);
}

TetMesh run_mesher(const TriangleSurface& surface, const MeshingOptions& options, const SizeField& size) {
    check_cancelled(options.progress);
    if (options.mesher == Mesher::Cgal) {
        CgalSettings settings{size, options.max_radius_edge_ratio, options.min_dihedral_deg};
        settings.progress = options.progress;
        // An unbounded size is meshed at a twentieth of the box diagonal (cgal_mesher.cpp).
        SizeField predicted_size = size;
        if (!size.is_bounded()) {
            Eigen::AlignedBox3d box;
            for (const auto& p : surface.points) box.extend(p);
            predicted_size = SizeField::uniform(box.diagonal().norm() / 20);
        }
        const double predicted = predicted_vertices(predicted_size, enclosed_volume(surface), surface_area(surface));
        settings.predicted_vertices = static_cast<size_t>(std::ceil(predicted));
        settings.max_vertices =
            static_cast<size_t>(std::max(kCgalVertexBoundFloor, std::ceil(kCgalVertexBoundPerPredicted * predicted)));
        return cgal_tetrahedralize(surface, settings);
    }
    report_stage(options.progress, "meshing (TetGen)");
    TetGenSettings settings = tetgen_settings(options, size);
    if (!size.is_bounded()) return tetgen_tetrahedralize(surface, settings);
    // TetGen keeps every input triangle, and a detailed surface can need far more refinement than the
    // size asks for (bad_stanford-bunny.obj, 70K triangles, at the default size: CGAL makes 15K tets
    // in 5 s, TetGen's two quality runs had not finished after 110 s). TetGen's own limit on added
    // points bounds that work, at many times what the size predicts.
    const double predicted = predicted_vertices(size, enclosed_volume(surface), surface_area(surface));
    settings.max_added_points =
        static_cast<long>(std::max(kTetGenAddedPointFloor, std::ceil(kTetGenAddedPointsPerPredicted * predicted)));
    bool stopped = false;
    TetMesh mesh = tetgen_tetrahedralize(surface, settings, &stopped);
    if (stopped)
        throw OutOfTetGenReach(
            "TetGen stopped at its limit of " + std::to_string(settings.max_added_points) +
                " added points, where this size needs about " +
                std::to_string(static_cast<long>(std::ceil(predicted))) + " vertices: it keeps the surface's " +
                std::to_string(surface.triangles.size()) +
                " triangles, and they need far more refinement than the size asks for; use the CGAL mesher "
                "(--mesher cgal), which remeshes the surface",
            "TetGen stopped at its limit of " + std::to_string(settings.max_added_points) +
                " added points: the surface's " + std::to_string(surface.triangles.size()) +
                " triangles need far more refinement than the size asks for");
    return mesh;
}

// The error for a target below TetGen's floor on this surface (`floor`: what it needs).
[[noreturn]] void refuse_tetgen_target(size_t target, const std::string& floor) {
    throw OutOfTetGenReach("meshing option sizing.target_tets = " + std::to_string(target) +
                               ": TetGen keeps the surface's triangles and needs " + floor +
                               "; ask for more tets or use the CGAL mesher "
                               "(--mesher cgal), which remeshes the surface",
                           "TetGen keeps the surface's triangles and needs " + floor);
}

// TetGen keeps every input triangle, so a small target may be out of its reach. Its bare constrained
// Delaunay tetrahedralization costs a fraction of a quality run (skull, 100K triangles: 284,411 tets
// in 3.6 s, where the coarsest quality mesh has 1,732,676 and takes 66 s), and the quality bounds only
// add vertices to it (1.4-6x the tets on the shared meshes): when it alone is over the promise, the
// target is refused at once.
void check_tetgen_bare_floor(const TriangleSurface& surface, const MeshingOptions& options, size_t target) {
    report_stage(options.progress, "meshing (TetGen, bare floor check)");
    TetGenSettings bare;
    bare.size = SizeField::unbounded();
    bare.quality = false;
    bare.quiet = options.quiet;
    const size_t bare_count = tetgen_tetrahedralize(surface, bare).tet_count();
    if (double(bare_count) > (1 + kTargetPromise) * double(target))
        refuse_tetgen_target(target, "more than " + std::to_string(bare_count) +
                                         " tets on this surface (its tetrahedralization without quality bounds "
                                         "has that many)");
}

// About `target` tets: a uniform edge length from V / target, then secant steps on log(count) against
// log(edge) (count ~ edge^-3 where the size bound, not the surface, decides the mesh). With TetGen,
// the quality mesh without a size bound is the coarsest it can make (it keeps every input triangle):
// a target the first pass overshoots, or one under kBareCheckTetsPerTriangle tets per triangle, is
// checked against it (for the latter first, after the bare check: a pass at the target's edge would
// only overshoot too). Both runs that may overshoot are cut short by a limit on added points.
// `closest`, when given, is told the count of the closest pass when the target is missed.
TetMesh mesh_to_target(const TriangleSurface& surface, const MeshingOptions& options, size_t target,
                       double volume, size_t* closest = nullptr) {
    const bool tetgen = options.mesher == Mesher::TetGen;
    const bool small_target = tetgen && (1 + kTargetPromise) * double(target) <
                                            kBareCheckTetsPerTriangle * double(surface.triangles.size());
    TetMesh best;
    double best_error = INFINITY;
    const auto consider = [&](TetMesh mesh) {
        const double error = std::abs(double(mesh.tet_count()) - double(target)) / double(target);
        if (error < best_error) {
            best_error = error;
            best = std::move(mesh);
        }
    };
    // TetGen refines by adding points and never takes one away, and its late refinement is the slow
    // part (skull: 632,604 tets after 150,000 added points in 8.7 s, the finished 1,732,676 in 66 s).
    // So the runs that may overshoot (the quality floor, the first pass) are cut short once they have
    // added points for more tets than the promise allows (kTetsPerAddedPointForFloorCheck).
    const double most = (1 + kTargetPromise) * double(target);
    const auto run_capped = [&](const SizeField& size, bool& stopped) {
        TetGenSettings settings = tetgen_settings(options, size);
        settings.max_added_points = static_cast<long>(std::ceil(most / kTetsPerAddedPointForFloorCheck));
        check_cancelled(options.progress);
        report_stage(options.progress, "meshing (TetGen, capped run)");
        return tetgen_tetrahedralize(surface, settings, &stopped);
    };
    bool floor_checked = false;
    const auto check_quality_floor = [&] {
        floor_checked = true;
        // Stopped with more tets than allowed, the run shows the target out of reach at a part of
        // the cost; finished, it is the coarsest mesh. Only a run stopped with fewer tets (more tets
        // per point than assumed) needs the finished run.
        bool stopped = false;
        TetMesh coarsest = run_capped(SizeField::unbounded(), stopped);
        if (stopped && double(coarsest.tet_count()) > most)
            refuse_tetgen_target(target, "more than " + std::to_string(coarsest.tet_count()) +
                                             " tets on this surface at this quality (its refinement had made that "
                                             "many when it was stopped, unfinished)");
        if (stopped) coarsest = run_mesher(surface, options, SizeField::unbounded());
        if (double(coarsest.tet_count()) > most)
            refuse_tetgen_target(target, "at least " + std::to_string(coarsest.tet_count()) +
                                             " tets on this surface at this quality");
        consider(std::move(coarsest));
    };
    if (small_target) {
        check_tetgen_bare_floor(surface, options, target);
        check_quality_floor();
        if (best_error <= kTargetTolerance) return best;
    }
    const double log_target = std::log(double(target));
    double edge = std::cbrt(kTetsPerRegularVolume * 6 * std::sqrt(2.0) * volume / double(target));
    double slope = 3;  // -d log(count) / d log(edge)
    double previous_log_edge = 0;
    double previous_log_count = 0;
    for (int pass = 0; pass < kMaxTargetPasses; ++pass) {
        TetMesh mesh;
        bool stopped = false;
        if (pass == 0 && tetgen && !floor_checked) {
            mesh = run_capped(SizeField::uniform(edge), stopped);
            if (stopped) {
                // The target's size needs more points than the target allows: the floor decides,
                // and where it is under the target, the first pass runs to the end after all.
                check_quality_floor();
                if (best_error <= kTargetTolerance) break;
                mesh = run_mesher(surface, options, SizeField::uniform(edge));
            }
        } else {
            mesh = run_mesher(surface, options, SizeField::uniform(edge));
        }
        const double log_count = std::log(double(mesh.tet_count()));
        consider(std::move(mesh));
        if (best_error <= kTargetTolerance) break;
        if (pass == 0 && tetgen && !floor_checked && log_count > log_target) {
            check_quality_floor();
            if (best_error <= kTargetTolerance) break;
        }
        const double log_edge = std::log(edge);
        if (pass > 0 && log_edge != previous_log_edge) {
            // Flat stretches (surface-dominated) would give huge steps: keep the slope in [1, 6].
            slope = std::clamp(-(log_count - previous_log_count) / (log_edge - previous_log_edge), 1.0, 6.0);
        }
        previous_log_edge = log_edge;
        previous_log_count = log_count;
        edge = std::exp(log_edge + (log_count - log_target) / slope);
    }
    if (best_error > kTargetPromise) {
        if (closest) *closest = best.tet_count();
        throw AlgorithmError("sizing.target_tets = " + std::to_string(target) + ": the closest of " +
                             std::to_string(kMaxTargetPasses) + " meshing passes had " +
                             std::to_string(best.tet_count()) + " tets");
    }
    return best;
}


// Mesher::Auto. TetGen's bare tetrahedralization of a surface has at least this many tets per
// triangle (1.4 to 2.8 on the shared meshes) and its quality meshes more: a budget under it is out of
// TetGen's reach on the input without trying.
constexpr double kBareTetsPerTriangleAtLeast = 1.4;
// A remeshed surface whose own TetGen floor is still above the budget is remeshed this much coarser,
// one on which no volume bound meets the budget this much finer, at most kMaxRemeshes times in all.
constexpr double kRemeshCoarsening = 1.25;
constexpr int kMaxRemeshes = 3;

struct AutoMeshing {
    TetMesh mesh;
    Mesher mesher = Mesher::TetGen;
    std::string reason;
    std::optional<SurfaceRemeshReport> remeshed;
};

MeshingOptions with_mesher(const MeshingOptions& options, Mesher mesher) {
    MeshingOptions chosen = options;
    chosen.mesher = mesher;
    return chosen;
}

// Why the input surface is not kept before trying TetGen on it, or "" when it may be.
std::string triangle_limit_reason(const TriangleSurface& surface) {
    if (surface.triangles.size() <= kMaxTetGenTriangles) return "";
    return "the surface's " + std::to_string(surface.triangles.size()) + " triangles are more than TetGen takes (" +
           std::to_string(kMaxTetGenTriangles) + ")";
}

std::string remeshed_text(const SurfaceRemeshReport& report) {
    return "; remeshed at edge " + number_text(report.edge) + " (" + std::to_string(report.triangles_out) +
           " triangles) for TetGen";
}

// A size (graded or uniform): TetGen on the input unless the input is far finer than the size's
// surface edge, has more triangles than TetGen takes, or stops TetGen at its point limit; then TetGen
// on the surface remeshed at the surface edge; CGAL on the input when the remeshing fails.
AutoMeshing auto_mesh_to_size(const TriangleSurface& surface, const MeshingOptions& options, const SizeField& size) {
    const MeshingOptions tetgen = with_mesher(options, Mesher::TetGen);
    const double edge = size.surface_edge;
    std::string why = triangle_limit_reason(surface);
    if (why.empty()) {
        if (const double mean = mean_edge_length(surface); options.remesh_edge_ratio * mean < edge) {
            why = "the surface's mean edge (" + number_text(mean) + ") is over " + number_text(options.remesh_edge_ratio) +
                  " times finer than the size's surface edge (" + number_text(edge) + ")";
        } else {
            try {
                return {run_mesher(surface, tetgen, size), Mesher::TetGen,
                        "TetGen keeps the surface's " + std::to_string(surface.triangles.size()) + " triangles",
                        std::nullopt};
            } catch (const OutOfTetGenReach& out_of_reach) {
                why = out_of_reach.reason();
            }
        }
    }
    std::string failure;
    try {
        RemeshedSurface remeshed = remesh_surface(surface, edge, options.progress);
        return {run_mesher(remeshed.surface, tetgen, size), Mesher::TetGen, why + remeshed_text(remeshed.report),
                remeshed.report};
    } catch (const OutOfTetGenReach& e) {
        failure = e.reason();
    } catch (const AlgorithmError& e) {
        failure = e.what();
    }
    return {run_mesher(surface, with_mesher(options, Mesher::Cgal), size), Mesher::Cgal,
            why + "; remeshing for TetGen failed (" + failure + "), so CGAL", std::nullopt};
}

// A budget: TetGen on the input where its triangles fit; otherwise TetGen on the surface remeshed at
// the uniform edge the budget allows (what mesh_to_target starts from), coarser while that surface's
// own floor is above the budget; CGAL on the input when the remeshing fails.
AutoMeshing auto_mesh_to_target(const TriangleSurface& surface, const MeshingOptions& options, size_t target,
                                double volume) {
    const MeshingOptions tetgen = with_mesher(options, Mesher::TetGen);
    std::string why = triangle_limit_reason(surface);
    if (why.empty()) {
        if ((1 + kTargetPromise) * double(target) < kBareTetsPerTriangleAtLeast * double(surface.triangles.size())) {
            why = "the surface's " + std::to_string(surface.triangles.size()) +
                  " triangles need more tets than the budget allows (TetGen keeps them, at least " +
                  number_text(kBareTetsPerTriangleAtLeast) + " tets per triangle)";
        } else {
            try {
                return {mesh_to_target(surface, tetgen, target, volume), Mesher::TetGen,
                        "TetGen keeps the surface's " + std::to_string(surface.triangles.size()) +
                            " triangles within the budget",
                        std::nullopt};
            } catch (const OutOfTetGenReach& out_of_reach) {
                why = out_of_reach.reason();
            }
        }
    }
    std::string failure;
    double edge = std::cbrt(kTetsPerRegularVolume * 6 * std::sqrt(2.0) * volume / double(target));
    for (int remesh = 0; remesh < kMaxRemeshes; ++remesh) {
        RemeshedSurface remeshed;
        try {
            remeshed = remesh_surface(surface, edge, options.progress);
        } catch (const AlgorithmError& e) {
            failure = e.what();
            break;
        }
        size_t closest = 0;
        try {
            const double remeshed_volume = enclosed_volume(remeshed.surface);
            return {mesh_to_target(remeshed.surface, tetgen, target, remeshed_volume, &closest), Mesher::TetGen,
                    why + remeshed_text(remeshed.report), remeshed.report};
        } catch (const OutOfTetGenReach& e) {
            failure = e.reason();  // the remeshed surface is still too fine for the budget: coarser
            edge *= kRemeshCoarsening;
        } catch (const AlgorithmError& e) {
            // Every volume bound missed the budget: the surface decides the count (too coarse: spot
            // at 1,000 tets had 747 at best; too fine: a sphere at 2,000 had 2,610), so its edge
            // moves the way the closest count asks.
            failure = e.what();
            if (closest > target) {
                edge *= kRemeshCoarsening;
            } else {
                edge /= kRemeshCoarsening;
            }
        }
    }
    return {mesh_to_target(surface, with_mesher(options, Mesher::Cgal), target, volume), Mesher::Cgal,
            why + "; remeshing for TetGen failed (" + failure + "), so CGAL", std::nullopt};
}

}  // namespace

std::string mesher_name(Mesher mesher) {
    switch (mesher) {
    case Mesher::TetGen: return "tetgen";
    case Mesher::Cgal: return "cgal";
    case Mesher::Auto: return "auto";
    }
    return "unknown";
}

MeshingResult tetrahedralize(const TriangleSurface& surface, const MeshingOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    validate_options(options);
    report_stage(options.progress, "checking the surface for meshing");
    validate_surface(surface);
    if (options.mesher == Mesher::TetGen && surface.triangles.size() > kMaxTetGenTriangles)
        throw InvalidArgumentError(
            "TetGen keeps every one of the surface's " + std::to_string(surface.triangles.size()) +
            " triangles, and its quality meshes of more than " + std::to_string(kMaxTetGenTriangles) +
            " take over a minute (horse.ply, 96966 triangles: 93 s); use the CGAL mesher (--mesher cgal), "
            "which remeshes the surface, or simplify the surface");
    const double volume = enclosed_volume(surface);
    const double area = surface_area(surface);

    MeshingResult result;
    const MeshSizing& sizing = options.sizing;
    std::optional<SizeField> size;  // none: a target count
    if (sizing.edge_length) {
        size = SizeField::uniform(*sizing.edge_length);
        check_predicted_size(*size, volume, area, "sizing.edge_length = " + number_text(*sizing.edge_length));
    } else if (!sizing.target_tets) {
        size = SizeField{sizing.surface_edge, sizing.grading,
                         sizing.max_edge > 0 ? sizing.max_edge : SizeField::unbounded().max_edge};
        check_predicted_size(*size, volume, area, "sizing.surface_edge = " + number_text(sizing.surface_edge));
    }
    if (options.mesher == Mesher::Auto) {
        AutoMeshing chosen = size ? auto_mesh_to_size(surface, options, *size)
                                  : auto_mesh_to_target(surface, options, *sizing.target_tets, volume);
        result.mesh = std::move(chosen.mesh);
        result.mesher = chosen.mesher;
        result.mesher_reason = "auto: " + chosen.reason;
        result.surface_remeshed = chosen.remeshed;
    } else {
        result.mesh = size ? run_mesher(surface, options, *size)
                           : mesh_to_target(surface, options, *sizing.target_tets, volume);
        result.mesher = options.mesher;
        result.mesher_reason = "chosen";
    }
    check_cancelled(options.progress);
    report_stage(options.progress, "ordering the mesh");
    sort_spatially(result.mesh);
    report_stage(options.progress, "measuring quality");
    result.quality = measure_quality(result.mesh);
    result.milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
}

MeshingResult tetrahedralize_surface_file(const std::filesystem::path& path, const TriangleSurface& surface,
                                          const MeshingOptions& options) {
    return naming_context(path.string(), [&] { return tetrahedralize(surface, options); });
}

}  // namespace waxwork
