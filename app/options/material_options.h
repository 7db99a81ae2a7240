// The material options shared by every command that assigns a material:
//   --material NAME | --mua R,G,B --musp R,G,B --eta N
#pragma once

#include "tetops/tet_mesh.h"

#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace waxwork {

struct MaterialOptions {
    std::string preset;
    std::vector<double> mua;
    std::vector<double> musp;
    double eta = 0;  // 0: not given
};

// Registers the options on `command`; --material excludes the coefficient options.
void add_material_options(CLI::App& command, MaterialOptions& options);

// The material the options describe, validated; nullopt when none was given. Throws
// InvalidArgumentError for incomplete or invalid coefficients.
std::optional<TetMaterial> chosen_material(const MaterialOptions& options);

}  // namespace waxwork
