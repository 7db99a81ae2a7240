#include "app/options/material_options.h"

#include "base/error.h"
#include "solver/material.h"

#include <CLI/CLI.hpp>

namespace waxwork {

void add_material_options(CLI::App& command, MaterialOptions& options) {
    std::string names;
    for (const std::string& name : material_preset_names()) names += (names.empty() ? "" : ", ") + name;
    auto* preset = command.add_option("--material", options.preset, "Measured material preset: " + names);
    auto* mua = command.add_option("--mua", options.mua, "Absorption coefficient mu_a per mm, R,G,B")
                    ->delimiter(',')
                    ->expected(3);
    auto* musp = command.add_option("--musp", options.musp, "Reduced scattering coefficient mu_s' per mm, R,G,B")
                     ->delimiter(',')
                     ->expected(3);
    auto* eta = command.add_option("--eta", options.eta, "Relative index of refraction");
    preset->excludes(mua)->excludes(musp)->excludes(eta);
}

std::optional<TetMaterial> chosen_material(const MaterialOptions& options) {
    if (!options.preset.empty()) return material_preset(options.preset);
    const bool any = !options.mua.empty() || !options.musp.empty() || options.eta != 0;
    if (!any) return std::nullopt;
    if (options.mua.size() != 3 || options.musp.size() != 3 || options.eta == 0)
        throw InvalidArgumentError("a custom material needs all of --mua R,G,B --musp R,G,B --eta N");
    TetMaterial material;
    for (int c = 0; c < 3; ++c) {
        material.mua[c] = options.mua[c];
        material.musp[c] = options.musp[c];
    }
    material.eta = options.eta;
    validate_material(material, "custom material");
    return material;
}

}  // namespace waxwork
