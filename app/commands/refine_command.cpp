// `waxwork refine`: adapts a volume's resolution to its light.
//   waxwork refine VOLUME -o OUT [--max-tets N] [--fraction F] [--rounds R] [light options as render]
// Each round solves the light as `render` does, ranks the tets by the gradient-jump error indicator
// (solver/error_indicator.h), and bisects the top fraction of them conformingly (tetops/refine.h) through
// the Document as a refine edit, never past the budget; rounds stop at the budget, when nothing could be
// refined, or after R rounds. The volume is written atomically (materials only if it stored them) and a
// one-line JSON summary is printed.
#include "app/commands.h"
#include "app/commands/edited_volume.h"
#include "app/options/help_sections.h"
#include "app/options/scene_light_options.h"
#include "app/stderr_progress.h"
#include "base/error.h"
#include "base/timing.h"
#include "io/volume_file.h"
#include "render/volume_render.h"
#include "scene/edit_operation.h"
#include "solver/error_indicator.h"
#include "solver/material.h"
#include "tetops/quality.h"
#include "tetops/refine.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

namespace waxwork {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kMaxRounds = 100;

struct RefineCommandOptions {
    std::string input;
    std::string output;
    std::optional<size_t> max_tets;
    double fraction = 0.2;
    int rounds = 10;
    SceneLightOptions light;
};

// Options first, so that a typing error is reported before the volume is read.
void check_options(const RefineCommandOptions& o) {
    if (o.max_tets && (*o.max_tets == 0 || *o.max_tets > kMaxRefinedTets))
        throw InvalidArgumentError("refine --max-tets: must be between 1 and " + std::to_string(kMaxRefinedTets) +
                                   ", got " + std::to_string(*o.max_tets));
    if (!(o.fraction > 0 && o.fraction <= 1))
        throw InvalidArgumentError("refine --fraction: must be in (0, 1], got " + number_text(o.fraction));
    if (o.rounds < 1 || o.rounds > kMaxRounds)
        throw InvalidArgumentError("refine --rounds: must be between 1 and " + std::to_string(kMaxRounds));
    check_scene_light_options(o.light);
}

// The top `fraction` of the tets by indicator, largest first (ties by index: deterministic).
std::vector<int32_t> largest_indicators(const std::vector<double>& eta, double fraction) {
    std::vector<int32_t> order(eta.size());
    std::iota(order.begin(), order.end(), 0);
    const auto count = std::max<size_t>(1, static_cast<size_t>(std::ceil(fraction * static_cast<double>(eta.size()))));
    const auto end = order.begin() + static_cast<std::ptrdiff_t>(std::min(count, order.size()));
    std::partial_sort(order.begin(), end, order.end(), [&](int32_t a, int32_t b) {
        return eta[a] != eta[b] ? eta[a] > eta[b] : a < b;
    });
    order.erase(end, order.end());
    return order;
}

void run_refine_command(const RefineCommandOptions& o) {
    const auto start = Clock::now();
    check_options(o);
    StderrProgress progress("waxwork: " + o.input + ": ");
    progress.set_stage("reading");
    VolumeFile file = read_volume_file(o.input);
    const ModelScale scale = chosen_scale(o.light, file);
    const VolumeRenderSettings settings = scene_light_settings(o.light, scale);
    if (file.mesh.tet_count() == 0) throw InvalidArgumentError(o.input + ": the volume has no tets to refine");
    const size_t tets_before = file.mesh.tet_count(), vertices_before = file.mesh.vertex_count();
    const size_t budget = o.max_tets.value_or(2 * tets_before);
    if (budget < tets_before)
        throw InvalidArgumentError("refine --max-tets: " + std::to_string(budget) + " is below the volume's " +
                                   std::to_string(tets_before) + " tets (refinement only adds tets)");
    // A volume that stores no materials is solved with the option's or the default one, as render does.
    const TetMaterial base = settings.material.value_or(material_preset("marble"));
    EditedVolume volume(o.input, std::move(file), base, /*write_base=*/false);
    const double min_dihedral_before = mesh_min_dihedral_deg(volume.mesh());

    double solve_ms = 0, estimate_ms = 0, refine_ms = 0;
    size_t bisections = 0, skipped_guard = 0;
    int rounds = 0;
    bool budget_reached = false;
    for (int round = 1; round <= o.rounds && !budget_reached; ++round) {
        progress.set_stage("solving the light (round " + std::to_string(round) + ")");
        auto clock = Clock::now();
        const VolumeLight light = solve_volume_light(volume.mesh(), o.input, settings);
        report_solve_warnings(o.input, light.scene);
        solve_ms += milliseconds_since(clock);
        check_cancelled(&progress);

        progress.set_stage("estimating the error (round " + std::to_string(round) + ")");
        clock = Clock::now();
        const std::vector<double> eta = gradient_jump_indicator(volume.mesh(), light.connectivity,
                                                                light.scene.diffusion.phi, light.materials,
                                                                scale.mm_per_unit);
        RefineOp op;
        op.tets = largest_indicators(eta, o.fraction);
        op.max_tets = budget;
        estimate_ms += milliseconds_since(clock);

        progress.set_stage("refining (round " + std::to_string(round) + ")");
        clock = Clock::now();
        const ChangeReport report = volume.apply(op, &progress);
        refine_ms += milliseconds_since(clock);
        const auto& result = std::get<RefineResult>(report.result);
        rounds = round;
        bisections += result.bisections;
        skipped_guard += result.marks_skipped_guard;
        budget_reached = result.marks_skipped_budget > 0;
        if (result.bisections == 0) break;
    }
    progress.set_stage("writing " + o.output);
    volume.write(o.output);
    progress.finish();
    report_chosen_scale(o.input, scale, volume.mesh());

    const TetMesh& mesh = volume.mesh();
    const nlohmann::ordered_json summary = {
        {"output", o.output},
        {"tets_before", tets_before},
        {"vertices_before", vertices_before},
        {"tets_after", mesh.tet_count()},
        {"vertices_after", mesh.vertex_count()},
        {"max_tets", budget},
        {"budget_reached", budget_reached},
        {"rounds", rounds},
        {"bisections", bisections},
        {"marks_skipped_guard", skipped_guard},
        {"min_dihedral_before_deg", min_dihedral_before},
        {"min_dihedral_deg", mesh_min_dihedral_deg(mesh)},
        {"mm_per_unit", scale.mm_per_unit},
        {"solve_ms", solve_ms},
        {"estimate_ms", estimate_ms},
        {"refine_ms", refine_ms},
        {"milliseconds", milliseconds_since(start)},
    };
    std::cout << summary.dump() << "\n";
}

}  // namespace

