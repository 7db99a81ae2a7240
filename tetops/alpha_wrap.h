// Repair by rebuilding: CGAL's 3D alpha wrapping (Portaneri et al., "Alpha Wrapping with an Offset",
// SIGGRAPH 2022) turns any triangle soup (open, non-manifold, self-intersecting, several overlapping
// shells, degenerate triangles) into a closed, 2-manifold, intersection-free surface that strictly
// contains it. Two lengths control the result: alpha, the radius of the ball that carves the outside
// (cavities and gaps narrower than about alpha are closed over), and offset, the distance the wrap
// keeps from the input (its vertices lie on the offset surface at that distance).
#pragma once

#include "tetops/triangle_surface.h"

#include <cstddef>
#include <optional>
#include <string>

namespace waxwork {

class Progress;

// Default alpha as a fraction of the bounding-box diagonal D. Why D/100: the material rule's surface
// edge h_s (solver/mesh_resolution.h) lies in [D/150, D/25], so a feature the default mesh resolves
// is wider than alpha and survives. Measured (docs/meshing.md): bad_cow and horse.ply give 18K
// triangles, well under the TetGen limit; halving alpha gives 66K on the cow for a Hausdorff distance
// that moves only from 2.07% to 1.83% of D (its distance is buried self-intersecting parts, not lost
// features), doubling it 5K triangles and 3.15%. An open model whose holes are wider than alpha is
// wrapped on both sides of its shell (hollow, and slow): the default alpha grows to close its holes
// (kDefaultWrapAlphaPerHole), up to kMaxDefaultWrapAlphaFraction.
inline constexpr double kDefaultWrapAlphaFraction = 1.0 / 100.0;
// With holes (loops of edges with one triangle), the default alpha is at least this fraction of the
// widest hole's bounding-box diagonal: a ball of radius alpha passes an opening only if alpha is under
// half its width, and a hole's width is under its box's diagonal. Measured on bad_stanford-bunny.obj
// (widest hole 0.18 D): alpha D/20 closes its holes (one solid component, 8 s), D/100 wraps both
// sides of its shell and ran past 300 s.
inline constexpr double kDefaultWrapAlphaPerHole = 0.3;
// The default alpha never exceeds this fraction of D: a model open that widely (a sheet, a shell
// with its side missing) is better wrapped with an alpha the user chooses.
inline constexpr double kMaxDefaultWrapAlphaFraction = 1.0 / 10.0;
// Default offset as a fraction of alpha: CGAL's own default (alpha / 30). A smaller offset hugs sharp
// features closer but puts more triangles around them; a larger one inflates the model visibly.
inline constexpr double kDefaultWrapOffsetFractionOfAlpha = 1.0 / 30.0;
// The smallest alpha taken, as a fraction of D: the wrap's work and its triangle count grow like
// (D / alpha)^2, and at D/2000 a model takes many minutes and far more triangles than the meshers take.
inline constexpr double kMinWrapAlphaFraction = 1.0 / 2000.0;
// The smallest offset taken, as a fraction of D: below it the offset surface's intersections are
// computed near the limit of double precision relative to the model's size.
inline constexpr double kMinWrapOffsetFraction = 1e-6;

// The error bound of the reported Hausdorff distance, as a fraction of alpha.
inline constexpr double kWrapHausdorffErrorFractionOfAlpha = 0.1;

struct WrapOptions {
    std::optional<double> alpha = std::nullopt;   // model units; default kDefaultWrapAlphaFraction * D
    std::optional<double> offset = std::nullopt;  // model units; default kDefaultWrapOffsetFractionOfAlpha * alpha
};

struct WrapReport {
    double alpha = 0;
    double offset = 0;
    double diagonal = 0;           // of the input's bounding box
    size_t triangles = 0;          // in the wrapped surface
    size_t ignored_triangles = 0;  // input triangles with a missing or non-finite vertex (not wrapped)
    // One-sided Hausdorff distance from the input to the wrap: the farthest any input point lies from
    // the wrapped surface (within alpha/10). About the offset where the wrap follows the input; larger
    // where it closes over a cavity or gap narrower than alpha (by the cavity's depth) and where input
    // triangles are buried inside the wrapped volume (overlapping or nested shells, inner walls), which
    // the wrap drops. Over the triangles wrapped (CGAL's oracle skips zero-area ones).
    double hausdorff = 0;

    // "wrapped (alpha A, offset D): N triangles, Hausdorff distance H (X% of the diagonal)".
    std::string describe() const;
};

struct WrapResult {
    TriangleSurface surface;  // closed, 2-manifold, outward oriented, free of self-intersections
    WrapReport report;
};

// Throws InvalidArgumentError naming --wrap-alpha or --wrap-offset when a given value is not positive
// and finite, or is below its floor relative to `diagonal` (kMinWrapAlphaFraction, kMinWrapOffsetFraction).
void validate_wrap_options(const WrapOptions& options, double diagonal);

// Wraps every usable triangle of `soup` (any connectivity; triangles with a missing or non-finite
// vertex are counted in the report and skipped). Throws InvalidArgumentError on bad options and
// InvalidMeshError when nothing is left to wrap. `progress`, when given, is told the stages
// ("wrapping", "measuring the wrap's distance") and asked to stop during the wrap's flood fill.
WrapResult wrap_surface(const TriangleSurface& soup, const WrapOptions& options, Progress* progress = nullptr);

}  // namespace waxwork
