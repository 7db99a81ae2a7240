// A file's extension as the readers and writers dispatch on it: lower case, with its dot (".vtu").
// One place for the rule, so that every format check (surfaces, volumes, session outputs) agrees on
// "Spot.OBJ" and "mesh.Vtu".
#pragma once

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

namespace waxwork {

inline std::string lower_extension(const std::filesystem::path& path) {
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension;
}

}  // namespace waxwork
