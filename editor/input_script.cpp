#include "editor/input_script.h"

#include "base/error.h"
#include "scene/json_fields.h"
#include "solver/material.h"
#include "render/image_background.h"
#include "render/turntable.h"
#include "solver/shading_surface.h"

#include <GLFW/glfw3.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>

namespace waxwork {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

std::optional<int> key_from_name(const std::string& name) {
    std::string n = name;
    std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (n.size() == 1 && n[0] >= 'a' && n[0] <= 'z') return GLFW_KEY_A + (n[0] - 'a');
    if (n.size() == 1 && n[0] >= '0' && n[0] <= '9') return GLFW_KEY_0 + (n[0] - '0');
    if (n == "escape" || n == "esc") return GLFW_KEY_ESCAPE;
    if (n == "home") return GLFW_KEY_HOME;
    if (n == "tab") return GLFW_KEY_TAB;
    if (n == "delete") return GLFW_KEY_DELETE;
    if (n == "enter") return GLFW_KEY_ENTER;
    if (n == "space") return GLFW_KEY_SPACE;
    return std::nullopt;
}

namespace {

double coordinate(const Json& v, const std::string& context) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) fail_json(context, "expected a finite number");
    const double c = v.get<double>();
    // Far outside any window: a typo, not a position.
    if (std::abs(c) > 1e5) fail_json(context, "must be a window coordinate within +-100000");
    return c;
}

std::array<double, 2> point_from(const Json& v, const std::string& context) {
    if (!v.is_array() || v.size() != 2) fail_json(context, "expected a point [x, y]");
    return {coordinate(v[0], context + " x"), coordinate(v[1], context + " y")};
}

int button_from(FieldReader& in) {
    if (!in.has("button")) return GLFW_MOUSE_BUTTON_LEFT;
    const Json& b = in.at("button");
    if (b == "left") return GLFW_MOUSE_BUTTON_LEFT;
    if (b == "right") return GLFW_MOUSE_BUTTON_RIGHT;
    if (b == "middle") return GLFW_MOUSE_BUTTON_MIDDLE;
    fail_json(in.field("button"), "expected \"left\", \"right\" or \"middle\"");
}

int mods_from(FieldReader& in) {
    if (!in.has("mods")) return 0;
    const Json& list = in.at("mods");
    if (!list.is_array()) fail_json(in.field("mods"), "expected a list of \"shift\", \"ctrl\", \"alt\"");
    int mods = 0;
    for (const Json& m : list) {
        if (m == "shift") mods |= GLFW_MOD_SHIFT;
        else if (m == "ctrl") mods |= GLFW_MOD_CONTROL;
        else if (m == "alt") mods |= GLFW_MOD_ALT;
        else fail_json(in.field("mods"), "expected a list of \"shift\", \"ctrl\", \"alt\"");
    }
    return mods;
}

void read_position(FieldReader& in, ScriptEvent& e) {
    e.x = coordinate(in.at("x"), in.field("x"));
    e.y = coordinate(in.at("y"), in.field("y"));
}

