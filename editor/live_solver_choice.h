// The live-solver options shared by the commands that solve frame by frame (`edit`, `run`):
//   --backend cpu|gpu --method jacobi|mgcg|multires --frame-ms MS
#pragma once

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

// The largest --frame-ms (a frame of 10 s is no longer live; a larger value is more likely a typo).
constexpr double kMaxFrameMilliseconds = 10000;
// Checks a frame time in ms: finite and in (0, kMaxFrameMilliseconds]. Returns "" when valid, else
// what is wrong (for the option's and the session file's one-line errors).
std::string frame_ms_problem(double milliseconds);

// Registers the options on `command`; `gpu_context` says where the GPU backend runs (it differs
// between the window and headless replays).
void add_live_solver_options(CLI::App& command, LiveSolverChoice& options, const std::string& gpu_context);

}  // namespace waxwork
