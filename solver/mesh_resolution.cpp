#include "solver/mesh_resolution.h"

#include "base/error.h"
#include "solver/material.h"
#include "tetops/connectivity.h"
#include "tetops/model_scale.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace waxwork {

double smallest_diffusion_length_mm(const TetMaterial& material) {
    double shortest = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 3; ++c) shortest = std::min(shortest, diffusion_length(material.mua[c], material.musp[c]));
    return shortest;
}

double default_surface_edge(double diagonal, const TetMaterial& material, double mm_per_unit,
                            const MeshResolutionRule& rule) {
    const double diffusion_length_units = smallest_diffusion_length_mm(material) / mm_per_unit;
    return std::clamp(rule.diffusion_length_fraction * diffusion_length_units, rule.finest_fraction_of_diagonal * diagonal,
                      rule.coarsest_surface_fraction_of_diagonal * diagonal);
}

double mean_surface_edge_length(const TetMesh& mesh) {
    const TetConnectivity connectivity = build_connectivity(mesh);
    double sum = 0;
    for (const BoundaryFace& face : connectivity.boundary_faces)
        for (int k = 0; k < 3; ++k)
            sum += (mesh.positions[face.vertices[(k + 1) % 3]] - mesh.positions[face.vertices[k]]).norm();
    return connectivity.boundary_faces.empty() ? 0.0 : sum / (3.0 * static_cast<double>(connectivity.boundary_faces.size()));
}

ResolutionFit fit_to_resolution_rule(const TetMesh& mesh, const std::vector<TetMaterial>& materials,
                                     double mm_per_unit) {
    validate_mm_per_unit(mm_per_unit);
    if (mesh.tet_count() == 0 || materials.empty())
        throw InvalidArgumentError("cannot compare an empty mesh with the mesh-size rule");
    const TetMaterial* hardest = &materials.front();
    size_t distinct = 1;
    for (const TetMaterial& m : materials) {
        if (m == *hardest) continue;
        ++distinct;
        if (smallest_diffusion_length_mm(m) < smallest_diffusion_length_mm(*hardest)) hardest = &m;
    }
    ResolutionFit fit;
    fit.surface_edge_mm = mean_surface_edge_length(mesh) * mm_per_unit;
    fit.rule_edge_mm = default_surface_edge(bounding_extent(mesh.positions).norm(), *hardest, mm_per_unit) * mm_per_unit;
    fit.diffusion_length_mm = smallest_diffusion_length_mm(*hardest);
    fit.material = distinct == 1 ? "its material" : "its most absorbing material";
    return fit;
}

std::string under_resolution_warning(const ResolutionFit& fit) {
    // The rule's light term alone: its clamps bound the cost (D/150) and follow the shape (D/25), which
    // say nothing of how well the light is resolved.
    const double light_edge_mm = MeshResolutionRule{}.diffusion_length_fraction * fit.diffusion_length_mm;
    if (!(fit.surface_edge_mm > kResolutionTolerance * light_edge_mm)) return "";
    char text[400];
    std::snprintf(text, sizeof text,
                  "the mesh under-resolves the light: mean surface edge %.3g mm against a diffusion length of %.3g mm "
                  "for %s (the mesh-size rule asks for %.3g mm at this size and scale); the diffusion solution's error "
                  "grows with (edge / diffusion length)^2",
                  fit.surface_edge_mm, fit.diffusion_length_mm, fit.material.c_str(), fit.rule_edge_mm);
    return text;
}

MeshSizing default_mesh_sizing(const TriangleSurface& surface, const TetMaterial& material, double mm_per_unit,
                               const MeshResolutionRule& rule) {
    validate_mm_per_unit(mm_per_unit);
    validate_material(material);
    if (surface.points.empty()) throw InvalidArgumentError("cannot size an empty surface");
    if (!(rule.size_factor > 0) || !std::isfinite(rule.size_factor))
        throw InvalidArgumentError("mesh size factor must be a positive number");
    const double diagonal = bounding_extent(surface.points).norm();
    if (!(diagonal > 0)) throw InvalidArgumentError("cannot size a surface whose bounding box is a point");

    MeshSizing sizing;
    sizing.surface_edge = default_surface_edge(diagonal, material, mm_per_unit, rule);
    sizing.grading = rule.grading;
    sizing.max_edge = std::max(sizing.surface_edge, rule.interior_fraction_of_diagonal * diagonal);
    sizing.surface_edge *= rule.size_factor;
    sizing.max_edge *= rule.size_factor;
    return sizing;
}

}  // namespace waxwork