void add_refine_command(CLI::App& app) {
    auto options = std::make_shared<RefineCommandOptions>();
    CLI::App* cmd = app.add_subcommand("refine", "Refine a volume where its light is least accurate, within a tet budget");
    cmd->add_option("input", options->input, "Volume file (.vtu, .msh, .mesh, .node)")->required()->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", options->output, "Volume file to write")->required();
    cmd->add_option("--max-tets", options->max_tets, "Tet budget of the refined volume (default: twice the tets it has)");
    cmd->add_option("--fraction", options->fraction,
                    "Per round, the fraction of the tets with the largest error indicator to bisect")
        ->capture_default_str();
    cmd->add_option("--rounds", options->rounds, "At most this many solve-estimate-refine rounds")->capture_default_str();
    add_scene_light_options(*cmd, options->light);
    cmd->footer(
        "Each round solves the light as `render` does, estimates each tet's error from the jumps of the\n"
        "fluence's flux across its faces (Kelly et al. 1983) and bisects the marked tets along their longest\n"
        "edges, with the neighbours the mesh needs to stay conforming; children keep their parent's material.\n"
        "No tet is made under 0.5 degrees (or under its parent's angle, if lower). Stops at the budget.");
    organise_help(*cmd, "waxwork refine spot.vtu -o spot_refined.vtu --max-tets 20000", {});
    cmd->callback([options] { run_refine_command(*options); });
}

}  // namespace waxwork
