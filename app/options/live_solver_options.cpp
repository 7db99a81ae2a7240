#include "app/options/live_solver_options.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <sstream>

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
                    "V-cycle; one V-cycle per 4 iterations of the frame budget; CPU or GPU) or "
                    "multires (the paper's Sec. 4 scheme: BiCGSTAB coarse to fine after a rebuild, then warm "
                    "level-0 CG per frame; CPU or GPU)")
        ->check(CLI::IsMember({"jacobi", "mgcg", "multires"}))
        ->capture_default_str();
    // Checked on the text, before conversion: CLI11 would read "nan" as a number.
    const CLI::Validator frame_ms_check(
        [](std::string& text) {
            std::istringstream in(text);
            double ms = 0;
            if (!(in >> ms) || !(in >> std::ws).eof()) return "'" + text + "' is not a number of milliseconds";
            const std::string problem = frame_ms_problem(ms);
            return problem.empty() ? problem : "'" + text + "' " + problem;
        },
        "MS", "frame ms");
    command
        .add_option("--frame-ms", options.frame_ms,
                    "Live solver budget per frame in milliseconds instead of iterations: the CPU methods stop "
                    "iterating at the deadline (an iteration that started finishes; at least one runs per channel), "
                    "so does the GPU multigrid CG (between V-cycles), the other GPU methods predict the iterations "
                    "that fit from the previous frames' times. Default: the "
                    "iteration budget (the editor's slider, a session's frame_iterations)")
        ->check(frame_ms_check);
}

}  // namespace waxwork
