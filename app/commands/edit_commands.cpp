// `waxwork cut`, `waxwork fracture` and `waxwork paint`: the editing operations of TransCut Sec. 5 (and
// the exact cut and fracture) from the command line.
//   waxwork cut VOLUME -o OUT --plane=NX,NY,NZ,D [--relax ITERS] [--no-guard] [--exact]
//               [--remove-fragments FRACTION]
//   waxwork fracture VOLUME -o OUT --pieces N [--seed K] [--exact|--no-exact] [--min-piece-tets M]
//                    [--collapse|--no-collapse]
//   waxwork paint VOLUME -o OUT --at "X,Y,Z;X,Y,Z" (--material NAME | --mua R,G,B --musp R,G,B --eta N)
//                 --sigma S [--base NAME] [--refine [--max-tets N]]
// Each builds the edit operation its options stand for (scene/edit_operation.h) and applies it
// through a Document, as the editor and sessions do, then writes the volume and prints a one-line JSON
// summary on stdout.
#include "app/options/help_sections.h"
#include "app/options/material_options.h"
#include "app/options/number_options.h"
#include "base/error.h"
#include "base/timing.h"
#include "io/volume_file.h"
#include "app/commands/edited_volume.h"
#include "scene/document.h"
#include "scene/edit_operation.h"
#include "solver/material.h"
#include "tetops/cut.h"
#include "tetops/fracture.h"
#include "tetops/paint.h"
#include "tetops/quality.h"
#include "tetops/refine.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace waxwork {
namespace {

using Clock = std::chrono::steady_clock;

struct CutCommandOptions {
    std::string input;
    std::string output;
    std::string plane;
    int relax_iterations = 10;
    bool no_guard = false;
    bool exact = false;
    std::optional<double> remove_fragments;  // volume fraction (tetops/fragments.h)
};

// Exact mode: tets crossed by the plane are split along it, so nothing is relaxed.
nlohmann::ordered_json exact_cut_summary(const CutCommandOptions& o, const ChangeReport& report) {
    const auto& cut = std::get<ExactCutResult>(report.result);
    return {
        {"output", o.output},
        {"mode", "exact"},
        {"tets_before", report.tets_before},
        {"vertices_before", report.vertices_before},
        {"tets_after", report.tets_after},
        {"vertices_after", report.vertices_after},
        {"tets_removed", cut.tets_removed},
        {"tets_split", cut.tets_split},
        {"vertices_snapped", cut.vertices_snapped},
        {"vertices_added", cut.vertices_added},
        {"components", report.connectivity->component_count},
        {"vertices_smoothed", cut.vertices_smoothed},
        {"min_dihedral_deg", cut.min_dihedral_deg},
        {"tets_under_guard", cut.tets_under_guard},
    };
}

nlohmann::ordered_json relaxed_cut_summary(const CutCommandOptions& o, const PlaneCutOp& op,
                                           const ChangeReport& report) {
    const auto& cut = std::get<RelaxedCutResult>(report.result);
    return {
        {"output", o.output},
        {"mode", "relax"},
        {"tets_before", report.tets_before},
        {"vertices_before", report.vertices_before},
        {"tets_after", report.tets_after},
        {"vertices_after", report.vertices_after},
        {"tets_removed", cut.removal.tets_removed},
        {"components", report.connectivity->component_count},
        {"relax_iterations", cut.relaxation.iterations},
        {"vertices_moved", cut.relaxation.vertices_moved},
        {"moves_rejected", cut.relaxation.moves_rejected},
        {"guard_deg", op.relax.guard_deg},
        {"min_dihedral_deg", cut.relaxation.min_dihedral_deg},
    };
}

// After the cut: drops the parts under the fraction, if asked, and reports them in the summary
// (whose "components" then counts the parts kept).
void remove_fragments_after_cut(const CutCommandOptions& o, EditedVolume& volume, nlohmann::ordered_json& summary) {
    if (!o.remove_fragments) return;
    const ChangeReport report = volume.apply(RemoveFragmentsOp{*o.remove_fragments});
    const auto& removal = std::get<FragmentRemoval>(report.result);
    summary["fragments_removed"] = removal.fragments_removed;
    summary["fragment_tets_removed"] = removal.removed.tets_removed;
    summary["components"] = removal.parts_kept;
    summary["tets_after"] = report.tets_after;
    summary["vertices_after"] = report.vertices_after;
}

void run_cut_command(const CutCommandOptions& o) {
    const std::vector<double> p = parse_numbers(o.plane, 4, "cut --plane");
    PlaneCutOp op;
    op.plane = {Eigen::Vector3d(p[0], p[1], p[2]), p[3]};
    // A zero or non-finite plane fails before the volume is read, naming the option.
    if (const std::string problem = plane_problem(op.plane.normal, op.plane.offset); !problem.empty())
        throw InvalidArgumentError("cut --plane=" + o.plane + ": " + problem);
    op.exact = o.exact;
    if (!o.exact) {  // --relax and --no-guard are unused by an exact cut
        if (o.relax_iterations < 0) throw InvalidArgumentError("cut --relax: the iteration count must be >= 0");
        op.relax.iterations = o.relax_iterations;
        if (o.no_guard) op.relax.guard_deg = 0;
    }

    EditedVolume volume(o.input, TetMaterial{}, /*write_base=*/false);
    const auto start = Clock::now();
    const ChangeReport report = volume.apply(op);
    nlohmann::ordered_json summary = o.exact ? exact_cut_summary(o, report) : relaxed_cut_summary(o, op, report);
    remove_fragments_after_cut(o, volume, summary);
    summary["milliseconds"] = milliseconds_since(start);
    volume.write(o.output);
    std::cout << summary.dump() << "\n";
}

struct FractureCommandOptions {
    std::string input;
    std::string output;
    int pieces = 0;
    uint32_t seed = 1;
    bool exact = true;
    int min_piece_tets = FractureOptions{}.min_piece_tets;
    bool collapse = FractureOptions{}.collapse_swallowed_walls;
};

void run_fracture_command(const FractureCommandOptions& o) {
    if (o.pieces < 1 || o.pieces > kMaxFracturePieces)
        throw InvalidArgumentError("fracture --pieces: must be between 1 and " + std::to_string(kMaxFracturePieces) +
                                   ", got " + std::to_string(o.pieces));
    if (o.min_piece_tets < 0) throw InvalidArgumentError("fracture --min-piece-tets: must be >= 0");
    FractureOp op;
    op.pieces = o.pieces;
    op.seed = o.seed;
    op.exact = o.exact;
    op.min_piece_tets = o.min_piece_tets;
    op.collapse = o.collapse;

    EditedVolume volume(o.input, TetMaterial{}, /*write_base=*/false);
    const auto start = Clock::now();
    const ChangeReport report = volume.apply(op);
    const double elapsed = milliseconds_since(start);
    volume.write(o.output);
    const auto& result = std::get<FractureResult>(report.result);
    nlohmann::ordered_json summary = {
        {"output", o.output},
        {"mode", o.exact ? "exact" : "tet_faces"},
        {"seed", o.seed},
        {"tets_before", report.tets_before},
        {"vertices_before", report.vertices_before},
        {"tets_after", report.tets_after},
        {"vertices_after", report.vertices_after},
        {"pieces_before", result.pieces_before},
        {"pieces", result.pieces_after},
        {"tets_split", result.tets_split},
        {"vertices_collapsed", result.vertices_collapsed},
        {"vertices_duplicated", result.vertices_duplicated},
        {"min_dihedral_deg", result.min_dihedral_deg},
        {"tets_under_guard", result.tets_under_guard},
        {"milliseconds", elapsed},
    };
    std::cout << summary.dump() << "\n";
}

struct PaintCommandOptions {
    std::string input;
    std::string output;
    std::string at;
    double sigma = 0;
    std::string base = "marble";
    MaterialOptions material;
    bool refine = false;
    std::optional<size_t> max_tets;  // --refine's budget; default kPaintRefineGrowth times the tets
};

// --refine's default budget, as a multiple of the volume's tets: room for a few strokes' worth of
// refinement, and a bound on what a tiny sigma can ask for.
constexpr size_t kPaintRefineGrowth = 8;

std::vector<Eigen::Vector3d> parse_points(const std::string& text) {
    std::vector<Eigen::Vector3d> points;
    size_t begin = 0;
    while (begin <= text.size()) {
        const size_t end = text.find(';', begin);
        const std::string item = text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
        const bool blank = std::all_of(item.begin(), item.end(),
                                       [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; });
        if (!blank) {
            const std::vector<double> v = parse_numbers(item, 3, "paint --at");
            points.emplace_back(v[0], v[1], v[2]);
        }
        if (end == std::string::npos) break;
        begin = end + 1;
    }
    if (points.empty()) throw InvalidArgumentError("paint --at: no stroke points given (expected X,Y,Z[;X,Y,Z...])");
    return points;
}

void run_paint_command(const PaintCommandOptions& o) {
    PaintOp op;
    op.points = parse_points(o.at);
    if (!(o.sigma > 0) || !std::isfinite(o.sigma))
        throw InvalidArgumentError("paint --sigma: must be a positive number (world units)");
    op.sigma = o.sigma;
    const std::optional<TetMaterial> brush_material = chosen_material(o.material);
    if (!brush_material)
        throw InvalidArgumentError("paint: choose the brush with --material NAME or --mua R,G,B --musp R,G,B --eta N");
    op.material = *brush_material;
    const TetMaterial base = material_preset(o.base);

    if (o.max_tets && !o.refine) throw InvalidArgumentError("paint --max-tets: only with --refine");
    if (o.max_tets && (*o.max_tets == 0 || *o.max_tets > kMaxRefinedTets))
        throw InvalidArgumentError("paint --max-tets: must be between 1 and " + std::to_string(kMaxRefinedTets) +
                                   ", got " + std::to_string(*o.max_tets));

    EditedVolume volume(o.input, base, /*write_base=*/true);
    const auto start = Clock::now();
    std::optional<ChangeReport> refined;
    size_t refine_budget = 0;
    if (o.refine) {
        // The tets the brush reaches, down to the brush's width: its Gaussian then varies by at most
        // about one standard deviation across a tet.
        RefineOp refine;
        refine.points = op.points;
        PaintBrush brush;
        brush.sigma = op.sigma;
        brush.cutoff_weight = op.cutoff_weight;
        refine.radius = paint_radius(brush);
        refine.edge_length = op.sigma;
        const size_t tets = volume.mesh().tet_count();
        refine.max_tets = o.max_tets.value_or(std::min(kMaxRefinedTets, kPaintRefineGrowth * std::max<size_t>(tets, 1)));
        if (refine.max_tets < tets)
            throw InvalidArgumentError("paint --max-tets: " + std::to_string(refine.max_tets) + " is below the volume's " +
                                       std::to_string(tets) + " tets (refinement only adds tets)");
        refine_budget = refine.max_tets;
        refined = volume.apply(refine);
    }
    const ChangeReport report = volume.apply(op);
    const double elapsed = milliseconds_since(start);

    volume.write(o.output);
    nlohmann::ordered_json summary = {
        {"output", o.output},
        {"tets_before", refined ? refined->tets_before : report.tets_before},
        {"vertices_before", refined ? refined->vertices_before : report.vertices_before},
        {"tets_after", report.tets_after},
        {"vertices_after", report.vertices_after},
        {"stroke_points", op.points.size()},
        {"tets_changed", report.changed_material_tets.size()},
        {"min_dihedral_deg", mesh_min_dihedral_deg(volume.mesh())},
        {"milliseconds", elapsed},
    };
    if (refined) {
        const auto& result = std::get<RefineResult>(refined->result);
        summary["refined"] = {{"max_tets", refine_budget},
                              {"bisections", result.bisections},
                              {"marks_skipped_guard", result.marks_skipped_guard},
                              {"budget_reached", result.marks_skipped_budget > 0},
                              {"milliseconds", refined->milliseconds}};
    }
    std::cout << summary.dump() << "\n";
}

}  // namespace

