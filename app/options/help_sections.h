// The layout of a command's --help for the reader who opens it first: what the command does and an
// example, then the options most uses need, then the rest in named sections (meshing, custom
// materials, solver details), in the order given.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace waxwork {

struct HelpSection {
    std::string title;
    std::vector<std::string> options;  // long names, "--mesher"
};

// Moves the named options of `command` into `sections` (printed after the ungrouped ones, in this
// order) and prints `example` under the description. Throws std::logic_error for a name the command
// does not have (a typo here is a programming error, caught by the help tests).
void organise_help(CLI::App& command, const std::string& example, const std::vector<HelpSection>& sections);

}  // namespace waxwork
