// The live-solver options shared by the commands that solve frame by frame (`edit`, `run`):
//   --backend cpu|gpu --method jacobi|mgcg|multires --frame-ms MS
#pragma once

#include "solver/frame_budget.h"

#include <optional>
#include <string>

namespace CLI {
class App;
}

namespace waxwork {

struct LiveSolverChoice {
    std::string backend = "cpu";
    std::string method = "jacobi";
    // --frame-ms: a time budget per live frame (solver/frame_budget.h) instead of the iteration budget;
    // nullopt: the iteration budget (the editor's slider, a session's frame_iterations).
    std::optional<double> frame_ms;
};

// Registers the options on `command`; `gpu_context` says where the GPU backend runs (it differs
// between the window and headless replays).
void add_live_solver_options(CLI::App& command, LiveSolverChoice& options, const std::string& gpu_context);

}  // namespace waxwork
