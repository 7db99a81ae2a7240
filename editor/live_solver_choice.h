// The live-solver options shared by the commands that solve frame by frame (`edit`, `run`):
//   --backend cpu|gpu --method jacobi|mgcg
#pragma once

#include <string>

namespace CLI {
class App;
}

namespace waxwork {

struct LiveSolverChoice {
    std::string backend = "cpu";
    std::string method = "jacobi";
};

// Registers the options on `command`; `gpu_context` says where the GPU backend runs (it differs
// between the window and headless replays).
void add_live_solver_options(CLI::App& command, LiveSolverChoice& options, const std::string& gpu_context);

}  // namespace waxwork
