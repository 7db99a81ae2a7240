#include "solver/mesh_resolution.h"

#include "base/error.h"
#include "solver/material.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace waxwork {

double smallest_diffusion_length_mm(const TetMaterial& material) {
    double shortest = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 3; ++c) shortest = std::min(shortest, diffusion_length(material.mua[c], material.musp[c]));
    return shortest;
}

MeshSizing default_mesh_sizing(const TriangleSurface& surface, const TetMaterial& material, double mm_per_unit,
                               const MeshResolutionRule& rule) {
    validate_mm_per_unit(mm_per_unit);
    validate_material(material);
    if (surface.points.empty()) throw InvalidArgumentError("cannot size an empty surface");
    if (!(rule.size_factor > 0) || !std::isfinite(rule.size_factor))
        throw InvalidArgumentError("mesh size factor must be a positive number");
    Eigen::Vector3d lo = surface.points.front(), hi = lo;
    for (const auto& p : surface.points) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    const double diagonal = (hi - lo).norm();
    if (!(diagonal > 0)) throw InvalidArgumentError("cannot size a surface whose bounding box is a point");

    const double diffusion_length_units = smallest_diffusion_length_mm(material) / mm_per_unit;
    MeshSizing sizing;
    sizing.surface_edge = std::clamp(rule.diffusion_length_fraction * diffusion_length_units,
                                     rule.finest_fraction_of_diagonal * diagonal,
                                     rule.coarsest_surface_fraction_of_diagonal * diagonal);
    sizing.grading = rule.grading;
    sizing.max_edge = std::max(sizing.surface_edge, rule.interior_fraction_of_diagonal * diagonal);
    sizing.surface_edge *= rule.size_factor;
    sizing.max_edge *= rule.size_factor;
    return sizing;
}

}  // namespace waxwork
