// Surface-to-volume meshing: TetGen (default) or CGAL Mesh_3, with quality and size bounds.
#pragma once

#include "tetops/quality.h"
#include "tetops/surface_remesh.h"
#include "tetops/tet_mesh.h"
#include "tetops/triangle_surface.h"

#include <filesystem>
#include <optional>
#include <string>

namespace waxwork {

class Progress;

// Auto: TetGen on the input surface where it can keep the surface's triangles within the size or the
// budget asked for; where it cannot (a budget under what those triangles need, more triangles than
// TetGen takes, or a surface far finer than the size: kAutoRemeshEdgeRatio), TetGen on the surface
// remeshed at the edge the size or budget allows (tetops/surface_remesh.h); CGAL Mesh_3 on the input
// when the remeshing fails. MeshingResult says which ran, why, and whether the surface was remeshed.
enum class Mesher { TetGen, Cgal, Auto };

// "tetgen", "cgal" or "auto".
std::string mesher_name(Mesher mesher);

// How fine the volume is. Exactly one of the three ways is used, in this order of precedence:
// an explicit edge length, a target tet count, or a graded size (fine near the surface, where the
// light varies over the diffusion length, coarser inside).
// - edge_length L: TetGen gets the volume bound -a 2.85 L^3/(6 sqrt 2) (calibrated so the mean edge
//   is ~L); CGAL gets cell_size 0.9 L, facet_size 0.8 L, edge_size L, facet_distance 0.1 L.
// - target_tets N: starts from L = (1.2 * 6 sqrt 2 * V / N)^(1/3), then secant steps on
//   log(count) vs log(L), at most 4 passes, stopping within 10% and failing (AlgorithmError) beyond 20%.
//   TetGen keeps every input triangle, so below the tet count of its unbounded quality mesh (spot:
//   ~50K) it throws InvalidArgumentError; CGAL remeshes the surface and can go coarser, and so does
//   Mesher::Auto (TetGen on the surface remeshed at the edge the target allows).
// - graded: edge(d) = min(surface_edge + grading * d, max_edge) at depth d; max_edge == 0: no cap.
//   TetGen: a quality mesh at max_edge is the background mesh (-m) carrying 0.9 edge(d) per vertex;
//   CGAL: the same rule as a sizing field, d from an AABB tree.
// Targets above kMaxMeshTets, and sizes whose predicted count (1.2 V / regular-tet volume, or the
// graded shell integral) exceeds it, are refused with InvalidArgumentError before any meshing.
struct MeshSizing {
    std::optional<double> edge_length;   // target edge length in model units, uniform
    std::optional<size_t> target_tets;   // about this many tets (within 20%)
    // Graded: edge length at the surface and the growth rate inward (edge(d) = surface_edge + grading*d,
    // capped at max_edge). Used when neither of the above is set.
    double surface_edge = 0;
    double grading = 0.5;
    double max_edge = 0;
};

// The largest mesh made: about a minute's work on a two-core machine at the measured TetGen rate
// (kMeasuredTetsPerSecond, uniform size, from the surface to the finished, ordered mesh). A larger
// one is refused up front with the predicted time.
inline constexpr size_t kMaxMeshTets = 2'000'000;
inline constexpr double kMeasuredTetsPerSecond = 40'000;
// The most surface triangles the meshers take. TetGen keeps every triangle (its mesh of a surface
// has at least 1.4 tets per triangle, and its quality bound adds many more), and CGAL answers a
// distance query on them for every size it asks; both ran past 180 s on a 2M-triangle sphere. More
// are refused up front (InvalidMeshError), before any check or mesher runs.
inline constexpr size_t kMaxSurfaceTriangles = 500'000;

// The most surface triangles TetGen takes (CGAL remeshes the surface and takes up to
// kMaxSurfaceTriangles). TetGen keeps every triangle, and the work of its quality refinement grows
// with them, whatever the size asks for: horse.ply (97K) takes 93 s, the skull's coarsest quality
// mesh (100K) 66 s, where CGAL takes 5 to 10 s. More are refused up front (InvalidArgumentError) with
// the way out. Below the limit a run can still be long: bad_stanford-bunny.obj (70K triangles, holes
// filled) at the default size runs past 90 s in its graded pass (CGAL: 5 s).
inline constexpr size_t kMaxTetGenTriangles = 75'000;

// The smallest radius-edge bound TetGen's refinement ends with (validate_options says why).
inline constexpr double kMinRadiusEdgeRatio = 1.2;

// Mesher::Auto remeshes the surface for a size (graded or --edge) when its mean edge is this many
// times finer than the size's surface edge: TetGen keeps every triangle, so its tets at the surface
// follow them, not the size. The skull (4.5 times finer than the default marble size, 100K
// triangles) has a coarsest quality mesh of 1.7M tets, remeshed 20K at the default size; armadillo
// (3.5 times finer, 41K tets at the default size) and spot (1.4 times) are kept as they are, so their
// default meshes stay what explicit TetGen makes (docs/meshing.md).
inline constexpr double kAutoRemeshEdgeRatio = 4.0;
// The same for a surface made by alpha wrapping (tetops/alpha_wrap.h): any wrap finer than the size is
// remeshed. A wrap approximates its input only to about its alpha anyway, and where the input is a
// sheet its offset leaves slabs two offsets thick that TetGen refines around for minutes (the wrapped
// bad_cow.obj and horse.ply: 18K triangles each, about 100 s kept as they are, 1.5 s remeshed).
inline constexpr double kWrapRemeshEdgeRatio = 1.0;

struct MeshingOptions {
    Mesher mesher = Mesher::TetGen;
    MeshSizing sizing;
    double max_radius_edge_ratio = 2.0;  // TetGen -q bound, >= kMinRadiusEdgeRatio
    double min_dihedral_deg = 10.0;      // TetGen -q/ bound (and CGAL exuder goal)
    // Mesher::Auto with a size remeshes a surface whose mean edge is this many times finer than the
    // size's surface edge (kAutoRemeshEdgeRatio; kWrapRemeshEdgeRatio for a wrapped surface).
    double remesh_edge_ratio = kAutoRemeshEdgeRatio;
    bool quiet = true;
    // Told each stage (checks, each mesher run, ordering, quality) and asked between them whether to
    // stop (CancelledError); CGAL's refinement also stops on its cancel flag. Not owned; may be null.
    Progress* progress = nullptr;
};

struct MeshingResult {
    TetMesh mesh;
    QualityReport quality;
    double milliseconds = 0;
    Mesher mesher = Mesher::TetGen;  // the one that made the mesh (never Auto)
    // Why: "chosen" for an explicit mesher; for Mesher::Auto what decided, e.g. "auto: the surface's
    // 100002 triangles are more than TetGen takes (75000); remeshed for TetGen".
    std::string mesher_reason;
    // Set when Mesher::Auto remeshed the surface before TetGen filled it.
    std::optional<SurfaceRemeshReport> surface_remeshed;
};

// Fills a closed, outward-oriented, self-intersection-free surface with tets. Throws
// InvalidArgumentError on absurd options and AlgorithmError when the mesher fails.
MeshingResult tetrahedralize(const TriangleSurface& surface, const MeshingOptions& options);

// tetrahedralize(surface, options) for the surface read from `path`: its errors name the file
// ("PATH: PROBLEM", the same error type), since the meshers' own messages know no file.
MeshingResult tetrahedralize_surface_file(const std::filesystem::path& path, const TriangleSurface& surface,
                                          const MeshingOptions& options);

}  // namespace waxwork
