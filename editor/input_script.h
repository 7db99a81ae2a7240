// Scripted mouse and keyboard input for the editor (`waxwork edit --input SCRIPT.json`): a JSON list
// of timed events replayed into the window through the callbacks GLFW calls for real input, so tests
// and docs drive the real mouse tools headless under xvfb.
//
//   [
//     {"event": "tool", "tool": "cut"},                       select a tool (ids: tool_infos())
//     {"event": "material", "material": "ketchup"},           the brush's material (a measured preset)
//     {"event": "crease_angle", "degrees": 180},              as the View panel's slider (0 to 180)
//     {"frame": 3, "event": "press", "x": 200, "y": 300, "button": "left", "mods": ["shift"]},
//     {"event": "move", "x": 260, "y": 310},
//     {"event": "release", "x": 420, "y": 320, "button": "left"},
//     {"event": "drag", "from": [200, 300], "to": [420, 320], "steps": 12, "button": "left"},
//                                 press, `steps` moves on successive frames, release ("points":
//                                 [[x, y], ...] instead of from/to: through those points)
//     {"event": "scroll", "x": 400, "y": 300, "dy": 2},       wheel steps (positive zooms in)
//     {"event": "key", "key": "Home", "mods": ["ctrl"]},      press and release a key
//     {"event": "idle"},                                      wait until edits are applied and solved
//     {"event": "save_session", "file": "s.json"},            as File > Save session / Save volume
//     {"event": "save_volume", "file": "v.vtu"},
//     {"event": "export_surface", "file": "v.ply"},           as File > Export surface
//     {"event": "open", "file": "other.obj"},                 as File > Open (loads in the background)
//     {"event": "cancel_task"},                               the status bar's Cancel of that load
//     {"event": "repair", "repair": "wrap"},                  a refused surface's repair button: "wrap",
//                                                             "fill_holes", "autorefine" or
//                                                             "fill_holes_autorefine" (repair_choices.h)
//     {"event": "render_reference", "seconds": 5, "noise": 5, "size": 4},
//                                 View > Render reference: at most `seconds`, until `noise` percent,
//                                 1/size of the view across (4, 2 or 1); all optional
//     {"event": "cancel_reference"},                          the Reference window's Cancel
//     {"event": "save_reference", "file": "r.png"},           its Save (the numbers go to r.json)
//     {"event": "quit"},                                      File > Quit (asks first when modified,
//                                                             as Ctrl+Q: {"event": "key", "key": "Q",
//                                                             "mods": ["ctrl"]})
//     {"event": "close_window"},                              the window's close button (likewise)
//     {"event": "dialog", "button": "save", "file": "s.json"},
//                                 a button of the unsaved-changes dialog: "save", "discard" or
//                                 "cancel"; Save writes `file` when given (a .json: the session, else
//                                 the volume), else what the document was opened from or saved as
//     {"event": "open_example", "name": "spot"},              a start screen example (as a click)
//     {"event": "recover"},                                   the recovery offer's Recover / Discard
//     {"event": "discard_recovery"},
//     {"event": "autosave"},                                  write the recovery copy now
//     {"event": "kill"},                                      die at once as a crash would (SIGKILL):
//                                                             the recovery copy stays behind
//     {"event": "snapshot"},                                  File > Snapshot
//     {"event": "save_image", "file": "view.png"},            as File > Save image (.png, .jpg, .jpeg)
//     {"event": "background", "background": "30,60,90"},      the View panel's background: "automatic",
//                                                             "environment", "R,G,B" or "#RRGGBB"
//     {"event": "export_turntable", "file": "spin.mp4", "frames": 36}
//                                 File > Export turntable: the frames in spin/, the video spin.mp4
//                                 when ffmpeg is on the PATH; frames optional (36)
//   ]
//
// Positions are window coordinates (GLFW's: screen units, origin top-left; with --hide-ui the view
// fills the window). "frame" is the earliest frame an event fires, counted from the first frame that
// shows the loaded object (or the start screen, when the editor opened with no file); events fire in order, each at the earliest one frame after the previous
// (several per frame would pile a whole drag into one frame). Output files are relative to the
// script's directory. Errors name the file and the entry ("s.json: entry 3 (press): field 'x': ...").
#pragma once

