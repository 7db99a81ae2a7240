#include "tetops/fragments.h"

#include "base/error.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace waxwork {
namespace {

void check_fraction(double max_volume_fraction) {
    if (!(max_volume_fraction >= 0 && max_volume_fraction < 1))
        throw InvalidArgumentError("remove fragments: the volume fraction must be in [0, 1), got " +
                                   number_text(max_volume_fraction));
}

// Per part (TetConnectivity::tet_component): 1 when it is a fragment under the fraction, the largest
// part (the lowest-numbered on a tie) excepted; counts in `survey`.
std::vector<uint8_t> small_parts(const TetMesh& mesh, const TetConnectivity& connectivity, double max_volume_fraction,
                                 FragmentSurvey& survey) {
    check_fraction(max_volume_fraction);
    if (connectivity.tet_component.size() != mesh.tet_count())
        throw InvalidArgumentError("remove fragments: the connectivity is not the volume's");
    const auto part_count = static_cast<size_t>(connectivity.component_count);
    std::vector<double> part_volume(part_count, 0.0);
    std::vector<size_t> part_tets(part_count, 0);
    double total = 0;
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        const double volume = std::abs(signed_volume(mesh, t));
        const auto part = static_cast<size_t>(connectivity.tet_component[t]);
        part_volume[part] += volume;
        ++part_tets[part];
        total += volume;
    }
    survey.parts = part_count;
    const size_t largest =
        static_cast<size_t>(std::max_element(part_volume.begin(), part_volume.end()) - part_volume.begin());
    std::vector<uint8_t> small(part_count, 0);
    for (size_t p = 0; p < part_count; ++p) {
        if (p == largest || !(part_volume[p] < max_volume_fraction * total)) continue;
        small[p] = 1;
        ++survey.small_parts;
        survey.small_part_tets += part_tets[p];
        survey.small_part_volume += part_volume[p];
    }
    return small;
}

}  // namespace

FragmentSurvey survey_fragments(const TetMesh& mesh, const TetConnectivity& connectivity, double max_volume_fraction) {
    FragmentSurvey survey;
    small_parts(mesh, connectivity, max_volume_fraction, survey);
    return survey;
}

FragmentRemoval remove_small_fragments(TetMesh& mesh, double max_volume_fraction) {
    check_fraction(max_volume_fraction);  // before building the connectivity
    FragmentSurvey survey;
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<uint8_t> small = small_parts(mesh, connectivity, max_volume_fraction, survey);
    FragmentRemoval result;
    result.fragments_removed = survey.small_parts;
    result.parts_kept = survey.parts - survey.small_parts;
    result.volume_removed = survey.small_part_volume;
    std::vector<uint8_t> remove(mesh.tet_count());
    for (size_t t = 0; t < mesh.tet_count(); ++t) remove[t] = small[static_cast<size_t>(connectivity.tet_component[t])];
    result.removed = remove_tets(mesh, remove);
    return result;
}

}  // namespace waxwork
