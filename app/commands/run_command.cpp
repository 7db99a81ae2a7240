// `waxwork run SESSION.json -o OUTDIR`: replays a scripted editing session headless (session.h) and
// prints one line per step; OUTDIR/metrics.json holds the same numbers.
#include "app/commands.h"
#include "app/options/help_sections.h"
#include "app/options/live_solver_options.h"
#include "scene/session.h"

#include <CLI/CLI.hpp>

#include <iomanip>
#include <iostream>
#include <memory>

namespace waxwork {
namespace {

struct RunCommandOptions {
    std::string session;
    std::string output;
    LiveSolverChoice solver;
};

void run_run_command(const RunCommandOptions& o) {
    const Session session = read_session(o.session);
    if (!writes_outputs(session))
        std::cerr << "waxwork: " << o.session << ": warning: no render or save step, so only metrics.json is written "
                  << "(add {\"render\": \"a.png\"} or {\"save\": \"a.vtu\"})\n";
    SessionRunOptions run;
    run.backend = parse_live_backend(o.solver.backend);
    run.method = parse_live_method(o.solver.method);
    run.frame_ms = o.solver.frame_ms;
    const SessionResult result = run_session(session, o.output, run);
    if (!result.gpu_fallback_reason.empty())
        std::cerr << "warning: solved on the CPU instead: " << result.gpu_fallback_reason << "\n";
    if (!result.method_fallback_reason.empty())
        std::cerr << "warning: " << result.method_fallback_reason << "\n";
    std::cout << std::fixed << std::setprecision(1) << "loaded the input in " << result.load_ms << " ms ("
              << result.input_tets << " tets)\n";
    for (size_t i = 0; i < result.steps.size(); ++i) {
        const StepMetrics& m = result.steps[i];
        std::cout << "step " << i << " " << m.name << ": " << m.milliseconds << " ms, " << m.tets << " tets, "
                  << m.vertices << " vertices";
        if (m.solver_iterations > 0) std::cout << ", " << m.solver_iterations << " CG iterations";
        std::cout << "\n";
    }
    for (const auto& path : result.written) std::cout << "wrote " << path.string() << "\n";
}

}  // namespace

void add_run_command(CLI::App& app) {
    auto options = std::make_shared<RunCommandOptions>();
    CLI::App* cmd = app.add_subcommand("run", "Replay a scripted editing session (JSON) headless");
    cmd->add_option("session", options->session, "Session file (.json)")->required()->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", options->output, "Directory for the frames, saved volumes and metrics.json")
        ->required();
    add_live_solver_options(*cmd, options->solver, "in the renderer's OSMesa context");
    cmd->footer("Steps: edit operations ({\"op\": \"plane_cut\", ...}), {\"render\": \"a.png\"}, {\"save\": \"a.vtu\"},\n"
                "{\"light\": {...}}, {\"camera\": {...}}, {\"undo\": 1}, {\"redo\": 1}. See assets/sessions/.");
    organise_help(*cmd, "waxwork run assets/sessions/carve.json -o carve", {});
    cmd->callback([options] { run_run_command(*options); });
}

}  // namespace waxwork
