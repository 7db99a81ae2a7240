#include "scene/rebuilt_hierarchy.h"

namespace waxwork {

std::optional<MultiresHierarchy> rebuilt_hierarchy(const MultiresHierarchy* previous,
                                                   std::span<const int32_t> new_of_old_vertex,
                                                   const DiffusionMatrix& matrix,
                                                   std::span<const Eigen::Vector3d> positions) {
    if (!previous || new_of_old_vertex.empty() || new_of_old_vertex.size() != previous->levels[0].size())
        return std::nullopt;
    return rebuild_multires_hierarchy(*previous, new_of_old_vertex, matrix, positions);
}

}  // namespace waxwork
