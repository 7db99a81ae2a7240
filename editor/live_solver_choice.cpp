#include "editor/live_solver_choice.h"

#include <CLI/CLI.hpp>

namespace waxwork {

void add_live_solver_options(CLI::App& command, LiveSolverChoice& options, const std::string& gpu_context) {
    command
        .add_option("--backend", options.backend,
                    "Live solver backend: cpu, or gpu (CG on OpenGL compute shaders " + gpu_context +
                        "; falls back to the CPU, saying why, when the driver cannot run it)")
        ->check(CLI::IsMember({"cpu", "gpu"}))
        ->capture_default_str();
    command
        .add_option("--method", options.method,
                    "Live solver method on the CPU: jacobi (Jacobi CG per channel) or mgcg (multigrid CG, three "
                    "channels per V-cycle; one V-cycle per 4 iterations of the frame budget)")
        ->check(CLI::IsMember({"jacobi", "mgcg"}))
        ->capture_default_str();
}

}  // namespace waxwork
