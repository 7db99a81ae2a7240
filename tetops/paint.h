// Volumetric painting (TransCut Sec. 5, "Painting Interaction"): a stroke of 3D points blends a brush
// material into the tets around it with a Gaussian of the distance from each tet's centroid to the
// nearest stroke point, w = exp(-d^2 / (2 sigma^2)), material <- (1 - w) material + w brush. Tets with
// w under a cutoff are left exactly as they were, and the changed tets are returned so the solver can
// update only the matrix rows of their vertices (paper: "we only update the rows corresponding to the
// vertices of tetrahedra that are affected").
//
// The paper evaluates every tet against every stroke point; at 500K tets that is too slow for a
// live brush, so tet centroids go into a kd-tree (nanoflann, Debian libnanoflann-dev) built once per
// mesh state and queried with the cutoff radius around each stroke point.
#pragma once

#include "tetops/tet_mesh.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace waxwork {

struct PaintBrush {
    TetMaterial material;
    double sigma = 0;             // Gaussian width in world units (> 0)
    double cutoff_weight = 1e-3;  // tets whose weight is below this are untouched; in (0, 1)
};

// Centroids of the tets in world space (rotation * centroid + translation of the tet's piece) in a
// kd-tree. Valid until the mesh is cut or a piece moves; rebuild then.
class PaintIndex {
public:
    explicit PaintIndex(const TetMesh& mesh);
    ~PaintIndex();
    PaintIndex(PaintIndex&&) noexcept;
    PaintIndex& operator=(PaintIndex&&) noexcept;

    size_t tet_count() const;
    const std::vector<Eigen::Vector3d>& centroids() const;

    // Every tet whose centroid is within `radius` of some point of `stroke`, with the squared distance
    // to the nearest such point, ascending by tet. Each tet is reported once however many stroke points
    // reach it (overlapping balls of a dense stroke are the common case).
    std::vector<std::pair<uint32_t, double>> nearest_within(std::span<const Eigen::Vector3d> stroke,
                                                            double radius) const;

private:
    struct Tree;
    std::unique_ptr<Tree> tree_;
};

struct PaintResult {
    std::vector<int32_t> changed_tets;  // ascending
    std::vector<double> weights;        // per changed tet, the blend weight w applied
};

// The radius beyond which a brush weight falls below its cutoff: sigma sqrt(-2 ln cutoff).
double paint_radius(const PaintBrush& brush);

// Blends `brush` into the tets near `stroke` (world-space points). When the mesh stores no
// materials, every tet first gets `base` (required then: InvalidArgumentError without it). Throws
// InvalidArgumentError for sigma <= 0, a cutoff outside (0, 1), an empty stroke, non-finite points or
// an index built for a different mesh.
PaintResult paint_stroke(TetMesh& mesh, const PaintIndex& index, std::span<const Eigen::Vector3d> stroke,
                         const PaintBrush& brush, const std::optional<TetMaterial>& base = std::nullopt);

// Convenience for a single stroke: builds the index, then paints.
PaintResult paint_stroke(TetMesh& mesh, std::span<const Eigen::Vector3d> stroke, const PaintBrush& brush,
                         const std::optional<TetMaterial>& base = std::nullopt);

}  // namespace waxwork
