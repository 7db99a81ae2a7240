#include "editor/input_script.h"

#include "base/error.h"

#include <GLFW/glfw3.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

namespace waxwork {
namespace {

using Json = nlohmann::ordered_json;

InputScript parse(const std::string& text) { return parse_input_script(Json::parse(text), "/scripts", "s.json"); }

// The one-line message parsing `text` fails with.
std::string parse_error(const std::string& text) {
    try {
        parse(text);
    } catch (const InvalidArgumentError& e) {
        return e.what();
    }
    return "";
}

TEST(InputScript, ParsesEveryEventKind) {
    const InputScript s = parse(R"([
        {"event": "tool", "tool": "remove_cut"},
        {"frame": 3, "event": "press", "x": 10, "y": 20.5, "button": "right", "mods": ["shift", "alt"]},
        {"event": "move", "x": 15, "y": 25},
        {"event": "release", "x": 16, "y": 26, "button": "right"},
        {"event": "scroll", "x": 5, "y": 6, "dy": -2},
        {"event": "key", "key": "home", "mods": ["ctrl"]},
        {"event": "idle"},
        {"event": "save_session", "file": "out/s.json"},
        {"event": "save_volume", "file": "/tmp/v.vtu"},
        {"event": "crease_angle", "degrees": 180},
        {"event": "export_surface", "file": "out/v.ply"}])");
    ASSERT_EQ(s.events.size(), 11u);
    EXPECT_EQ(s.events[0].action, ScriptAction::SelectTool);
    EXPECT_EQ(s.events[0].tool, Tool::RemoveCut);
    EXPECT_FALSE(s.events[0].frame);
    EXPECT_EQ(s.events[1].action, ScriptAction::Press);
    EXPECT_EQ(s.events[1].frame, 3);
    EXPECT_EQ(s.events[1].x, 10);
    EXPECT_EQ(s.events[1].y, 20.5);
    EXPECT_EQ(s.events[1].button, GLFW_MOUSE_BUTTON_RIGHT);
    EXPECT_EQ(s.events[1].mods, GLFW_MOD_SHIFT | GLFW_MOD_ALT);
    EXPECT_EQ(s.events[2].action, ScriptAction::Move);
    EXPECT_EQ(s.events[3].action, ScriptAction::Release);
    EXPECT_EQ(s.events[4].action, ScriptAction::Scroll);
    EXPECT_EQ(s.events[4].scroll, -2);
    EXPECT_EQ(s.events[5].key, GLFW_KEY_HOME);
    EXPECT_EQ(s.events[5].mods, GLFW_MOD_CONTROL);
    EXPECT_EQ(s.events[6].action, ScriptAction::WaitIdle);
    EXPECT_EQ(s.events[7].file, std::filesystem::path("/scripts/out/s.json"));
    EXPECT_EQ(s.events[8].file, std::filesystem::path("/tmp/v.vtu"));
    EXPECT_EQ(s.events[9].action, ScriptAction::SetCreaseAngle);
    EXPECT_EQ(s.events[9].degrees, 180.0);
    EXPECT_EQ(s.events[10].action, ScriptAction::ExportSurface);
    EXPECT_EQ(s.events[10].file, std::filesystem::path("/scripts/out/v.ply"));
}

TEST(InputScript, ParsesOpenCancelAndRepairAndPlaysThemIntoTheTarget) {
    const InputScript s = parse(R"([
        {"event": "open", "file": "meshes/box.obj"},
        {"event": "cancel_task"},
        {"event": "repair", "repair": "wrap"},
        {"event": "repair", "repair": "fill_holes_autorefine"}])");
    ASSERT_EQ(s.events.size(), 4u);
    EXPECT_EQ(s.events[0].action, ScriptAction::Open);
    EXPECT_EQ(s.events[0].file, std::filesystem::path("/scripts/meshes/box.obj"));
    EXPECT_EQ(s.events[1].action, ScriptAction::CancelTask);
    EXPECT_EQ(s.events[2].action, ScriptAction::Repair);
    EXPECT_EQ(s.events[2].repair, "wrap");
    EXPECT_EQ(s.events[3].repair, "fill_holes_autorefine");
    for (const auto& [text, expected] : std::vector<std::pair<std::string, std::string>>{
             {R"([{"event": "open"}])", "s.json: entry 0 (open): missing field 'file'"},
             {R"([{"event": "repair", "repair": "glue"}])", "s.json: entry 0 (repair): field 'repair': expected \"wrap\""},
             {R"([{"event": "repair"}])", "missing field 'repair'"},
             {R"([{"event": "cancel_task", "file": "x"}])", "unknown field 'file'"}}) {
        const std::string message = parse_error(text);
        EXPECT_NE(message.find(expected), std::string::npos) << text << " -> " << message;
    }
}