void add_cut_command(CLI::App& app) {
    auto options = std::make_shared<CutCommandOptions>();
    CLI::App* cmd = app.add_subcommand("cut", "Cut a volume with a plane and relax the cross-section");
    cmd->add_option("input", options->input, "Volume file (.vtu, .msh, .mesh, .node)")->required()->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", options->output, "Volume file to write")->required();
    cmd->add_option("--plane", options->plane, "NX,NY,NZ,D: removes the side n.x > D (write --plane=-1,0,0,0 when "
                                               "the first number is negative)")
        ->required();
    cmd->add_option("--relax", options->relax_iterations, "Relaxation sweeps moving cut vertices onto the plane")
        ->capture_default_str();
    cmd->add_flag("--no-guard", options->no_guard,
                  "Let relaxation create tets under 0.5 degrees (paper Fig. 9(a); for comparison only)");
    cmd->add_flag("--exact", options->exact,
                  "Split the tets crossed by the plane along it instead of relaxing (--relax and --no-guard are "
                  "then unused)");
    // Checked on the text (parse_numbers): CLI11 would take an empty value for no option at all.
    const CLI::Validator fraction_check(
        [](std::string& text) {
            try {
                const double fraction = parse_numbers(text, 1, "the volume fraction")[0];
                return fraction >= 0 && fraction < 1 ? std::string() : "'" + text + "' is not in [0, 1)";
            } catch (const InvalidArgumentError& error) {
                return std::string(error.what());
            }
        },
        "FRACTION", "volume fraction");
    cmd->add_option("--remove-fragments", options->remove_fragments,
                    "Then drop the detached parts smaller than this fraction of the volume (0.001: 0.1%), such as "
                    "the caps a plane grazing a concave shape leaves floating; the largest part always stays")
        ->check(fraction_check);
    cmd->footer("Tets with all four vertices on the side n.x > D are removed (TransCut Sec. 5); vertices left there\n"
                "then move toward their one-ring average, never across the plane and never below the guard.\n"
                "--exact: vertices within 20% of an edge from the plane snap onto it (when no tet of their star\n"
                "drops under 0.5 degrees), every other crossed edge is split, crossed tets are split into tets on\n"
                "either side and the side n.x > D is removed: the cross-section lies on the plane.");
    organise_help(*cmd, "waxwork cut spot.vtu -o cut.vtu --plane 1,0,0,0.1 --exact", {});
    cmd->callback([options] { run_cut_command(*options); });
}