#include "editor/viewport_tools.h"

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace waxwork {

enum class ScriptAction {
    Move, Press, Release, Scroll, Key, SelectTool, SelectMaterial, SetCreaseAngle, WaitIdle, SaveSession, SaveVolume,
    ExportSurface, Open, CancelTask, Repair, RenderReference, CancelReference, SaveReference, Quit, CloseWindow,
    Dialog, OpenExample, Recover, DiscardRecovery, Autosave, Kill, Snapshot, SaveImage, ExportTurntable, SetBackground
};

struct ScriptEvent {
    ScriptAction action = ScriptAction::Move;
    std::optional<int> frame;  // earliest frame; nullopt: one frame after the previous event
    double x = 0, y = 0;       // window coordinates (Move, Press, Release, Scroll)
    int button = 0;            // GLFW_MOUSE_BUTTON_LEFT / RIGHT / MIDDLE
    int mods = 0;              // GLFW_MOD_SHIFT | GLFW_MOD_CONTROL | GLFW_MOD_ALT
    double scroll = 0;         // wheel steps
    int key = 0;               // GLFW_KEY_*
    Tool tool = Tool::Orbit;
    std::string material;        // SelectMaterial: a preset name (material_preset_names())
    double degrees = 0;          // SetCreaseAngle: in [0, 180]
    std::filesystem::path file;  // SaveSession, SaveVolume, ExportSurface, Open (absolute after parsing)
    std::string repair;          // Repair: a RepairChoice id
    int frames = 0;              // ExportTurntable
    std::string background;      // SetBackground: as render --background takes it, but transparent
    std::string name;            // Dialog: "save", "discard" or "cancel"; OpenExample: the example
                                 // (Dialog's optional file is `file`, empty when not given)
    std::optional<double> seconds, noise_percent;  // RenderReference: the Reference window's settings
    std::optional<int> size_divisor;               // (nullopt: as the window has them)
    std::string context;         // "SCRIPT: entry N (kind)" for messages
};

struct InputScript {
    std::string name;
    std::vector<ScriptEvent> events;  // drags expanded into press, moves, release
};

// Throws InvalidArgumentError "NAME: entry N (kind): problem"; relative files resolve against
// `base_directory`.
InputScript parse_input_script(const nlohmann::ordered_json& json, const std::filesystem::path& base_directory,
                               const std::string& name);
// Reads and parses; FileError for unreadable files or malformed JSON.
InputScript read_input_script(const std::filesystem::path& path);

// The key for a name: "A".."Z", "0".."9", "Escape" (or "Esc"), "Home", "Tab", "Delete", "Enter",
// "Space" (case-insensitive); nullopt for others.
std::optional<int> key_from_name(const std::string& name);

// What the player drives: EditorApp through GLFW's callbacks in the window, a fake in the tests.
class ScriptTarget {
public:
    virtual ~ScriptTarget() = default;
    virtual bool ready() const = 0;  // the loaded object is on screen (frames count from here)
    virtual bool idle() const = 0;   // edits applied and the solve converged
    virtual void cursor(double x, double y) = 0;
    virtual void button(int button, bool press, int mods) = 0;
    virtual void scroll(double steps) = 0;
    virtual void key(int key, int mods) = 0;  // press and release
    virtual void select_tool(Tool tool) = 0;
    virtual void select_material(const std::string& preset) = 0;  // as a click in the material panel
    virtual void set_crease_angle(double degrees) = 0;            // as the View panel's slider
    virtual void save_session(const std::filesystem::path& file) = 0;
    virtual void save_volume(const std::filesystem::path& file) = 0;
    virtual void export_surface(const std::filesystem::path& file) = 0;
    virtual void open_file(const std::filesystem::path& file) = 0;  // as File > Open
    virtual void cancel_task() = 0;                                 // the status bar's Cancel
    virtual void choose_repair(const std::string& id) = 0;          // a refused surface's repair button
    // View > Render reference with these settings (nullopt: the Reference window's), its Cancel and Save.
    virtual void render_reference(std::optional<double> seconds, std::optional<double> noise_percent,
                                  std::optional<int> size_divisor) = 0;
    virtual void cancel_reference() = 0;
    virtual void save_reference(const std::filesystem::path& file) = 0;
    virtual void snapshot() = 0;  // File > Snapshot
    // Document safety and the start screen (editor_app.h).
    virtual void quit() = 0;          // File > Quit
    virtual void close_window() = 0;  // the window's close button
    virtual void answer_dialog(const std::string& button, const std::filesystem::path& file) = 0;
    virtual void open_example(const std::string& name) = 0;
    virtual void recover(bool accept) = 0;  // Recover (true) or Discard
    virtual void autosave() = 0;
    virtual void kill() = 0;
    virtual void save_image(const std::filesystem::path& file) = 0;  // File > Save image
    virtual void export_turntable(const std::filesystem::path& video, int frames) = 0;
    virtual void set_background(const std::string& background) = 0;  // the View panel's (parse_background)
};

// Replays a script, a frame at a time.
class InputScriptPlayer {
public:
    explicit InputScriptPlayer(InputScript script) : script_(std::move(script)) {}
    // Called once per frame before the frame is drawn: fires the events due.
    void advance(ScriptTarget& target);
    bool done() const { return next_ >= script_.events.size(); }
    const InputScript& script() const { return script_; }

private:
    InputScript script_;
    size_t next_ = 0;
    int frame_ = -1;       // frames since the target became ready
    int last_fired_ = -1;  // the frame the previous event fired in
};

}  // namespace waxwork