TEST(InputScript, DragExpandsIntoPressMovesAndRelease) {
    const InputScript s = parse(R"([{"frame": 5, "event": "drag", "from": [0, 100], "to": [40, 60], "steps": 4,
                                    "button": "middle"}])");
    ASSERT_EQ(s.events.size(), 6u);  // press, 4 moves, release
    EXPECT_EQ(s.events[0].action, ScriptAction::Press);
    EXPECT_EQ(s.events[0].frame, 5);
    EXPECT_EQ(s.events[0].button, GLFW_MOUSE_BUTTON_MIDDLE);
    for (int i = 1; i <= 4; ++i) {
        EXPECT_EQ(s.events[i].action, ScriptAction::Move);
        EXPECT_FALSE(s.events[i].frame);
        EXPECT_DOUBLE_EQ(s.events[i].x, 10.0 * i);
        EXPECT_DOUBLE_EQ(s.events[i].y, 100 - 10.0 * i);
    }
    EXPECT_EQ(s.events[5].action, ScriptAction::Release);
    EXPECT_EQ(s.events[5].button, GLFW_MOUSE_BUTTON_MIDDLE);
    EXPECT_EQ(s.events[5].x, 40);

    const InputScript through = parse(R"([{"event": "drag", "points": [[1, 2], [3, 4], [5, 6]]}])");
    ASSERT_EQ(through.events.size(), 4u);
    EXPECT_EQ(through.events[2].x, 5);
    EXPECT_EQ(through.events[3].action, ScriptAction::Release);
    EXPECT_EQ(through.events[3].button, GLFW_MOUSE_BUTTON_LEFT);
}