// --NAME sets `target`, --no-NAME clears it (the last given wins), each with its own help line: CLI11's
// "--x,!--no-x" prints one line ending in "{false}", which reads as if the flag were off by default.
void add_on_off_flags(CLI::App* cmd, const std::string& name, bool& target, const std::string& on_help,
                      const std::string& off_help) {
    cmd->add_flag_callback("--" + name, [&target] { target = true; }, on_help);
    cmd->add_flag_callback("--no-" + name, [&target] { target = false; }, off_help);
}

void add_fracture_command(CLI::App& app) {
    auto options = std::make_shared<FractureCommandOptions>();
    CLI::App* cmd = app.add_subcommand("fracture", "Break a volume into pieces along Voronoi cells");
    cmd->add_option("input", options->input, "Volume file (.vtu, .msh, .mesh, .node)")->required()->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", options->output, "Volume file to write (.vtu keeps the pieces)")->required();
    cmd->add_option("--pieces", options->pieces, "Number of Voronoi seeds (pieces)")->required();
    cmd->add_option("--seed", options->seed, "Random seed for the seed points")->capture_default_str();
    add_on_off_flags(cmd, "exact", options->exact, "Split tets along the cell walls: flat cracks (default)",
                     "Keep whole tets: cracks run along tet faces");
    cmd->add_option("--min-piece-tets", options->min_piece_tets, "Smaller pieces join their largest neighbour")
        ->capture_default_str();
    add_on_off_flags(cmd, "collapse", options->collapse,
                     "Exact mode: collapse the vertices that walls of earlier cells left inside later ones (default)",
                     "Exact mode: keep every split (to compare)");
    cmd->footer("Seeds are scattered uniformly in the volume; each cell's part of each piece becomes a piece (a cell\n"
                "cut in two by a concave volume gives two), with the crack vertices duplicated so pieces move apart.");
    organise_help(*cmd, "waxwork fracture spot.vtu -o broken.vtu --pieces 5", {});
    cmd->callback([options] { run_fracture_command(*options); });
}

