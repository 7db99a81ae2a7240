#include "tetops/mesher_scale.h"

#include "base/error.h"

#include <Eigen/Geometry>

#include <cmath>
#include <string>

namespace waxwork {
namespace {

// Diagonals within [2^kSmallest, 2^kLargest] are meshed at their own scale.
constexpr int kSmallestExponent = -10;
constexpr int kLargestExponent = 20;

Eigen::Vector3d scaled(const Eigen::Vector3d& p, int exponent) {
    return {std::ldexp(p.x(), exponent), std::ldexp(p.y(), exponent), std::ldexp(p.z(), exponent)};
}

}  // namespace

int mesher_scale_exponent(const TriangleSurface& surface) {
    Eigen::AlignedBox3d box;
    for (const auto& p : surface.points) box.extend(p);
    const double diagonal = surface.points.empty() ? 0.0 : box.diagonal().norm();
    if (!(diagonal > 0) || !std::isfinite(diagonal))
        throw InvalidArgumentError("the surface's bounding box has a diagonal of " + std::to_string(diagonal) +
                                   ": nothing to mesh");
    int exponent = 0;
    std::frexp(diagonal, &exponent);  // diagonal = m 2^exponent, m in [0.5, 1)
    if (exponent - 1 >= kSmallestExponent && exponent <= kLargestExponent) return 0;
    return 1 - exponent;  // diagonal 2^(1 - exponent) in [1, 2)
}

TriangleSurface scaled_surface(const TriangleSurface& surface, int exponent) {
    TriangleSurface out = surface;
    for (auto& p : out.points) p = scaled(p, exponent);
    return out;
}

SizeField scaled_size_field(const SizeField& size, int exponent) {
    SizeField out = size;
    out.surface_edge = std::ldexp(size.surface_edge, exponent);
    out.max_edge = std::ldexp(size.max_edge, exponent);
    return out;
}

void scale_positions(TetMesh& mesh, int exponent) {
    for (auto& p : mesh.positions) p = scaled(p, exponent);
}

}  // namespace waxwork