TEST(InputScript, BadScriptsGetOneLineErrorsNamingTheFileAndEntry) {
    const std::vector<std::pair<std::string, std::string>> cases = {
        {R"({"event": "press"})", "s.json: an input script is a JSON list"},
        {R"([{"event": "press", "x": 1, "y": 2}, 3])", "s.json: entry 1"},
        {R"([{"x": 1}])", "s.json: entry 0: missing field 'event'"},
        {R"([{"event": "hover", "x": 1, "y": 2}])", "s.json: entry 0: unknown event \"hover\""},
        {R"([{"event": "press", "x": 1}])", "s.json: entry 0 (press): missing field 'y'"},
        {R"([{"event": "press", "x": "a", "y": 1}])", "s.json: entry 0 (press): field 'x'"},
        {R"([{"event": "press", "x": 1, "y": 1, "button": "fourth"}])", "field 'button'"},
        {R"([{"event": "press", "x": 1, "y": 1, "mods": ["hyper"]}])", "field 'mods'"},
        {R"([{"event": "press", "x": 1, "y": 1, "colour": 3}])", "unknown field 'colour'"},
        {R"([{"event": "move", "x": 1, "y": 1, "frame": -1}])", "field 'frame'"},
        {R"([{"event": "key", "key": "F13"}])", "s.json: entry 0 (key): field 'key'"},
        {R"([{"event": "tool", "tool": "chisel"}])", "expected one of orbit, cut, remove_cut"},
        {R"([{"event": "material", "material": "cheese"}])", "s.json: entry 0 (material): field 'material': expected a measured preset: apple"},
        {R"([{"event": "material", "material": 3}])", "field 'material'"},
        {R"([{"event": "drag", "from": [0, 0]}])", "missing field 'to'"},
        {R"([{"event": "drag", "from": [0, 0], "to": [1, 1], "points": [[0, 0], [1, 1]]}])", "either"},
        {R"([{"event": "drag", "points": [[0, 0]]}])", "at least two"},
        {R"([{"event": "drag", "from": [0, 0], "to": [1, 1], "steps": 0}])", "field 'steps'"},
        {R"([{"event": "save_volume", "file": ""}])", "s.json: entry 0 (save_volume): field 'file'"},
        {R"([{"event": "scroll", "x": 1, "y": 1}])", "missing field 'dy'"},
        {R"([{"event": "crease_angle", "degrees": 181}])", "s.json: entry 0 (crease_angle): field 'degrees': must be between 0 and 180"},
        {R"([{"event": "crease_angle", "degrees": -1}])", "field 'degrees': must be between 0 and 180"},
        {R"([{"event": "crease_angle"}])", "missing field 'degrees'"},
        {R"([{"event": "render_reference", "seconds": 0}])", "s.json: entry 0 (render_reference): field 'seconds'"},
        {R"([{"event": "render_reference", "seconds": 1e9}])", "field 'seconds'"},
        {R"([{"event": "render_reference", "noise": 100}])", "field 'noise': must be a percentage"},
        {R"([{"event": "render_reference", "size": 3}])", "field 'size': must be 4, 2 or 1"},
        {R"([{"event": "render_reference", "samples": 3}])", "unknown field 'samples'"},
        {R"([{"event": "save_reference"}])", "missing field 'file'"},
        {R"([{"event": "dialog", "button": "maybe"}])", "s.json: entry 0 (dialog): field 'button': expected \"save\""},
        {R"([{"event": "dialog"}])", "missing field 'button'"},
        {R"([{"event": "dialog", "button": "save", "file": ""}])", "field 'file'"},
        {R"([{"event": "open_example"}])", "s.json: entry 0 (open_example): missing field 'name'"},
        {R"([{"event": "quit", "now": true}])", "unknown field 'now'"},
        {R"([{"event": "save_image"}])", "missing field 'file'"},
        {R"([{"event": "export_turntable", "file": "a.mp4", "frames": 0}])", "field 'frames': must be between 1"},
        {R"([{"event": "background", "background": "transparent"}])", "field 'background': a window cannot"},
        {R"([{"event": "background", "background": "300,0,0"}])", "s.json: entry 0 (background): field 'background'"},
    };
    for (const auto& [text, expected] : cases) {
        const std::string message = parse_error(text);
        EXPECT_NE(message.find(expected), std::string::npos) << text << " -> " << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
}

TEST(InputScript, UnreadableOrMalformedFilesAreFileErrors) {
    EXPECT_THROW(read_input_script("/nonexistent/script.json"), FileError);
    const auto path = std::filesystem::temp_directory_path() / ("waxwork_bad_script_" + std::to_string(::getpid()) + ".json");
    std::ofstream(path) << "[{\"event\": ";
    try {
        read_input_script(path);
        ADD_FAILURE() << "malformed JSON was accepted";
    } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
    std::filesystem::remove(path);
}

// Records what the player does, frame by frame.
class FakeTarget final : public ScriptTarget {
public:
    bool is_ready = false, is_idle = true;
    int frame = 0;
    std::vector<std::string> log;
    bool ready() const override { return is_ready; }
    bool idle() const override { return is_idle; }
    void cursor(double x, double y) override { add("cursor " + std::to_string(int(x)) + "," + std::to_string(int(y))); }
    void button(int button, bool press, int) override { add((press ? "press " : "release ") + std::to_string(button)); }
    void scroll(double steps) override { add("scroll " + std::to_string(int(steps))); }
    void key(int key, int) override { add("key " + std::to_string(key)); }
    void select_tool(Tool tool) override { add("tool " + std::to_string(static_cast<int>(tool))); }
    void select_material(const std::string& preset) override { add("material " + preset); }
    void set_crease_angle(double degrees) override { add("crease " + std::to_string(int(degrees))); }
    void save_session(const std::filesystem::path& f) override { add("session " + f.filename().string()); }
    void save_volume(const std::filesystem::path& f) override { add("volume " + f.filename().string()); }
    void export_surface(const std::filesystem::path& f) override { add("surface " + f.filename().string()); }
    void open_file(const std::filesystem::path& f) override { add("open " + f.filename().string()); }
    void cancel_task() override { add("cancel"); }
    void choose_repair(const std::string& id) override { add("repair " + id); }
    void render_reference(std::optional<double> seconds, std::optional<double> noise, std::optional<int> size) override {
        add("reference " + (seconds ? std::to_string(int(*seconds)) : "-") + " " + (noise ? std::to_string(int(*noise)) : "-") +
            " " + (size ? std::to_string(*size) : "-"));
    }
    void cancel_reference() override { add("cancel reference"); }
    void save_reference(const std::filesystem::path& f) override { add("save reference " + f.filename().string()); }
    void snapshot() override { add("snapshot"); }
    void quit() override { add("quit"); }
    void close_window() override { add("close window"); }
    void answer_dialog(const std::string& button, const std::filesystem::path& f) override {
        add("dialog " + button + (f.empty() ? "" : " " + f.filename().string()));
    }
    void open_example(const std::string& name) override { add("example " + name); }
    void recover(bool accept) override { add(accept ? "recover" : "discard recovery"); }
    void autosave() override { add("autosave"); }
    void kill() override { add("kill"); }
    void save_image(const std::filesystem::path& f) override { add("save image " + f.filename().string()); }
    void set_background(const std::string& background) override { add("background " + background); }
    void export_turntable(const std::filesystem::path& f, int frames) override {
        add("turntable " + f.filename().string() + " " + std::to_string(frames));
    }

private:
    void add(const std::string& s) { log.push_back(std::to_string(frame) + ": " + s); }
};

TEST(InputScriptPlayer, FiresInOrderOnePerFrameFromTheFirstReadyFrame) {
    InputScriptPlayer player(parse(R"([{"event": "tool", "tool": "cut"}, {"event": "material", "material": "ketchup"},
        {"frame": 3, "event": "drag", "from": [0, 0], "to": [10, 0], "steps": 1},
        {"event": "idle"}, {"event": "save_volume", "file": "v.vtu"}, {"event": "crease_angle", "degrees": 90},
        {"event": "export_surface", "file": "v.ply"}])"));
    FakeTarget target;
    // Not ready: nothing fires and frames do not count.
    for (target.frame = 0; target.frame < 3; ++target.frame) player.advance(target);
    EXPECT_TRUE(target.log.empty());
    target.is_ready = true;
    for (; target.frame < 14; ++target.frame) {
        target.is_idle = target.frame >= 10;  // the cut is being applied until window frame 10
        player.advance(target);
        EXPECT_EQ(player.done(), target.frame >= 13) << target.frame;
    }
    // Ready at window frame 3 = script frame 0; the press waits for script frame 3 (window frame 6);
    // one event per frame after it; the save waits for idle (frame 10) and fires one frame later.
    const std::vector<std::string> expected = {"3: tool 1",      "4: material ketchup", "6: cursor 0,0",  "6: press 0",     "7: cursor 10,0",
                                               "8: cursor 10,0", "8: release 0",   "11: volume v.vtu", "12: crease 90",
                                               "13: surface v.ply"};
    EXPECT_EQ(target.log, expected);
}

TEST(InputScriptPlayer, PlaysOpenCancelAndRepair) {
    InputScriptPlayer player(parse(R"([{"event": "open", "file": "big.obj"}, {"event": "cancel_task"},
        {"event": "repair", "repair": "autorefine"}])"));
    FakeTarget target;
    target.is_ready = true;
    for (target.frame = 0; target.frame < 4; ++target.frame) player.advance(target);
    EXPECT_EQ(target.log, (std::vector<std::string>{"0: open big.obj", "1: cancel", "2: repair autorefine"}));
}

TEST(InputScriptPlayer, PlaysTheDocumentEvents) {
    InputScriptPlayer player(parse(R"([{"event": "quit"}, {"event": "dialog", "button": "cancel"},
        {"event": "close_window"}, {"event": "dialog", "button": "save", "file": "s.json"},
        {"event": "open_example", "name": "spot"}, {"event": "recover"}, {"event": "discard_recovery"},
        {"event": "autosave"}, {"event": "kill"}])"));
    FakeTarget target;
    target.is_ready = true;
    for (target.frame = 0; target.frame < 10; ++target.frame) player.advance(target);
    EXPECT_EQ(target.log, (std::vector<std::string>{"0: quit", "1: dialog cancel", "2: close window", "3: dialog save s.json",
                                                    "4: example spot", "5: recover", "6: discard recovery",
                                                    "7: autosave", "8: kill"}));
}

TEST(InputScriptPlayer, PlaysTheReferenceEventsWithTheirSettingsAndSnapshot) {
    InputScriptPlayer player(parse(R"([{"event": "render_reference", "seconds": 3, "noise": 7, "size": 2},
        {"event": "render_reference"}, {"event": "cancel_reference"}, {"event": "save_reference", "file": "r.png"}, {"event": "snapshot"}])"));
    FakeTarget target;
    target.is_ready = true;
    for (target.frame = 0; target.frame < 6; ++target.frame) player.advance(target);
    EXPECT_EQ(target.log, (std::vector<std::string>{"0: reference 3 7 2", "1: reference - - -", "2: cancel reference",
                                                    "3: save reference r.png", "4: snapshot"}));
}

TEST(InputScriptPlayer, PlaysSaveImageAndTurntable) {
    InputScriptPlayer player(parse(R"([{"event": "save_image", "file": "out/view.jpg"},
        {"event": "export_turntable", "file": "spin.mp4", "frames": 8}, {"event": "export_turntable", "file": "a.mp4"}])"));
    FakeTarget target;
    target.is_ready = true;
    for (target.frame = 0; target.frame < 4; ++target.frame) player.advance(target);
    EXPECT_EQ(target.log, (std::vector<std::string>{"0: save image view.jpg", "1: turntable spin.mp4 8",
                                                    "2: turntable a.mp4 36"}));
}

TEST(InputScript, ExampleScriptsParse) {
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(WAXWORK_ASSET_DIR) / "input")) {
        if (entry.path().extension() != ".json") continue;
        ++count;
        const InputScript script = read_input_script(entry.path());
        EXPECT_FALSE(script.events.empty()) << entry.path();
    }
    EXPECT_GE(count, 1);
}

TEST(InputScript, KeyNames) {
    EXPECT_EQ(key_from_name("c"), GLFW_KEY_C);
    EXPECT_EQ(key_from_name("Z"), GLFW_KEY_Z);
    EXPECT_EQ(key_from_name("7"), GLFW_KEY_7);
    EXPECT_EQ(key_from_name("Esc"), GLFW_KEY_ESCAPE);
    EXPECT_EQ(key_from_name("ESCAPE"), GLFW_KEY_ESCAPE);
    EXPECT_FALSE(key_from_name("F1"));
    EXPECT_FALSE(key_from_name(""));
}

}  // namespace
}  // namespace waxwork