// One entry, appended to `events` (a drag as several).
void parse_entry(const Json& json, size_t index, const fs::path& base, const std::string& name,
                 std::vector<ScriptEvent>& events) {
    const std::string entry = name + ": entry " + std::to_string(index);
    if (!json.is_object()) fail_json(entry, "expected a JSON object with an \"event\"");
    const auto kind_it = json.find("event");
    if (kind_it == json.end() || !kind_it->is_string()) fail_json(entry, "missing field 'event' (a string)");
    const std::string kind = kind_it->get<std::string>();
    const std::string context = entry + " (" + kind + ")";
    FieldReader in(json, context);
    in.ignore("event");
    ScriptEvent e;
    e.context = context;
    if (in.has("frame")) {
        const int64_t f = in.integer("frame");
        if (f < 0 || f > 10'000'000) fail_json(in.field("frame"), "must be a frame number >= 0");
        e.frame = static_cast<int>(f);
    }
    if (kind == "move" || kind == "press" || kind == "release") {
        e.action = kind == "move" ? ScriptAction::Move : kind == "press" ? ScriptAction::Press : ScriptAction::Release;
        read_position(in, e);
        if (kind != "move") e.button = button_from(in);
        e.mods = mods_from(in);
        events.push_back(e);
    } else if (kind == "scroll") {
        e.action = ScriptAction::Scroll;
        read_position(in, e);
        e.scroll = in.number("dy");
        if (std::abs(e.scroll) > 1000) fail_json(in.field("dy"), "must be at most 1000 wheel steps");
        events.push_back(e);
    } else if (kind == "drag") {
        e.button = button_from(in);
        e.mods = mods_from(in);
        std::vector<std::array<double, 2>> points;
        if (in.has("points") == (in.has("from") || in.has("to")))
            fail_json(context, "give either 'from' and 'to' (with 'steps') or 'points'");
        if (in.has("points")) {
            const Json& list = in.at("points");
            if (!list.is_array() || list.size() < 2) fail_json(in.field("points"), "expected at least two [x, y] points");
            for (size_t i = 0; i < list.size(); ++i)
                points.push_back(point_from(list[i], in.field("points") + " point " + std::to_string(i)));
        } else {
            const auto from = point_from(in.at("from"), in.field("from")), to = point_from(in.at("to"), in.field("to"));
            const int64_t steps = in.integer("steps", 10);
            if (steps < 1 || steps > 10000) fail_json(in.field("steps"), "must be between 1 and 10000");
            for (int64_t i = 0; i <= steps; ++i) {
                const double t = static_cast<double>(i) / static_cast<double>(steps);
                points.push_back({from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1])});
            }
        }
        for (size_t i = 0; i < points.size(); ++i) {
            ScriptEvent step = e;
            if (i > 0) step.frame.reset();
            step.action = i == 0 ? ScriptAction::Press : ScriptAction::Move;
            step.x = points[i][0];
            step.y = points[i][1];
            events.push_back(step);
        }
        ScriptEvent release = e;
        release.frame.reset();
        release.action = ScriptAction::Release;
        release.x = points.back()[0];
        release.y = points.back()[1];
        events.push_back(release);
    } else if (kind == "key") {
        e.action = ScriptAction::Key;
        const Json& k = in.at("key");
        const std::optional<int> key = k.is_string() ? key_from_name(k.get<std::string>()) : std::nullopt;
        if (!key)
            fail_json(in.field("key"), "expected a key name: A-Z, 0-9, Escape, Home, Tab, Delete, Enter or Space");
        e.key = *key;
        e.mods = mods_from(in);
        events.push_back(e);
    } else if (kind == "tool") {
        e.action = ScriptAction::SelectTool;
        const Json& t = in.at("tool");
        const auto& tools = tool_infos();
        const auto it = std::find_if(tools.begin(), tools.end(), [&](const ToolInfo& info) { return t == info.id; });
        if (it == tools.end()) {
            std::string ids;
            for (const ToolInfo& info : tools) ids += (ids.empty() ? "" : ", ") + std::string(info.id);
            fail_json(in.field("tool"), "expected one of " + ids);
        }
        e.tool = it->tool;
        events.push_back(e);
    } else if (kind == "material") {
        e.action = ScriptAction::SelectMaterial;
        const Json& m = in.at("material");
        const std::vector<std::string> names = material_preset_names();
        if (!m.is_string() || std::find(names.begin(), names.end(), m.get<std::string>()) == names.end()) {
            std::string list;
            for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
            fail_json(in.field("material"), "expected a measured preset: " + list);
        }
        e.material = m.get<std::string>();
        events.push_back(e);
    } else if (kind == "crease_angle") {
        e.action = ScriptAction::SetCreaseAngle;
        e.degrees = in.number("degrees");
        if (!is_crease_angle(e.degrees)) fail_json(in.field("degrees"), "must be between 0 and 180");
        events.push_back(e);
    } else if (kind == "idle") {
        e.action = ScriptAction::WaitIdle;
        events.push_back(e);
    } else if (kind == "render_reference") {
        e.action = ScriptAction::RenderReference;
        if (in.has("seconds")) {
            e.seconds = in.number("seconds");
            if (!(*e.seconds > 0 && *e.seconds <= 3600)) fail_json(in.field("seconds"), "must be above 0 and at most 3600");
        }
        if (in.has("noise")) {
            e.noise_percent = in.number("noise");
            if (!(*e.noise_percent >= 0 && *e.noise_percent < 100)) fail_json(in.field("noise"), "must be a percentage in [0, 100)");
        }
        if (in.has("size")) {
            const int64_t divisor = in.integer("size");
            if (divisor != 1 && divisor != 2 && divisor != 4) fail_json(in.field("size"), "must be 4, 2 or 1 (1/size of the view across)");
            e.size_divisor = static_cast<int>(divisor);
        }
        events.push_back(e);
    } else if (kind == "cancel_reference") {
        e.action = ScriptAction::CancelReference;
        events.push_back(e);
    } else if (kind == "background") {
        e.action = ScriptAction::SetBackground;
        const Json& b = in.at("background");
        if (!b.is_string()) fail_json(in.field("background"), "expected \"automatic\", \"environment\", \"R,G,B\" or \"#RRGGBB\"");
        e.background = b.get<std::string>();
        if (e.background != "automatic") {
            ImageBackground parsed;
            try {
                parsed = parse_background(e.background);
            } catch (const InvalidArgumentError& error) {
                fail_json(in.field("background"), error.what());
            }
            if (parsed.kind == BackgroundKind::Transparent)
                fail_json(in.field("background"), "a window cannot show a transparent background");
        }
        events.push_back(e);
    } else if (kind == "snapshot") {
        e.action = ScriptAction::Snapshot;
        events.push_back(e);
    } else if (kind == "save_session" || kind == "save_volume" || kind == "export_surface" || kind == "open" ||
               kind == "save_reference" || kind == "save_image" || kind == "export_turntable") {
        e.action = kind == "save_session"     ? ScriptAction::SaveSession
                   : kind == "save_volume"    ? ScriptAction::SaveVolume
                   : kind == "export_surface" ? ScriptAction::ExportSurface
                   : kind == "save_reference" ? ScriptAction::SaveReference
                   : kind == "save_image"     ? ScriptAction::SaveImage
                   : kind == "open"           ? ScriptAction::Open
                                              : ScriptAction::ExportTurntable;
        const Json& f = in.at("file");
        if (!f.is_string() || f.get<std::string>().empty()) fail_json(in.field("file"), "expected a file path");
        e.file = fs::absolute(base / fs::path(f.get<std::string>()));
        if (e.action == ScriptAction::ExportTurntable) {
            const int64_t frames = in.integer("frames", kDefaultTurntableFrames);
            if (frames < 1 || frames > 100000) fail_json(in.field("frames"), "must be between 1 and 100000");
            e.frames = static_cast<int>(frames);
        }
        events.push_back(e);
    } else if (kind == "quit" || kind == "close_window" || kind == "recover" || kind == "discard_recovery" ||
               kind == "autosave" || kind == "kill") {
        e.action = kind == "quit"               ? ScriptAction::Quit
                   : kind == "close_window"     ? ScriptAction::CloseWindow
                   : kind == "recover"          ? ScriptAction::Recover
                   : kind == "discard_recovery" ? ScriptAction::DiscardRecovery
                   : kind == "autosave"         ? ScriptAction::Autosave
                                                : ScriptAction::Kill;
        events.push_back(e);
    } else if (kind == "dialog") {
        e.action = ScriptAction::Dialog;
        const Json& b = in.at("button");
        if (!b.is_string() || (b != "save" && b != "discard" && b != "cancel"))
            fail_json(in.field("button"), "expected \"save\", \"discard\" or \"cancel\"");
        e.name = b.get<std::string>();
        if (in.has("file")) {
            const Json& f = in.at("file");
            if (!f.is_string() || f.get<std::string>().empty()) fail_json(in.field("file"), "expected a file path");
            e.file = fs::absolute(base / fs::path(f.get<std::string>()));
        }
        events.push_back(e);
    } else if (kind == "open_example") {
        e.action = ScriptAction::OpenExample;
        const Json& n = in.at("name");
        if (!n.is_string() || n.get<std::string>().empty()) fail_json(in.field("name"), "expected an example's name, e.g. \"spot\"");
        e.name = n.get<std::string>();
        events.push_back(e);
    } else if (kind == "cancel_task") {
        e.action = ScriptAction::CancelTask;
        events.push_back(e);
    } else if (kind == "repair") {
        e.action = ScriptAction::Repair;
        const Json& r = in.at("repair");
        static const std::vector<std::string> ids = {"wrap", "fill_holes", "autorefine", "fill_holes_autorefine"};
        if (!r.is_string() || std::find(ids.begin(), ids.end(), r.get<std::string>()) == ids.end())
            fail_json(in.field("repair"), "expected \"wrap\", \"fill_holes\", \"autorefine\" or \"fill_holes_autorefine\"");
        e.repair = r.get<std::string>();
        events.push_back(e);
    } else {
        fail_json(entry, "unknown event \"" + kind +
                             "\" (expected press, move, release, drag, scroll, key, tool, material, crease_angle, "
                             "idle, save_session, save_volume, export_surface, open, cancel_task, repair, render_reference, "
                             "cancel_reference, save_reference, quit, close_window, dialog, open_example, recover, "
                             "discard_recovery, autosave, kill, snapshot, save_image, export_turntable, background)");
    }
    in.finish();
}

}  // namespace

