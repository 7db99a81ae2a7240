// `waxwork deform`: as-rigid-as-possible deformation of a volume from the command line.
//   waxwork deform VOLUME -o OUT --grab X,Y,Z --radius R --move DX,DY,DZ [--pin X,Y,Z:R]...
//                  [--iterations N] [--steps S]
// The body under the grab point is dragged by the move in S frames of N local/global iterations each,
// guarded against inverted and sliver tets (tetops/arap_deformation.h), as the editor's drag runs it;
// the volume is written atomically with its materials, ids and pieces unchanged (only positions move)
// and a one-line JSON summary is printed on stdout.
#include "app/options/number_options.h"
#include "base/error.h"
#include "base/timing.h"
#include "io/volume_file.h"
#include "tetops/arap_deformation.h"
#include "tetops/connectivity.h"
#include "tetops/quality.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace waxwork {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kMaxIterations = 10000;
constexpr int kMaxSteps = 10000;

struct DeformCommandOptions {
    std::string input;
    std::string output;
    std::string grab;
    std::string radius;
    std::string move;
    std::vector<std::string> pins;
    int iterations = 10;
    int steps = 10;
};

Eigen::Vector3d parse_point(const std::string& text, const std::string& what) {
    const std::vector<double> v = parse_numbers(text, 3, what);
    return {v[0], v[1], v[2]};
}

double parse_positive(const std::string& text, const std::string& what) {
    const double value = parse_numbers(text, 1, what)[0];
    if (!(value > 0)) throw InvalidArgumentError(what + ": must be positive, got " + text);
    return value;
}

PinSphere parse_pin(const std::string& text) {
    const size_t colon = text.find(':');
    if (colon == std::string::npos)
        throw InvalidArgumentError("deform --pin: \"" + text + "\" is not X,Y,Z:RADIUS");
    return {parse_point(text.substr(0, colon), "deform --pin " + text),
            parse_positive(text.substr(colon + 1), "deform --pin " + text + " radius")};
}

size_t count_inverted(const TetMesh& mesh) {
    size_t inverted = 0;
    for (size_t t = 0; t < mesh.tet_count(); ++t) inverted += signed_volume(mesh, t) > 0 ? 0 : 1;
    return inverted;
}

void run_deform_command(const DeformCommandOptions& o) {
    // Options first, so a typing error is reported before the volume is read.
    const Eigen::Vector3d grab = parse_point(o.grab, "deform --grab");
    const double radius = parse_positive(o.radius, "deform --radius");
    const Eigen::Vector3d move = parse_point(o.move, "deform --move");
    std::vector<PinSphere> pins;
    for (const std::string& pin : o.pins) pins.push_back(parse_pin(pin));
    if (o.iterations < 1 || o.iterations > kMaxIterations)
        throw InvalidArgumentError("deform --iterations: must be between 1 and " + std::to_string(kMaxIterations));
    if (o.steps < 1 || o.steps > kMaxSteps)
        throw InvalidArgumentError("deform --steps: must be between 1 and " + std::to_string(kMaxSteps));

    VolumeFile file = read_volume_file(o.input);
    TetMesh& mesh = file.mesh;
    const auto start = Clock::now();
    const TetConnectivity connectivity = naming_context(o.input, [&] { return build_connectivity(mesh); });
    DragRegion region;
    try {
        region = select_drag_region(mesh, connectivity, grab, radius, move, pins);
    } catch (const InvalidArgumentError& error) {
        throw InvalidArgumentError(o.input + ": deform --grab " + o.grab + " --radius " + o.radius +
                                   (pins.empty() ? std::string() : " with " + std::to_string(pins.size()) + " --pin") +
                                   ": " + error.what());
    }
    const double volume_before = total_volume(mesh);
    const auto factor_start = Clock::now();
    ArapDeformer deformer = naming_context(o.input, [&] { return ArapDeformer(mesh, region.body_tets); });
    naming_context(o.input, [&] { deformer.set_constrained(region.constrained()); });
    const double factor_ms = milliseconds_since(factor_start);
    const DragReport drag =
        naming_context(o.input, [&] { return run_drag(deformer, mesh, region, mesh.positions, o.steps, o.iterations); });
    size_t moved = 0;
    for (size_t v = 0; v < mesh.vertex_count(); ++v) moved += deformer.positions()[v] != mesh.positions[v] ? 1 : 0;
    mesh.positions = deformer.positions();
    const double elapsed = milliseconds_since(start);
    write_volume(mesh, o.output, file.metadata);

    const nlohmann::ordered_json summary = {
        {"output", o.output},
        {"tets", mesh.tet_count()},
        {"vertices", mesh.vertex_count()},
        {"piece", region.piece},
        {"body_tets", region.body_tets.size()},
        {"handle_vertices", region.handle.size()},
        {"pinned_vertices", region.pinned.size()},
        {"moved_vertices", moved},
        {"steps", drag.steps},
        {"iterations", drag.iterations_per_step},
        {"energy", drag.energy},
        {"step_shortened", drag.shortened_steps > 0},
        {"shortened_steps", drag.shortened_steps},
        {"handle_error", drag.handle_error},
        {"guard_deg", GuardOptions{}.min_dihedral_guard_deg},
        {"min_dihedral_deg", mesh_min_dihedral_deg(mesh)},
        {"volume_before", volume_before},
        {"volume_after", total_volume(mesh)},
        {"inverted_tets", count_inverted(mesh)},
        {"factorization_ms", factor_ms},
        {"milliseconds", elapsed},
    };
    std::cout << summary.dump() << "\n";
}

}  // namespace

void add_deform_command(CLI::App& app) {
    auto options = std::make_shared<DeformCommandOptions>();
    CLI::App* cmd = app.add_subcommand("deform", "Drag a region of a volume as rigidly as possible");
    cmd->add_option("input", options->input, "Volume file (.vtu, .msh, .mesh, .node)")->required()->check(CLI::ExistingFile);
    cmd->add_option("-o,--output", options->output, "Volume file to write (.vtu keeps materials and pieces)")->required();
    cmd->add_option("--grab", options->grab, "X,Y,Z: the centre of the handle, in world space")->required();
    cmd->add_option("--radius", options->radius, "Falloff radius of the handle, in world units")->required();
    cmd->add_option("--move", options->move, "DX,DY,DZ: how far the handle's centre moves, in world units")->required();
    cmd->add_option("--pin", options->pins, "X,Y,Z:R: vertices within R of the point stay where they are (repeatable)")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    cmd->add_option("--iterations", options->iterations, "Local/global ARAP iterations per step")->capture_default_str();
    cmd->add_option("--steps", options->steps, "The move is applied in this many equal steps (drag frames)")
        ->capture_default_str();
    cmd->footer("Handle weight w = (1 - (d/R)^2)^2 for d < R from the grab point; vertices with w >= 0.5 (d <= 0.54 R)\n"
                "move by w x the move, the rest of the grabbed body follows as rigidly as possible (per-tet\n"
                "rotations, Sorkine and Alexa 2007). Other bodies and pieces stay. A step that would invert a tet or\n"
                "leave one under 0.5 degrees is shortened (halved until it passes): then \"step_shortened\" is true.");
    cmd->callback([options] { run_deform_command(*options); });
}

}  // namespace waxwork
