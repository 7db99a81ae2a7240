#include "tetops/fragments.h"

#include "tetops/connectivity.h"
#include "tetops/error.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace waxwork {

FragmentRemoval remove_small_fragments(TetMesh& mesh, double max_volume_fraction) {
    if (!(max_volume_fraction >= 0 && max_volume_fraction < 1))
        throw InvalidArgumentError("remove fragments: the volume fraction must be in [0, 1), got " +
                                   number_text(max_volume_fraction));
    FragmentRemoval result;
    const TetConnectivity connectivity = build_connectivity(mesh);
    std::vector<double> part_volume(static_cast<size_t>(connectivity.component_count), 0.0);
    double total = 0;
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const double volume = std::abs(signed_volume(mesh, t));
        part_volume[static_cast<size_t>(connectivity.tet_component[t])] += volume;
        total += volume;
    }
    // The largest part stays even when it too is under the threshold (the lowest-numbered on a tie).
    const size_t largest = static_cast<size_t>(std::max_element(part_volume.begin(), part_volume.end()) -
                                               part_volume.begin());
    std::vector<uint8_t> drop_part(part_volume.size(), 0);
    for (size_t p = 0; p < part_volume.size(); ++p) {
        if (p != largest && part_volume[p] < max_volume_fraction * total) {
            drop_part[p] = 1;
            ++result.fragments_removed;
            result.volume_removed += part_volume[p];
        }
    }
    result.parts_kept = part_volume.size() - result.fragments_removed;
    std::vector<uint8_t> remove(mesh.tet_count());
    for (size_t t = 0; t < mesh.tet_count(); ++t)
        remove[t] = drop_part[static_cast<size_t>(connectivity.tet_component[t])];
    result.removed = remove_tets(mesh, remove);
    return result;
}

}  // namespace waxwork
