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
                    "Live solver method: jacobi (Jacobi CG per channel), mgcg (multigrid CG, three channels per "
                    "V-cycle; one V-cycle per 4 iterations of the frame budget; CPU only, the GPU runs jacobi) or "
                    "multires (the paper's Sec. 4 scheme: BiCGSTAB coarse to fine after a rebuild, then warm "
                    "level-0 CG per frame; CPU or GPU)")
        ->check(CLI::IsMember({"jacobi", "mgcg", "multires"}))
        ->capture_default_str();
}

}  // namespace waxwork
