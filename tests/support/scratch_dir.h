// Scratch directories for tests. ctest runs test processes in parallel, so every directory carries the
// process id: two tests that pick the same name never share (and never clobber) each other's files.
#pragma once

#include <filesystem>
#include <string>
#include <unistd.h>

namespace waxwork::testing {

// A fresh, empty scratch directory for one test, private to this process.
inline std::filesystem::path scratch_dir(const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / ("waxwork_test_" + std::to_string(::getpid())) / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

}  // namespace waxwork::testing