InputScript parse_input_script(const Json& json, const fs::path& base_directory, const std::string& name) {
    if (!json.is_array()) fail_json(name, "an input script is a JSON list of events");
    InputScript script;
    script.name = name;
    for (size_t i = 0; i < json.size(); ++i) parse_entry(json[i], i, base_directory, name, script.events);
    return script;
}

InputScript read_input_script(const fs::path& path) {
    return parse_input_script(read_json_file(path), fs::absolute(path).parent_path(), path.string());
}

void InputScriptPlayer::advance(ScriptTarget& target) {
    if (frame_ < 0 && !target.ready()) return;
    ++frame_;
    while (next_ < script_.events.size()) {
        const ScriptEvent& e = script_.events[next_];
        if (e.frame && frame_ < *e.frame) return;
        if (last_fired_ >= 0 && frame_ <= last_fired_) return;  // one event per frame
        if (e.action == ScriptAction::WaitIdle && !target.idle()) return;
        switch (e.action) {
        case ScriptAction::Move: target.cursor(e.x, e.y); break;
        case ScriptAction::Press:
        case ScriptAction::Release:
            target.cursor(e.x, e.y);
            target.button(e.button, e.action == ScriptAction::Press, e.mods);
            break;
        case ScriptAction::Scroll:
            target.cursor(e.x, e.y);
            target.scroll(e.scroll);
            break;
        case ScriptAction::Key: target.key(e.key, e.mods); break;
        case ScriptAction::SelectTool: target.select_tool(e.tool); break;
        case ScriptAction::SelectMaterial: target.select_material(e.material); break;
        case ScriptAction::SetCreaseAngle: target.set_crease_angle(e.degrees); break;
        case ScriptAction::WaitIdle: break;
        case ScriptAction::SaveSession: target.save_session(e.file); break;
        case ScriptAction::SaveVolume: target.save_volume(e.file); break;
        case ScriptAction::ExportSurface: target.export_surface(e.file); break;
        case ScriptAction::Open: target.open_file(e.file); break;
        case ScriptAction::CancelTask: target.cancel_task(); break;
        case ScriptAction::Repair: target.choose_repair(e.repair); break;
        case ScriptAction::RenderReference: target.render_reference(e.seconds, e.noise_percent, e.size_divisor); break;
        case ScriptAction::CancelReference: target.cancel_reference(); break;
        case ScriptAction::SaveReference: target.save_reference(e.file); break;
        case ScriptAction::Snapshot: target.snapshot(); break;
        case ScriptAction::Quit: target.quit(); break;
        case ScriptAction::CloseWindow: target.close_window(); break;
        case ScriptAction::Dialog: target.answer_dialog(e.name, e.file); break;
        case ScriptAction::OpenExample: target.open_example(e.name); break;
        case ScriptAction::Recover: target.recover(true); break;
        case ScriptAction::DiscardRecovery: target.recover(false); break;
        case ScriptAction::Autosave: target.autosave(); break;
        case ScriptAction::Kill: target.kill(); break;
        case ScriptAction::SaveImage: target.save_image(e.file); break;
        case ScriptAction::ExportTurntable: target.export_turntable(e.file, e.frames); break;
        case ScriptAction::SetBackground: target.set_background(e.background); break;
        }
        last_fired_ = frame_;
        ++next_;
    }
}

}  // namespace waxwork
