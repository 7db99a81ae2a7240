// "Model no more than a scene needs": the default mesh size for a surface filled with a material.
//
// Light entering a scattering solid decays over the diffusion length l_d = 1/sigma_tr, so the tets
// near the surface must be small against l_d, while deep inside, where phi is smooth, they may grow.
// The rule (all lengths in model units, D = bounding-box diagonal, l_d the smallest over the rgb
// channels, converted from mm with mm_per_unit):
//   surface edge  h_s = clamp(l_d / 2, D / 150, D / 25)
//   inward growth h(d) = h_s + 0.5 d            (d = depth below the surface)
//   largest edge  h_max = max(h_s, D / 8)
// Why these numbers: linear elements interpolate exp(-x/l_d) with a relative error of about
// h^2 / (8 l_d^2), i.e. ~3% per element at h = l_d/2, and the solution error is smaller still (the
// ball test in tests/solver measures it). The cap D/25 keeps enough resolution of the shape and of the
// incident light (shadow edges, curvature) when l_d is large (marble, milk, spectralon: mu_a -> 0);
// the floor D/150 bounds the cost (a few million tets at most) for strongly absorbing materials on
// large objects, where a finer mesh would not change the rendered image at screen resolution.
#pragma once

#include "tetops/tet_mesh.h"
#include "tetops/tetrahedralize.h"
#include "tetops/triangle_surface.h"

#include <string>
#include <vector>

namespace waxwork {

struct MeshResolutionRule {
    double diffusion_length_fraction = 0.5;  // h_s <= fraction * l_d
    double finest_fraction_of_diagonal = 1.0 / 150.0;
    double coarsest_surface_fraction_of_diagonal = 1.0 / 25.0;
    double interior_fraction_of_diagonal = 1.0 / 8.0;
    double grading = 0.5;
    // Multiplies the rule's edge lengths (surface and largest): the mesh-size studies' knob
    // (bench/studies/resolution_study.h, accuracy_study.h). 1 is the rule above.
    double size_factor = 1.0;
};

// The smallest diffusion length over the rgb channels, in mm (infinite when every mu_a is 0).
double smallest_diffusion_length_mm(const TetMaterial& material);

// The rule's surface edge h_s, in model units, for a model whose bounding-box diagonal is `diagonal`
// model units (before the rule's size_factor).
double default_surface_edge(double diagonal, const TetMaterial& material, double mm_per_unit,
                            const MeshResolutionRule& rule = {});

// The mean length of the edges of the mesh's boundary faces (each face's three edges; edges shared by
// two faces count twice, which weights them alike): what default_surface_edge asks of a mesh, to say
// how far an existing mesh is from the rule at another scale. Zero for a mesh without tets.
double mean_surface_edge_length(const TetMesh& mesh);

// An existing mesh against the rule (lengths in mm): the mean surface edge, the rule's h_s for the
// mesh's bounding box, and the smallest diffusion length, for the material the rule is hardest on.
struct ResolutionFit {
    double surface_edge_mm = 0;
    double rule_edge_mm = 0;
    double diffusion_length_mm = 0;
    std::string material;  // which material set the rule (its name or "the finest of N materials")
};

// `materials`: per tet (the hardest one counts: the smallest diffusion length). Throws
// InvalidArgumentError for an empty mesh or material list.
ResolutionFit fit_to_resolution_rule(const TetMesh& mesh, const std::vector<TetMaterial>& materials,
                                     double mm_per_unit);

// Within this factor of the rule's edge either way, the rule's error estimate (about h^2) changes by at
// most 2.25x: what the editor's scale panel and the benchmarks' warnings accept.
inline constexpr double kResolutionTolerance = 1.5;

// A warning, or "" when the mesh resolves the light: its mean surface edge is more than
// kResolutionTolerance times the rule's light term (l_d / 2). The rule's clamps are left out: its cost
// floor D/150 can ask for edges longer than l_d (each linear element then interpolates exp(-x/l_d) with
// over 10% error; the stability study measures 20-40% there), and its shape cap D/25 asks for shorter
// edges than the light needs.
std::string under_resolution_warning(const ResolutionFit& fit);

// Graded sizing for `surface` filled with `material` at mm_per_unit millimetres per model unit.
MeshSizing default_mesh_sizing(const TriangleSurface& surface, const TetMaterial& material, double mm_per_unit,
                               const MeshResolutionRule& rule = {});

}  // namespace waxwork
