// The hierarchy of a multires or multigrid frame solver after an edit, rebuilt from the one before it
// (rebuild_multires_hierarchy: selecting again only around the changed rows) instead of from scratch.
#pragma once

#include "multires/hierarchy.h"
#include "solver/diffusion_matrix.h"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <span>

namespace waxwork {

// `previous` rebuilt around an edit for `matrix` (positions: the mesh's rest positions), or nothing
// when there is no previous hierarchy or the vertex map does not belong to it (then the caller builds
// from scratch).
std::optional<MultiresHierarchy> rebuilt_hierarchy(const MultiresHierarchy* previous,
                                                   std::span<const int32_t> new_of_old_vertex,
                                                   const DiffusionMatrix& matrix,
                                                   std::span<const Eigen::Vector3d> positions);

}  // namespace waxwork
