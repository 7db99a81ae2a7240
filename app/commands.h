// Subcommands of the waxwork executable. Each add_*_command registers its options and a callback
// that does the work and throws waxwork::Error on failure (run_cli turns it into the one-line message).
#pragma once

namespace CLI {
class App;
}

namespace waxwork {

void add_mesh_command(CLI::App& app);
void add_info_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_turntable_command(CLI::App& app);
void add_export_command(CLI::App& app);
void add_demo_command(CLI::App& app);
void add_cut_command(CLI::App& app);
void add_fracture_command(CLI::App& app);
void add_paint_command(CLI::App& app);
void add_deform_command(CLI::App& app);
void add_refine_command(CLI::App& app);
void add_run_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_edit_command(CLI::App& app);

inline void register_commands(CLI::App& app) {
    add_mesh_command(app);
    add_info_command(app);
    add_render_command(app);
    add_turntable_command(app);
    add_export_command(app);
    add_cut_command(app);
    add_fracture_command(app);
    add_paint_command(app);
    add_deform_command(app);
    add_refine_command(app);
    add_run_command(app);
    add_demo_command(app);
    add_bench_command(app);
    add_edit_command(app);
}

}  // namespace waxwork
