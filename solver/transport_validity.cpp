#include "solver/transport_validity.h"

#include "solver/material.h"

#include <cstring>
#include <sstream>

namespace waxwork {

ReducedAlbedoFloor lowest_reduced_albedo(std::span<const TetMaterial> materials) {
    ReducedAlbedoFloor floor;
    for (size_t t = 0; t < materials.size(); ++t) {
        if (t > 0 && std::memcmp(&materials[t], &materials[t - 1], sizeof(TetMaterial)) == 0) continue;
        const TetMaterial& m = materials[t];
        for (int c = 0; c < 3; ++c) {
            const double extinction = m.mua[c] + m.musp[c];
            const double albedo = extinction > 0 ? m.musp[c] / extinction : 0.0;
            if (albedo < floor.reduced_albedo) floor = {albedo, c, m};
        }
    }
    return floor;
}

std::string diffusion_trust_warning(std::span<const TetMaterial> materials) {
    const ReducedAlbedoFloor floor = lowest_reduced_albedo(materials);
    if (floor.reduced_albedo >= kTrustedReducedAlbedo) return "";
    std::string name;
    for (const std::string& preset : material_preset_names())
        if (material_preset(preset) == floor.material) name = preset;
    std::ostringstream line;
    line.precision(3);
    static const char* const kChannels[] = {"red", "green", "blue"};
    line << "live image outside the trusted regime: " << (name.empty() ? "a painted material" : name)
         << " scatters little in " << kChannels[floor.channel] << " (reduced albedo " << floor.reduced_albedo
         << " < " << kTrustedReducedAlbedo << "), where diffusion's light distribution was off by 13-73% "
         << "against Monte Carlo transport (docs/diffusion_vs_transport.md)";
    return line.str();
}

}  // namespace waxwork
