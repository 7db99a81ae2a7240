// Subcommands of the waxwork executable. Each add_*_command registers its options and a callback
// that does the work and throws waxwork::Error on failure (run_cli turns it into the one-line message).
#pragma once

namespace CLI {
class App;
}

namespace waxwork {

inline void register_commands(CLI::App&) {}

}  // namespace waxwork
