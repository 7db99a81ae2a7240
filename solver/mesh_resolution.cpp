#include "solver/mesh_resolution.h"

#include "base/error.h"
#include "solver/material.h"
#include "tetops/connectivity.h"
#include "tetops/model_scale.h"

#include <algorithm>
#include <cmath>
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