void add_paint_command(CLI::App& app) {
    auto options = std::make_shared<PaintCommandOptions>();
    CLI::App* cmd = app.add_subcommand("paint", "Blend a material into the tets around stroke points");
    cmd->add_option("input", options->input, "Volume file (.vtu, .msh, .mesh, .node)")->required()->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", options->output, "Volume file to write (.vtu keeps the materials)")->required();
    cmd->add_option("--at", options->at, "Stroke points in world space: \"X,Y,Z;X,Y,Z;...\"")->required();
    cmd->add_option("--sigma", options->sigma, "Gaussian width of the brush in world units")->required();
    cmd->add_option("--base", options->base, "Material of every tet when the volume stores none")
        ->capture_default_str();
    add_material_options(*cmd, options->material);
    cmd->add_flag("--refine", options->refine,
                  "First bisect the tets the brush reaches until their longest edge is at most sigma (conforming; "
                  "children keep their parent's material), so the stroke's Gaussian is resolved");
    cmd->add_option("--max-tets", options->max_tets,
                    "--refine: tet budget of the refined volume (default: 8 times the tets it has)");
    cmd->footer("Weight w = exp(-d^2 / (2 sigma^2)), d from a tet's centroid to the nearest stroke point; tets with\n"
                "w < 0.001 are untouched; material <- (1 - w) material + w brush (TransCut Sec. 5).");
    organise_help(*cmd, "waxwork paint spot.vtu -o painted.vtu --at 0,0.3,0.2 --sigma 0.05 --material ketchup", {});
    cmd->callback([options] { run_paint_command(*options); });
}

}  // namespace waxwork
