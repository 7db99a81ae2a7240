// Scripted editing sessions: a JSON file that names an input, a material, lights, a camera
// and a list of steps, replayed headless by `waxwork run SESSION.json -o OUTDIR` through the same
// SceneCore (scene_core.h: Document and LiveScene) the editor uses, rendering frames with the OSMesa
// renderer.
//
//   {
//     "input": {"surface": "spot.obj", "max_tets": 20000, "mesher": "tetgen"|"auto"|"cgal"}   (or "edge": L; neither:
//              sized for the material and scale, solver/mesh_resolution.h; optional, as the command
//              line's options: "min_dihedral", "radius_edge", "fill_holes", "autorefine",
//              "repair": "wrap", "wrap_alpha", "wrap_offset") | {"volume": "spot.vtu"},
//     "material": "marble" | {"mua": [..], "musp": [..], "eta": 1.3},   (tets without a stored material)
//     "scale": 30,                         millimetres per model unit (optional: the input volume's
//                                          stored scale, else chosen from the model's size)
//     "lights": [{"direction": [1,-1,-1], "intensity": [1,1,1]}, {"position": [0,2,0]},
//                {"rect": {"center": [0,2,0], "normal": [0,-1,0], "tangent": [1,0,0], "size": [1,0.5]}},
//                {"disk": {"center": [..], "normal": [..], "radius": 0.3}},
//                {"sphere": {"center": [..], "radius": 0.2}}],   area lights (solver/lighting.h): the
//                                          tangent (the width's direction) is optional, default_rect_tangent
//     "ambient": [0.02, 0.02, 0.02], "shadows": true,   optional: without "lights" (or "ambient"),
//                                          render's key light (and ambient); "lights": [] is no light
//     "environment": {"file": "studio.hdr" | "sky": {"sun_elevation": 35, "sun_azimuth": 60,
//                     "turbidity": 3}, "rotation": 0, "intensity": 1, "background": true},
//                                          optional (solver/environment_light.h); with it, no key light
//                                          or ambient unless given; null in a light step removes it
//     "camera": {"eye_direction": [0.75,0.5,-1], "up": [0,1,0], "fov_y_deg": 30, "margin": 1.1,
//                "target_offset": [0,0,0]},    margin: framing distance factor (zoom); offset: pan
//     "image": {"width": 640, "height": 480},
//     "tolerance": 0.001,                  relative error a converged frame reaches
//     "frame_iterations": 10,              CG iterations per channel of one live frame
//     "frame_ms": 10,                      optional: a live frame's time budget in ms instead (solver/
//                                          frame_budget.h); renders after "frames" then vary with the machine
//     "crease_angle": 40,                  optional: degrees in [0, 180] past which the surface is shaded
//                                          and lit as folded (solver/shading_surface.h; 180: never)
//     "steps": [
//       {"op": "plane_cut", ...},          any edit operation (edit_operation.h)
//       {"render": "cut.png"},             a converged frame; {"render": "f.png", "frames": 3}: the frame
//                                          a live editor shows 3 frames after the last change
//       {"save": "cut.vtu"},               the volume (format from the extension)
//       {"light": {"lights": [...], "ambient": [...], "shadows": true, "environment": {...}}},
//                                          new lighting (the fields given replace the current ones)
//       {"camera": {...}},
//       {"undo": 1}, {"redo": 2}
//     ]
//   }
// Input paths are relative to the session file, output names to OUTDIR. Errors name the session file
// and the step index ("s.json: step 3 (paint): field 'sigma': ...").
#pragma once

