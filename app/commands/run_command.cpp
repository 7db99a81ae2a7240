// `waxwork run SESSION.json -o OUTDIR`: replays a scripted editing session headless (session.h) and
// prints one line per step; OUTDIR/metrics.json holds the same numbers. With `--engine petsc` under
// mpirun, sessions of renders, saves, lights and cameras solve with the processes (distributed_session.h).
#include "app/cli.h"
#include "app/commands.h"
#include "app/options/engine_options.h"
#include "app/options/help_sections.h"
#include "app/options/live_solver_options.h"
#include "base/error.h"
#include "scene/distributed_session.h"
#include "scene/session.h"
#include "solver/petsc_peers.h"
#include "solver/petsc_runtime.h"

#include <CLI/CLI.hpp>

#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>

namespace waxwork {
namespace {

struct RunCommandOptions {
    std::string session;
    std::string output;
    LiveSolverChoice solver;
    EngineOptions engine;
};

// One line per step, then the files written.
void print_steps(const std::vector<StepMetrics>& steps, const std::vector<std::filesystem::path>& written) {
    for (size_t i = 0; i < steps.size(); ++i) {
        const StepMetrics& m = steps[i];
        std::cout << "step " << i << " " << m.name << ": " << m.milliseconds << " ms, " << m.tets << " tets, "
                  << m.vertices << " vertices";
        if (m.solver_iterations > 0) std::cout << ", " << m.solver_iterations << " CG iterations";
        std::cout << "\n";
    }
    for (const auto& path : written) std::cout << "wrote " << path.string() << "\n";
}

#ifdef WAXWORK_HAVE_PETSC
// `--engine petsc`: the session read by every process (errors agreed), its renders solved together,
// rank 0 writing the files and printing the lines (no metrics.json).
void run_distributed(const RunCommandOptions& o) {
    const ProgramArguments arguments = program_arguments();
    ensure_petsc_runtime(arguments.argc, arguments.argv);
    std::optional<Session> session;
    agreed_step([&] { session.emplace(read_session(o.session)); });
    const DistributedSessionResult result = run_session_distributed(*session, o.output, chosen_preconditioner(o.engine));
    if (result.rank != 0) return;
    std::cout << std::fixed << std::setprecision(1) << "loaded the input in " << result.load_ms << " ms ("
              << result.input_tets << " tets) on each of " << result.processes << " processes; edge cut "
              << result.edge_cut << " of " << result.edges << " edges\n";
    print_steps(result.steps, result.written);
}
#endif

void run_run_command(const RunCommandOptions& o) {
    check_engine_options(o.engine);
    if (o.engine.petsc()) {
        if (o.solver.backend != "cpu" || o.solver.method != "jacobi" || o.solver.frame_ms)
            throw InvalidArgumentError("--engine petsc solves converged renders with PETSc: --backend, --method and "
                                       "--frame-ms choose the live solver of --engine cpu");
#ifdef WAXWORK_HAVE_PETSC
        return run_distributed(o);
#endif
    }
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
    print_steps(result.steps, result.written);
}

}  // namespace

void add_run_command(CLI::App& app) {
    auto options = std::make_shared<RunCommandOptions>();
    CLI::App* cmd = app.add_subcommand("run", "Replay a scripted editing session (JSON) headless");
    cmd->add_option("session", options->session, "Session file (.json)")->required()->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", options->output, "Directory for the frames, saved volumes and metrics.json")
        ->required();
    add_live_solver_options(*cmd, options->solver, "in the renderer's OSMesa context");
    add_engine_options(*cmd, options->engine, "the renders of a session of renders, saves, lights and cameras");
    cmd->footer("Steps: edit operations ({\"op\": \"plane_cut\", ...}), {\"render\": \"a.png\"}, {\"save\": \"a.vtu\"},\n"
                "{\"light\": {...}}, {\"camera\": {...}}, {\"undo\": 1}, {\"redo\": 1}. See assets/sessions/.");
    organise_help(*cmd, "waxwork run assets/sessions/carve.json -o carve", {});
    cmd->callback([options] { run_run_command(*options); });
}

}  // namespace waxwork
