// Runs the waxwork executable from tests and captures what it prints.
#pragma once

#include "support/scratch_dir.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

namespace waxwork::testing {

// The assets (meshes, sessions) the commands under test read.
inline const std::string kAssets = WAXWORK_ASSET_DIR;

struct CommandResult {
    int exit_code = -1;
    std::string out;
    std::string err;
};

inline std::string read_text(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// `arguments` is appended to the binary's path as-is (quote paths with spaces yourself); `launcher`
// (e.g. "xvfb-run -a ") is put before it.
inline CommandResult run_waxwork(const std::string& arguments, const std::string& launcher = "") {
    static int counter = 0;
    const auto dir = std::filesystem::temp_directory_path();
    const std::string tag = std::to_string(::getpid()) + "_" + std::to_string(counter++);
    const auto out_path = dir / ("waxwork_out_" + tag), err_path = dir / ("waxwork_err_" + tag);
    const std::string command = launcher + std::string(WAXWORK_BINARY) + " " + arguments + " >" + out_path.string() + " 2>" +
                                err_path.string() + " </dev/null";
    const int status = std::system(command.c_str());
    CommandResult result;
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    result.out = read_text(out_path);
    result.err = read_text(err_path);
    std::filesystem::remove(out_path);
    std::filesystem::remove(err_path);
    return result;
}

// Number of lines in captured output (a one-line error message has exactly one).
inline size_t line_count(const std::string& s) { return static_cast<size_t>(std::count(s.begin(), s.end(), '\n')); }

// Whether xvfb-run is installed (the window tests skip without it).
inline bool have_xvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

// Runs waxwork under its own virtual display (-a: a free server number, so tests may run in
// parallel); `environment` (e.g. "VAR=1 ") is put before the launcher. The editor's state (recent
// files, recovery copies) goes to a folder of this test process unless `environment` sets
// WAXWORK_STATE_DIR: never the user's, and no test sees another's recovery offer.
inline CommandResult run_under_xvfb(const std::string& arguments, const std::string& environment = "") {
    std::string state;
    if (environment.find("WAXWORK_STATE_DIR=") == std::string::npos)
        state = "WAXWORK_STATE_DIR=" + (std::filesystem::temp_directory_path() /
                                        ("waxwork_test_" + std::to_string(::getpid())) / "editor_state").string() + " ";
    return run_waxwork(arguments, state + environment + "xvfb-run -a -s '-screen 0 1280x1024x24' ");
}

}  // namespace waxwork::testing