#include "render/render_input.h"
#include "render/surface_renderer.h"
#include "scene/document.h"
#include "scene/edit_operation.h"
#include "scene/live_solver.h"
#include "solver/light_spec.h"
#include "solver/lighting.h"
#include "solver/shading_surface.h"
#include "solver/solved_scene.h"
#include "tetops/model_scale.h"
#include "tetops/surface_check.h"
#include "tetops/tet_mesh.h"
#include "tetops/tetrahedralize.h"

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace waxwork {

class Progress;

struct SessionInput {
    std::filesystem::path surface;  // exactly one of surface / volume (absolute after reading)
    std::filesystem::path volume;
    std::optional<size_t> max_tets;
    std::optional<double> edge;
    Mesher mesher = Mesher::TetGen;
    double min_dihedral_deg = MeshingOptions{}.min_dihedral_deg;  // the mesher's quality bounds
    double max_radius_edge_ratio = MeshingOptions{}.max_radius_edge_ratio;
    SurfaceRepairOptions repair;  // the opt-in repairs: fill_holes, autorefine, wrap
};

struct RenderStep {
    std::string file;
    std::optional<int> frames;       // nullopt: converged
    std::optional<double> exposure;  // nullopt: the image's automatic exposure (render_input.h)
};
struct SaveStep {
    std::string file;
};
struct LightStep {
    Lighting lighting;
};
struct CameraStep {
    CameraSettings camera;
};
struct UndoStep {
    int count = 1;
};
struct RedoStep {
    int count = 1;
};

using SessionStep = std::variant<EditOperation, RenderStep, SaveStep, LightStep, CameraStep, UndoStep, RedoStep>;

struct Session {
    std::string name;  // the file it came from, for errors ("session" when built in memory)
    SessionInput input;
    TetMaterial material;
    // Millimetres per model unit; nullopt: the input volume's stored scale, else one chosen from the
    // model's size (tetops/model_scale.h).
    std::optional<double> scale;
    // Without "lights" / "ambient": `waxwork render`'s key light and ambient (an empty "lights" list
    // is no light).
    Lighting lighting = default_lighting();
    CameraSettings camera;
    int width = 640;
    int height = 480;
    double tolerance = 1e-3;
    int frame_iterations = 10;
    std::optional<double> frame_ms;  // nullopt: frames are budgeted by frame_iterations
    double crease_angle_degrees = kDefaultCreaseAngleDegrees;
    std::vector<SessionStep> steps;
};

// Parses a session; relative input paths resolve against `base_directory`. Throws
// InvalidArgumentError "NAME: [step N (kind): ]field 'x': problem".
Session parse_session(const nlohmann::ordered_json& json, const std::filesystem::path& base_directory,
                      const std::string& name);
// Reads and parses; FileError for unreadable files or malformed JSON.
Session read_session(const std::filesystem::path& path);

nlohmann::ordered_json session_to_json(const Session& session);

// A lighting as the session file writes it: {"lights": [{"direction" | "position" | "rect" | "disk" |
// "sphere", "intensity"}, ...],
// "ambient", "shadows", "environment" (null when none)}.
nlohmann::ordered_json lighting_to_json(const Lighting& lighting);
// Writes atomically. Input paths are written relative to the file's directory when possible.
void write_session(const std::filesystem::path& path, const Session& session);

// Whether the session writes anything besides metrics.json (a render or a save step).
bool writes_outputs(const Session& session);

// Steps that belong between two operations of a recorded history: before the operation at index
// `before` (the history's size: after the last).
struct AnchoredSteps {
    size_t before = 0;
    std::vector<SessionStep> steps;
};

// The recording of an editing session: `setup`'s input, material, lights and camera, and as steps the
// document's history (the operations that made its current mesh) with `anchored` steps in their places
// (in order; those anchored past the history's end are dropped), followed by `extra_steps` (e.g. a
// final render or save). Replaying it gives the document's mesh bit for bit.
Session record_session(const Session& setup, const Document& document,
                       const std::vector<SessionStep>& extra_steps = {},
                       const std::vector<AnchoredSteps>& anchored = {});

// The volume a session starts from and its scale (the session's, else the one the volume stores, else
// the model's default).
struct SessionVolume {
    TetMesh mesh;
    ModelScale scale;
};

// The volume a session starts from (meshing the surface at the scale, or reading the volume); errors
// name the input file only. For a session that is not a file: the editor opening a mesh.
// `progress`, when given, is told each stage (reading, repairing, meshing) and its cancel request
// stops the work with CancelledError (base/progress.h).
SessionVolume read_session_input(const Session& session, Progress* progress = nullptr);

// As read_session_input, with the session before every error ("s.json: input: bad.stl: no faces"): a
// session's input is often a path relative to it, and the user runs the session, not the mesh.
SessionVolume load_session_input(const Session& session, Progress* progress = nullptr);

struct StepMetrics {
    std::string name;
    double milliseconds = 0;     // the whole step (edit + scene update, or solve + render, ...)
    size_t tets = 0, vertices = 0;
    int solver_iterations = 0;   // summed over channels and frames
    double estimated_error = -1; // of phi after the step (max over channels); -1: not solved since the change
};

struct SessionResult {
    TetMesh mesh;  // the final volume
    std::vector<StepMetrics> steps;
    double load_ms = 0;  // meshing or reading the input
    size_t input_tets = 0;  // as loaded, before the first step
    ModelScale scale;       // the scale the session ran at, and where it came from
    std::vector<std::filesystem::path> written;  // images and volumes, in order
    LiveBackend solver_backend = LiveBackend::Cpu;  // that solved the last step (Cpu after a fallback)
    std::string gpu_fallback_reason;                // why the GPU was given up ("" if it was not)
    std::string method_fallback_reason;             // why the method ran as Jacobi CG ("" if it did not)
};

// How `waxwork run` solves (live_solver.h). The GPU backend shares the renderer's OSMesa context.
struct SessionRunOptions {
    LiveMethod method = LiveMethod::JacobiCg;
    LiveBackend backend = LiveBackend::Cpu;
    std::optional<double> frame_ms;  // `run --frame-ms`: replaces the session's frame budget
};

// The budget of one live frame of `session` run with `run_options` (frame_ms, else frame_iterations).
FrameBudget session_frame_budget(const Session& session, const SessionRunOptions& run_options = {});

// Replays the session, writing renders and saves under `output_directory` (created) and
// OUTDIR/metrics.json. Errors name the session and the step index.
// metrics.json also names the solver backend (solver_backend, and gpu_fallback_reason after one), why
// the method fell back to Jacobi CG (method_fallback_reason, "" if it did not),
// and the frames' time budget (frame_ms; null for an iteration budget).
SessionResult run_session(const Session& session, const std::filesystem::path& output_directory,
                          const SessionRunOptions& run_options = {});

// What a session's steps leave behind, converged: its edits, lights and camera applied in order, its
// render and save steps skipped (nothing is written). `waxwork turntable SESSION` draws it. Errors
// name the session and the step as run_session's do.
struct SessionScene {
    TetMesh mesh;
    SolvedScene scene;
    Lighting lighting;
    CameraSettings camera;
    int width = 640;
    int height = 480;
    ModelScale scale;
};
SessionScene replay_session_scene(const Session& session);

}  // namespace waxwork
