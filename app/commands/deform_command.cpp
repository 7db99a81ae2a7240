// `waxwork deform`: as-rigid-as-possible deformation of a volume from the command line.
//   waxwork deform VOLUME -o OUT --grab X,Y,Z --radius R
//                  (--move DX,DY,DZ | --bend PX,PY,PZ:AX,AY,AZ:DEGREES | --twist PX,PY,PZ:AX,AY,AZ:DEGREES_PER_UNIT)
//                  [--pin X,Y,Z:R]... [--iterations N] [--steps S]
// Builds the deform operation (scene/edit_operation.h) and applies it through a Document, as the
// editor and sessions do: the body under the grab point follows the handle in S guarded steps of N
// local/global iterations each (tetops/arap_deformation.h). The volume is written atomically with its
// materials, ids and pieces unchanged (only positions move) and a one-line JSON summary is printed.
#include "app/commands/edited_volume.h"
#include "app/options/help_sections.h"
#include "app/options/number_options.h"
#include "app/stderr_progress.h"
#include "base/error.h"
#include "base/timing.h"
#include "scene/edit_operation.h"
#include "tetops/arap_deformation.h"
#include "tetops/quality.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

namespace waxwork {
namespace {

using Clock = std::chrono::steady_clock;

struct DeformCommandOptions {
    std::string input;
    std::string output;
    std::string grab;
    std::string radius;
    std::string move;
    std::string bend;
    std::string twist;
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

// PX,PY,PZ:AX,AY,AZ:DEGREES (per unit length for a twist).
HandleMotion parse_axis_motion(const std::string& text, const std::string& option, HandleMotion::Kind kind) {
    const size_t first = text.find(':'), second = first == std::string::npos ? first : text.find(':', first + 1);
    if (second == std::string::npos)
        throw InvalidArgumentError(option + ": \"" + text + "\" is not PX,PY,PZ:AX,AY,AZ:DEGREES");
    const Eigen::Vector3d point = parse_point(text.substr(0, first), option + " axis point");
    const Eigen::Vector3d axis = parse_point(text.substr(first + 1, second - first - 1), option + " axis");
    if (axis.norm() == 0) throw InvalidArgumentError(option + ": the axis direction must not be zero");
    const double radians = parse_numbers(text.substr(second + 1), 1, option + " angle")[0] * std::numbers::pi / 180;
    return kind == HandleMotion::Kind::Bend ? HandleMotion::bend(point, axis, radians)
                                            : HandleMotion::twist(point, axis, radians);
}

const char* tool_name(HandleMotion::Kind kind) {
    switch (kind) {
    case HandleMotion::Kind::Translate: return "grab";
    case HandleMotion::Kind::Bend: return "bend";
    case HandleMotion::Kind::Twist: return "twist";
    }
    return "";
}

size_t count_inverted(const TetMesh& mesh) {
    size_t inverted = 0;
    for (size_t t = 0; t < mesh.tet_count(); ++t) inverted += signed_volume(mesh, t) > 0 ? 0 : 1;
    return inverted;
}

DeformOp deform_operation(const DeformCommandOptions& o) {
    DeformOp op;
    op.grab = parse_point(o.grab, "deform --grab");
    op.radius = parse_positive(o.radius, "deform --radius");
    const int motions = int(!o.move.empty()) + int(!o.bend.empty()) + int(!o.twist.empty());
    if (motions != 1) throw InvalidArgumentError("deform: give exactly one of --move, --bend and --twist");
    if (!o.move.empty()) op.motion = HandleMotion::translation(parse_point(o.move, "deform --move"));
    if (!o.bend.empty()) op.motion = parse_axis_motion(o.bend, "deform --bend", HandleMotion::Kind::Bend);
    if (!o.twist.empty()) op.motion = parse_axis_motion(o.twist, "deform --twist", HandleMotion::Kind::Twist);
    for (const std::string& pin : o.pins) op.pins.push_back(parse_pin(pin));
    if (o.iterations < 1 || o.iterations > kMaxDeformIterations)
        throw InvalidArgumentError("deform --iterations: must be between 1 and " + std::to_string(kMaxDeformIterations));
    if (o.steps < 1 || o.steps > kMaxDeformSteps)
        throw InvalidArgumentError("deform --steps: must be between 1 and " + std::to_string(kMaxDeformSteps));
    op.iterations = o.iterations;
    op.steps = o.steps;
    return op;
}

void run_deform_command(const DeformCommandOptions& o) {
    // Options first, so a typing error is reported before the volume is read.
    const DeformOp op = deform_operation(o);
    EditedVolume volume(o.input, TetMaterial{}, /*write_base=*/false);
    const double volume_before = total_volume(volume.mesh());
    StderrProgress progress("waxwork: " + o.input + ": ");
    const auto start = Clock::now();
    const ChangeReport report = volume.apply(op, &progress);
    const double elapsed = milliseconds_since(start);
    progress.set_stage("writing " + o.output);
    volume.write(o.output);
    progress.finish();

    const DragReport& drag = std::get<DragReport>(report.result);
    const TetMesh& mesh = volume.mesh();
    const nlohmann::ordered_json summary = {
        {"output", o.output},
        {"tool", tool_name(op.motion.kind)},
        {"tets", mesh.tet_count()},
        {"vertices", mesh.vertex_count()},
        {"body_tets", drag.body_tets},
        {"handle_vertices", drag.handle_vertices},
        {"pinned_vertices", drag.pinned_vertices},
        {"moved_vertices", report.moved_vertices.size()},
        {"steps", drag.steps},
        {"iterations", drag.iterations_per_step},
        {"energy", drag.energy},
        {"step_shortened", drag.shortened_steps > 0},
        {"shortened_steps", drag.shortened_steps},
        {"handle_error", drag.handle_error},
        {"guard_deg", op.guard_deg},
        {"min_dihedral_deg", report.min_dihedral_deg},
        {"volume_before", volume_before},
        {"volume_after", total_volume(mesh)},
        {"inverted_tets", count_inverted(mesh)},
        {"factorization_ms", drag.factorization_ms},
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
    cmd->add_option("--move", options->move, "DX,DY,DZ: Grab: how far the handle's centre moves, in world units");
    cmd->add_option("--bend", options->bend,
                    "PX,PY,PZ:AX,AY,AZ:DEGREES: Bend: turn the handle about the axis through P along A");
    cmd->add_option("--twist", options->twist,
                    "PX,PY,PZ:AX,AY,AZ:DEGREES: Twist: turn the handle about the axis by DEGREES per unit length "
                    "along it from P");
    cmd->add_option("--pin", options->pins, "X,Y,Z:R: vertices within R of the point stay where they are (repeatable)")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    cmd->add_option("--iterations", options->iterations, "Local/global ARAP iterations per step")->capture_default_str();
    cmd->add_option("--steps", options->steps, "The move is applied in this many equal steps (drag frames)")
        ->capture_default_str();
    cmd->footer("Handle weight w = (1 - (d/R)^2)^2 for d < R from the grab point; vertices with w >= 0.5 (d <= 0.54 R)\n"
                "form the handle, which moves (--move) or turns (--bend, --twist) as one rigid grip.\n"
                "The rest of the grabbed body follows as rigidly as possible (per-tet rotations, Sorkine and\n"
                "Alexa 2007); other bodies and pieces stay. A step that would invert a tet or leave one under\n"
                "0.5 degrees is shortened (halved until it passes): then \"step_shortened\" is true.");
    organise_help(*cmd, "waxwork deform spot.vtu -o bent.vtu --grab 0,0.4,0.1 --radius 0.2 --move 0,0.1,0", {});
    cmd->callback([options] { run_deform_command(*options); });
}

}  // namespace waxwork
