#include "scene/session.h"

#include "base/error.h"
#include "base/progress.h"
#include "base/timing.h"
#include "gl/gl_context.h"
#include "io/atomic_file.h"
#include "io/file_extension.h"
#include "io/image_io.h"
#include "io/output_folder.h"
#include "io/surface_reader.h"
#include "io/volume_file.h"
#include "render/camera.h"
#include "render/render_input.h"
#include "scene/environment_loading.h"
#include "scene/json_fields.h"
#include "scene/live_scene.h"
#include "scene/scene_core.h"
#include "solver/conjugate_gradient.h"
#include "solver/frame_budget.h"
#include "solver/material.h"
#include "solver/mesh_resolution.h"
#include "solver/solved_scene.h"
#include "tetops/tetrahedralize.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <climits>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

namespace waxwork {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

Json rgb_to_json(const Rgb& c) { return Json::array({c[0], c[1], c[2]}); }

Rgb rgb_from(FieldReader& in, const std::string& key) {
    const Eigen::Vector3d v = in.vector(key);
    if ((v.array() < 0).any()) fail_json(in.field(key), "must be non-negative");
    return {v.x(), v.y(), v.z()};
}

// The shape of an area light: {"center", "normal", "tangent" (optional), "size": [w, h]} for "rect",
// {"center", "normal", "radius"} for "disk", {"center", "radius"} for "sphere".
void area_light_from_json(const Json& json, const std::string& context, Light& light) {
    FieldReader in(json, context);
    light.vector = in.vector("center");
    if (light.type != LightType::Sphere) {
        light.axis = in.vector("normal");
        if (light.axis.cwiseAbs().maxCoeff() == 0) fail_json(in.field("normal"), "must not be zero");
    }
    if (light.type == LightType::Rectangle) {
        if (in.has("tangent")) {
            light.tangent = in.vector("tangent");
            if (!tangent_spans_plane(light.axis, light.tangent))
                fail_json(in.field("tangent"), "must not be zero or parallel to the normal");
        } else {
            light.tangent = default_rect_tangent(light.axis);
        }
        const Json& size = in.at("size");
        if (!size.is_array() || size.size() != 2 || !size[0].is_number() || !size[1].is_number())
            fail_json(in.field("size"), "expected [width, height]");
        light.size = {size[0].get<double>(), size[1].get<double>()};
        if (!(light.size.allFinite() && light.size.minCoeff() > 0))
            fail_json(in.field("size"), "width and height must be finite and positive");
    } else {
        light.size.setConstant(in.number("radius"));
        if (!(light.size.x() > 0)) fail_json(in.field("radius"), "must be positive");
    }
    in.finish();
}

// {"direction": [x, y, z]} (directional), {"position": [x, y, z]} (point) or one of {"rect": SHAPE},
// {"disk": SHAPE}, {"sphere": SHAPE} (area_light_from_json), with an optional "intensity".
Light light_from_json(const Json& json, const std::string& context) {
    FieldReader in(json, context);
    Light light;
    static const std::array<std::pair<const char*, LightType>, 5> kinds = {{{"direction", LightType::Directional},
                                                                            {"position", LightType::Point},
                                                                            {"rect", LightType::Rectangle},
                                                                            {"disk", LightType::Disk},
                                                                            {"sphere", LightType::Sphere}}};
    const auto given = std::count_if(kinds.begin(), kinds.end(), [&](const auto& kind) { return in.has(kind.first); });
    if (given != 1)
        fail_json(context, "give exactly one of 'direction' (a directional light), 'position' (a point light), "
                           "'rect', 'disk' and 'sphere' (area lights)");
    if (in.has("direction")) {
        light.type = LightType::Directional;
        light.vector = in.vector("direction");
        if (light.vector.norm() == 0) fail_json(in.field("direction"), "must not be zero");
    } else if (in.has("position")) {
        light.type = LightType::Point;
        light.vector = in.vector("position");
    } else {
        for (const auto& [key, type] : kinds) {
            if (!in.has(key)) continue;
            light.type = type;
            area_light_from_json(in.at(key), in.field(key), light);
        }
    }
    if (in.has("intensity")) light.intensity = rgb_from(in, "intensity");
    in.finish();
    return light;
}

Json light_to_json(const Light& light) {
    Json j;
    switch (light.type) {
    case LightType::Directional: j["direction"] = vector_to_json(light.vector); break;
    case LightType::Point: j["position"] = vector_to_json(light.vector); break;
    case LightType::Rectangle:
        j["rect"] = {{"center", vector_to_json(light.vector)},
                     {"normal", vector_to_json(light.axis)},
                     {"tangent", vector_to_json(light.tangent)},
                     {"size", Json::array({light.size.x(), light.size.y()})}};
        break;
    case LightType::Disk:
        j["disk"] = {{"center", vector_to_json(light.vector)}, {"normal", vector_to_json(light.axis)}, {"radius", light.size.x()}};
        break;
    case LightType::Sphere:
        j["sphere"] = {{"center", vector_to_json(light.vector)}, {"radius", light.size.x()}};
        break;
    }
    j["intensity"] = rgb_to_json(light.intensity);
    return j;
}

// {"file": PATH | "sky": {"sun_elevation", "sun_azimuth", "turbidity"}, "rotation", "intensity",
// "background"}: the environment, its file read (relative paths from `base`, the session's folder).
EnvironmentLight environment_from_json(const Json& json, const std::string& context, const fs::path& base) {
    FieldReader in(json, context);
    if (in.has("file") == in.has("sky"))
        fail_json(context, "give exactly one of 'file' (an equirectangular .hdr image) and 'sky' (the built-in sky)");
    EnvironmentSpec spec;
    const std::string source = in.has("file") ? "file" : "sky";
    if (in.has("file")) {
        const Json& file = in.at("file");
        if (!file.is_string() || file.get<std::string>().empty()) fail_json(in.field("file"), "expected a file path");
        spec.file = (base / fs::path(file.get<std::string>())).string();
    } else {
        FieldReader sky(in.at("sky"), in.field("sky"));
        SkySettings settings;
        settings.sun_elevation_degrees = sky.number("sun_elevation");
        settings.sun_azimuth_degrees = sky.number("sun_azimuth");
        settings.turbidity = sky.number("turbidity", settings.turbidity);
        sky.finish();
        spec.sky = settings;
    }
    spec.rotation_degrees = in.number("rotation", 0.0);
    spec.intensity = in.number("intensity", 1.0);
    if (!(spec.intensity >= 0 && spec.intensity <= kMaxLightIntensity))
        fail_json(in.field("intensity"), "must be non-negative and at most 1e15");
    const bool background = in.boolean("background", true);
    in.finish();
    EnvironmentLight environment;
    try {
        environment = load_environment(spec);
    } catch (const Error& e) {
        fail_json(in.field(source), e.what());
    }
    environment.background = background;
    return environment;
}

Json environment_to_json(const EnvironmentLight& environment) {
    Json j = Json::object();
    if (environment.sky) {
        j["sky"] = {{"sun_elevation", environment.sky->sun_elevation_degrees},
                    {"sun_azimuth", environment.sky->sun_azimuth_degrees},
                    {"turbidity", environment.sky->turbidity}};
    } else {
        j["file"] = environment.file;
    }
    j["rotation"] = environment.rotation_degrees;
    j["intensity"] = environment.intensity;
    j["background"] = environment.background;
    return j;
}

// "lights", "ambient", "shadows", "environment" of `in` into `lighting` (only the fields present;
// "environment": null removes it). Environment files resolve against `base`.
void read_lighting_fields(FieldReader& in, Lighting& lighting, const fs::path& base) {
    if (in.has("lights")) {
        const Json& lights = in.at("lights");
        if (!lights.is_array()) fail_json(in.field("lights"), "expected an array of lights");
        lighting.lights.clear();
        for (size_t i = 0; i < lights.size(); ++i)
            lighting.lights.push_back(light_from_json(lights[i], in.field("lights") + " light " + std::to_string(i)));
    }
    if (in.has("ambient")) lighting.ambient = rgb_from(in, "ambient");
    lighting.shadows = in.boolean("shadows", lighting.shadows);
    if (in.has("environment")) {
        const Json& environment = in.at("environment");
        if (environment.is_null()) {
            lighting.environment.reset();
        } else {
            lighting.environment = environment_from_json(environment, in.field("environment"), base);
        }
    }
}

void write_lighting_fields(const Lighting& lighting, Json& j) {
    Json lights = Json::array();
    for (const Light& l : lighting.lights) lights.push_back(light_to_json(l));
    j["lights"] = lights;
    j["ambient"] = rgb_to_json(lighting.ambient);
    j["shadows"] = lighting.shadows;
    j["environment"] = lighting.environment ? environment_to_json(*lighting.environment) : Json(nullptr);
}

}  // namespace

Json lighting_to_json(const Lighting& lighting) {
    Json j = Json::object();
    write_lighting_fields(lighting, j);
    return j;
}

namespace {

CameraSettings camera_from_json(const Json& json, const std::string& context, CameraSettings camera) {
    FieldReader in(json, context);
    if (in.has("eye_direction")) camera.eye_direction = in.vector("eye_direction");
    if (camera.eye_direction.cwiseAbs().maxCoeff() == 0) fail_json(in.field("eye_direction"), "must not be zero");
    if (in.has("up")) camera.up = in.vector("up");
    if (!up_orients_view(camera.eye_direction, camera.up))
        fail_json(in.field(in.has("up") ? "up" : "eye_direction"), "the up vector must not be zero or parallel to the eye direction");
    camera.fov_y_degrees = in.number("fov_y_deg", camera.fov_y_degrees);
    if (!(camera.fov_y_degrees > 1 && camera.fov_y_degrees < 170)) fail_json(in.field("fov_y_deg"), "must be in (1, 170)");
    camera.margin = in.number("margin", camera.margin);
    if (!(camera.margin > 0)) fail_json(in.field("margin"), "must be positive");
    if (in.has("target_offset")) camera.target_offset = in.vector("target_offset");
    in.finish();
    return camera;
}

Json camera_to_json(const CameraSettings& c) {
    Json j{{"eye_direction", vector_to_json(c.eye_direction)},
           {"up", vector_to_json(c.up)},
           {"fov_y_deg", c.fov_y_degrees},
           {"margin", c.margin}};
    if (c.target_offset != Eigen::Vector3d::Zero()) j["target_offset"] = vector_to_json(c.target_offset);
    return j;
}

std::string output_name(FieldReader& in, const std::string& key) {
    const Json& v = in.at(key);
    if (!v.is_string() || v.get<std::string>().empty()) fail_json(in.field(key), "expected a file name");
    // Outputs go to the run's output directory: a session from elsewhere writes nothing outside it.
    const std::string name = v.get<std::string>();
    const std::string problem = output_name_problem(name);
    if (!problem.empty()) fail_json(in.field(key), problem);
    return name;
}

int count_from(FieldReader& in, const std::string& key) {
    const int64_t n = in.integer(key);
    if (n < 1 || n > 1000000) fail_json(in.field(key), "must be a count >= 1");
    return static_cast<int>(n);
}

SessionStep step_from_json(const Json& json, const std::string& context, const Session& session,
                           const fs::path& base_directory) {
    if (!json.is_object()) fail_json(context, "a step must be a JSON object");
    if (json.contains("op")) return edit_operation_from_json(json, context);
    FieldReader in(json, context);
    SessionStep step;
    if (in.has("render")) {
        RenderStep r;
        r.file = output_name(in, "render");
        if (lower_extension(r.file) != ".png") fail_json(in.field("render"), "'" + r.file + "' must be a .png");
        if (in.has("frames")) r.frames = count_from(in, "frames");
        if (in.has("exposure")) {
            r.exposure = in.number("exposure");
            // The renderer multiplies radiance by it in float: beyond 1e30 it overflows.
            if (!(*r.exposure > 0 && *r.exposure <= 1e30)) fail_json(in.field("exposure"), "must be a positive number");
        }
        step = r;
    } else if (in.has("save")) {
        step = SaveStep{output_name(in, "save")};
        if (!is_volume_path(std::get<SaveStep>(step).file))
            fail_json(in.field("save"), "'" + std::get<SaveStep>(step).file +
                                            "' must name a volume format (.vtu keeps pieces and materials; .msh, .mesh, .node)");
    } else if (in.has("light")) {
        LightStep l{session.lighting};
        FieldReader light(in.at("light"), in.field("light"));
        read_lighting_fields(light, l.lighting, base_directory);
        light.finish();
        try {
            validate(l.lighting);
        } catch (const Error& e) {
            fail_json(in.field("light"), e.what());
        }
        step = l;
    } else if (in.has("camera")) {
        step = CameraStep{camera_from_json(in.at("camera"), in.field("camera"), session.camera)};
    } else if (in.has("undo")) {
        step = UndoStep{count_from(in, "undo")};
    } else if (in.has("redo")) {
        step = RedoStep{count_from(in, "redo")};
    } else {
        fail_json(context, "expected an edit operation (\"op\") or one of render, save, light, camera, undo, redo");
    }
    in.finish();
    return step;
}

std::string step_kind(const SessionStep& step) {
    if (const auto* op = std::get_if<EditOperation>(&step)) return operation_name(*op);
    static const char* const kinds[] = {"", "render", "save", "light", "camera", "undo", "redo"};
    return kinds[step.index()];
}

Json step_to_json(const SessionStep& step, const Session& session) {
    if (const auto* op = std::get_if<EditOperation>(&step)) return to_json(*op);
    if (const auto* r = std::get_if<RenderStep>(&step)) {
        Json j{{"render", r->file}};
        if (r->frames) j["frames"] = *r->frames;
        if (r->exposure) j["exposure"] = *r->exposure;
        return j;
    }
    if (const auto* s = std::get_if<SaveStep>(&step)) return Json{{"save", s->file}};
    if (const auto* l = std::get_if<LightStep>(&step)) {
        Json light = Json::object();
        write_lighting_fields(l->lighting, light);
        return Json{{"light", light}};
    }
    if (const auto* c = std::get_if<CameraStep>(&step)) return Json{{"camera", camera_to_json(c->camera)}};
    if (const auto* u = std::get_if<UndoStep>(&step)) return Json{{"undo", u->count}};
    (void)session;
    return Json{{"redo", std::get<RedoStep>(step).count}};
}

// The optional meshing fields of a surface input, named as the command line's options. Written only
// when they differ from the defaults, so a session that uses none reads as before.
const char* const kMeshingFields[] = {"min_dihedral", "radius_edge", "fill_holes", "autorefine",
                                      "repair", "wrap_alpha", "wrap_offset"};

bool has_meshing_fields(const FieldReader& input) {
    return std::any_of(std::begin(kMeshingFields), std::end(kMeshingFields),
                       [&](const char* key) { return input.has(key); });
}

void read_meshing_fields(FieldReader& input, SessionInput& session_input) {
    session_input.min_dihedral_deg = input.number("min_dihedral", session_input.min_dihedral_deg);
    session_input.max_radius_edge_ratio = input.number("radius_edge", session_input.max_radius_edge_ratio);
    SurfaceRepairOptions& repair = session_input.repair;
    repair.fill_holes = input.boolean("fill_holes", false);
    repair.autorefine = input.boolean("autorefine", false);
    if (input.has("repair")) {
        if (input.at("repair") != "wrap") fail_json(input.field("repair"), "expected \"wrap\"");
        if (repair.fill_holes || repair.autorefine)
            fail_json(input.field("repair"), "wrapping replaces 'fill_holes' and 'autorefine'; give one or the other");
        repair.wrap = WrapOptions{};
    }
    for (const char* key : {"wrap_alpha", "wrap_offset"}) {
        if (!input.has(key)) continue;
        if (!repair.wrap) fail_json(input.field(key), "needs \"repair\": \"wrap\"");
        const double value = input.number(key);
        if (!(value > 0)) fail_json(input.field(key), "must be positive");
        (std::string(key) == "wrap_alpha" ? repair.wrap->alpha : repair.wrap->offset) = value;
    }
}

void write_meshing_fields(const SessionInput& session_input, Json& input) {
    const SessionInput defaults;
    if (session_input.min_dihedral_deg != defaults.min_dihedral_deg) input["min_dihedral"] = session_input.min_dihedral_deg;
    if (session_input.max_radius_edge_ratio != defaults.max_radius_edge_ratio)
        input["radius_edge"] = session_input.max_radius_edge_ratio;
    const SurfaceRepairOptions& repair = session_input.repair;
    if (repair.fill_holes) input["fill_holes"] = true;
    if (repair.autorefine) input["autorefine"] = true;
    if (repair.wrap) {
        input["repair"] = "wrap";
        if (repair.wrap->alpha) input["wrap_alpha"] = *repair.wrap->alpha;
        if (repair.wrap->offset) input["wrap_offset"] = *repair.wrap->offset;
    }
}

fs::path relative_if_possible(const fs::path& path, const fs::path& base) {
    std::error_code ec;
    const fs::path relative = fs::relative(path, base, ec);
    return ec || relative.empty() ? path : relative;
}

}  // namespace

Session parse_session(const Json& json, const fs::path& base_directory, const std::string& name) {
    Session session;
    session.name = name;
    FieldReader in(json, name);
    {
        FieldReader input(in.at("input"), in.field("input"));
        if (input.has("surface") == input.has("volume"))
            fail_json(in.field("input"), "give exactly one of 'surface' (a mesh to fill) and 'volume'");
        const std::string key = input.has("surface") ? "surface" : "volume";
        const Json& file = input.at(key);
        if (!file.is_string() || file.get<std::string>().empty()) fail_json(input.field(key), "expected a file path");
        (key == "surface" ? session.input.surface : session.input.volume) =
            base_directory / fs::path(file.get<std::string>());
        if (input.has("max_tets")) {
            const int64_t n = input.integer("max_tets");
            if (n < 1) fail_json(input.field("max_tets"), "must be positive");
            session.input.max_tets = static_cast<size_t>(n);
        }
        if (input.has("edge")) {
            session.input.edge = input.number("edge");
            if (!(*session.input.edge > 0)) fail_json(input.field("edge"), "must be positive");
        }
        if (input.has("mesher")) {
            const Json& m = input.at("mesher");
            if (m == "tetgen") {
                session.input.mesher = Mesher::TetGen;
            } else if (m == "cgal") {
                session.input.mesher = Mesher::Cgal;
            } else if (m == "auto") {
                session.input.mesher = Mesher::Auto;
            } else {
                fail_json(input.field("mesher"), "expected \"auto\", \"tetgen\" or \"cgal\"");
            }
        }
        read_meshing_fields(input, session.input);
        if (key == "volume" && (session.input.max_tets || session.input.edge || input.has("mesher") ||
                                has_meshing_fields(input)))
            fail_json(in.field("input"), "meshing options apply to a 'surface' input only");
        input.finish();
    }
    session.material = in.has("material") ? in.material("material") : material_from_json(Json("marble"), name);
    if (in.has("scale")) {
        session.scale = in.number("scale");
        if (!(*session.scale >= kMinMmPerUnit && *session.scale <= kMaxMmPerUnit))
            fail_json(in.field("scale"), "must be a length in mm per model unit between 1e-6 and 1e6");
    }
    read_lighting_fields(in, session.lighting, base_directory);
    if (session.lighting.environment) {
        // The environment lights the scene as --env does: the key light and ambient only when given.
        if (!in.has("lights")) session.lighting.lights.clear();
        if (!in.has("ambient")) session.lighting.ambient = {0, 0, 0};
    }
    try {
        validate(session.lighting);
    } catch (const Error& e) {
        fail_json(name, e.what());
    }
    if (in.has("camera")) session.camera = camera_from_json(in.at("camera"), in.field("camera"), session.camera);
    if (in.has("image")) {
        FieldReader image(in.at("image"), in.field("image"));
        const int64_t w = image.integer("width", session.width), h = image.integer("height", session.height);
        if (w < 1 || h < 1 || w > kMaxImageSide || h > kMaxImageSide)
            fail_json(in.field("image"), "width and height must be between 1 and " + std::to_string(kMaxImageSide));
        session.width = static_cast<int>(w);
        session.height = static_cast<int>(h);
        image.finish();
    }
    session.tolerance = in.number("tolerance", session.tolerance);
    if (!(session.tolerance >= kMinRelativeTolerance && session.tolerance < 1))
        fail_json(in.field("tolerance"), "must be a relative tolerance in [1e-15, 1)");
    if (in.has("frame_iterations")) session.frame_iterations = count_from(in, "frame_iterations");
    if (in.has("frame_ms")) {
        session.frame_ms = in.number("frame_ms");
        const std::string problem = frame_ms_problem(*session.frame_ms);
        if (!problem.empty()) fail_json(in.field("frame_ms"), problem);
    }
    session.crease_angle_degrees = in.number("crease_angle", session.crease_angle_degrees);
    if (!is_crease_angle(session.crease_angle_degrees))
        fail_json(in.field("crease_angle"), "must be between 0 and 180 degrees");
    const Json& steps = in.at("steps");
    if (!steps.is_array()) fail_json(in.field("steps"), "expected an array of steps");
    for (size_t i = 0; i < steps.size(); ++i)
        session.steps.push_back(step_from_json(steps[i], name + ": step " + std::to_string(i), session, base_directory));
    in.finish();
    return session;
}

Session read_session(const fs::path& path) {
    return parse_session(read_json_file(path), path.parent_path(), path.string());
}

Json session_to_json(const Session& session) {
    Json j;
    Json input = Json::object();
    if (!session.input.surface.empty()) {
        input["surface"] = session.input.surface.generic_string();
        if (session.input.max_tets) input["max_tets"] = *session.input.max_tets;
        if (session.input.edge) input["edge"] = *session.input.edge;
        input["mesher"] = mesher_name(session.input.mesher);
        write_meshing_fields(session.input, input);
    } else {
        input["volume"] = session.input.volume.generic_string();
    }
    j["input"] = input;
    j["material"] = material_to_json(session.material);
    if (session.scale) j["scale"] = *session.scale;
    write_lighting_fields(session.lighting, j);
    j["camera"] = camera_to_json(session.camera);
    j["image"] = Json{{"width", session.width}, {"height", session.height}};
    j["tolerance"] = session.tolerance;
    j["frame_iterations"] = session.frame_iterations;
    if (session.frame_ms) j["frame_ms"] = *session.frame_ms;
    j["crease_angle"] = session.crease_angle_degrees;
    Json steps = Json::array();
    for (const SessionStep& step : session.steps) steps.push_back(step_to_json(step, session));
    j["steps"] = steps;
    return j;
}

void write_session(const fs::path& path, const Session& session) {
    Session relative = session;
    const fs::path base = fs::absolute(path).parent_path();
    if (!relative.input.surface.empty())
        relative.input.surface = relative_if_possible(fs::absolute(relative.input.surface), base);
    if (!relative.input.volume.empty())
        relative.input.volume = relative_if_possible(fs::absolute(relative.input.volume), base);
    const auto relative_environment = [&](Lighting& lighting) {
        if (lighting.environment && !lighting.environment->file.empty())
            lighting.environment->file = relative_if_possible(fs::absolute(lighting.environment->file), base).string();
    };
    relative_environment(relative.lighting);
    for (SessionStep& step : relative.steps)
        if (auto* light = std::get_if<LightStep>(&step)) relative_environment(light->lighting);
    const std::string text = session_to_json(relative).dump(2) + "\n";
    write_file_atomically(path, [&](std::ostream& out) { out << text; });
}

bool writes_outputs(const Session& session) {
    return std::any_of(session.steps.begin(), session.steps.end(), [](const SessionStep& step) {
        return std::holds_alternative<RenderStep>(step) || std::holds_alternative<SaveStep>(step);
    });
}

Session record_session(const Session& setup, const Document& document, const std::vector<SessionStep>& extra_steps,
                       const std::vector<AnchoredSteps>& anchored) {
    Session session = setup;
    session.steps.clear();
    const auto& history = document.history();
    const auto insert_anchored = [&](size_t before) {
        for (const AnchoredSteps& a : anchored)
            if (a.before == before) session.steps.insert(session.steps.end(), a.steps.begin(), a.steps.end());
    };
    for (size_t i = 0; i < history.size(); ++i) {
        insert_anchored(i);
        session.steps.emplace_back(history[i]);
    }
    insert_anchored(history.size());
    session.steps.insert(session.steps.end(), extra_steps.begin(), extra_steps.end());
    return session;
}

SessionVolume read_session_input(const Session& session, Progress* progress) {
    if (!session.input.volume.empty()) {
        report_stage(progress, "reading the volume");
        VolumeFile file = read_volume_file(session.input.volume);
        check_cancelled(progress);
        const ModelScale scale =
            choose_model_scale(session.scale, file.metadata.mm_per_unit, bounding_extent(file.mesh.positions));
        return {std::move(file.mesh), scale};
    }
    const LoadedSurface loaded = load_closed_surface(session.input.surface, session.input.repair, progress);
    const ModelScale scale = choose_model_scale(session.scale, std::nullopt, bounding_extent(loaded.surface.points));
    MeshingOptions meshing;
    meshing.mesher = session.input.mesher;
    meshing.min_dihedral_deg = session.input.min_dihedral_deg;
    meshing.max_radius_edge_ratio = session.input.max_radius_edge_ratio;
    meshing.progress = progress;
    if (loaded.wrap) meshing.remesh_edge_ratio = kWrapRemeshEdgeRatio;
    if (session.input.edge) {
        meshing.sizing.edge_length = session.input.edge;
    } else if (session.input.max_tets) {
        meshing.sizing.target_tets = session.input.max_tets;
    } else {
        meshing.sizing = default_mesh_sizing(loaded.surface, session.material, scale.mm_per_unit);
    }
    return {tetrahedralize_surface_file(session.input.surface, loaded.surface, meshing).mesh, scale};
}

SessionVolume load_session_input(const Session& session, Progress* progress) {
    const std::string context = session.name + ": input";
    try {
        return naming_context(context, [&] { return read_session_input(session, progress); });
    } catch (const FileError& e) {  // still "PATH: PROBLEM" with path() the input; the session follows
        throw FileError(e.path(), e.problem() + " (" + context + ")");
    }
}

FrameBudget session_frame_budget(const Session& session, const SessionRunOptions& run_options) {
    const std::optional<double> ms = run_options.frame_ms ? run_options.frame_ms : session.frame_ms;
    return ms ? FrameBudget::milliseconds(*ms) : FrameBudget::iterations(session.frame_iterations);
}

namespace {

// The file a render or save step writes, or nullptr.
const std::string* output_file(const SessionStep& step) {
    if (const auto* r = std::get_if<RenderStep>(&step)) return &r->file;
    if (const auto* v = std::get_if<SaveStep>(&step)) return &v->file;
    return nullptr;
}

Json written_to_json(const std::vector<fs::path>& written, const fs::path& output_directory) {
    Json list = Json::array();
    for (const fs::path& path : written) list.push_back(path.lexically_relative(output_directory).generic_string());
    return list;
}

// What a replay has done so far, for metrics.json when a step fails.
struct ReplayProgress {
    std::optional<size_t> step;  // the step running; nullopt while the input loads
    Json steps = Json::array();  // metrics of the finished steps
};

// Rethrows the Error being handled with the session and step before its message, keeping its type.
[[noreturn]] void rethrow_in_step(const std::string& context_name) {
    try {
        throw;
    } catch (const FileError& e) {
        throw FileError(e.path(), context_name + ": " + e.problem());
    } catch (const InvalidArgumentError& e) {
        const std::string what = e.what();
        throw InvalidArgumentError(what.rfind(context_name, 0) == 0 ? what : context_name + ": " + what);
    } catch (const InvalidMeshError& e) {
        throw InvalidMeshError(context_name + ": " + e.what());
    } catch (const Error& e) {
        throw AlgorithmError(context_name + ": " + e.what());
    }
}

// The replay behind run_session; returns metrics.json's summary without "status" and "written".
Json replay_session(const Session& session, const fs::path& output_directory, const SessionRunOptions& run_options,
                    SessionResult& result, ReplayProgress& progress) {
    const auto load_start = std::chrono::steady_clock::now();
    SessionVolume input = load_session_input(session);
    Session setup = session;  // the scale resolved: the session's, else the input volume's, else the model's
    setup.scale = input.scale.mm_per_unit;
    result.scale = input.scale;
    Document document(std::move(input.mesh), session.material);
    result.load_ms = milliseconds_since(load_start);
    result.input_tets = document.mesh().tet_count();
    LiveSceneOptions scene_options;  // the scale, tolerance and crease angle come from the session
    scene_options.method = run_options.method;
    scene_options.backend = run_options.backend;
    // One GL context for the whole session, created at the first render (or now, for the GPU solver,
    // which then shares it with the renderer). A context that fails here makes the solver fall back
    // with the reason (live_solver.h).
    std::unique_ptr<HeadlessGlContext> context;
    if (run_options.backend == LiveBackend::Gpu) {
        try {
            context = std::make_unique<HeadlessGlContext>();
            scene_options.gl_context = borrow_headless_solver_context(*context);
        } catch (const Error&) {
            context.reset();
        }
    }
    std::unique_ptr<SurfaceRenderer> renderer;
    // Declared after the context and the renderer: the live scene, which may use the context, goes first.
    SceneCore core(std::move(document), setup, scene_options);
    ImageSettings image;
    image.width = session.width;
    image.height = session.height;
    image.camera = session.camera;

    for (size_t i = 0; i < session.steps.size(); ++i) {
        progress.step = i;
        const SessionStep& step = session.steps[i];
        const std::string context_name = session.name + ": step " + std::to_string(i) + " (" + step_kind(step) + ")";
        const auto start = std::chrono::steady_clock::now();
        StepMetrics m;
        m.name = step_kind(step);
        try {
            if (const auto* op = std::get_if<EditOperation>(&step)) {
                core.apply(*op);
            } else if (const auto* r = std::get_if<RenderStep>(&step)) {
                FrameReport frame;
                if (r->frames) {
                    for (int f = 0; f < *r->frames; ++f) {
                        frame = core.step(session_frame_budget(session, run_options));
                        m.solver_iterations += frame.total_iterations();
                    }
                } else {
                    frame = core.converge();
                    m.solver_iterations = frame.total_iterations();
                }
                if (!context) context = std::make_unique<HeadlessGlContext>();
                context->make_current();  // the solver may have used its own context meanwhile
                if (!renderer) renderer = std::make_unique<SurfaceRenderer>(context->gl());
                const SolvedScene solved = core.live().solved_scene();
                ImageSettings step_image = image;
                if (r->exposure) step_image.exposure = static_cast<float>(*r->exposure);
                const Image picture = render_scene(
                    *renderer, make_render_input(core.document().mesh(), solved, core.live().lighting(), step_image));
                const fs::path path = contained_output_path(output_directory, r->file);
                write_png(picture, path);
                result.written.push_back(path);
            } else if (const auto* s = std::get_if<SaveStep>(&step)) {
                const fs::path path = contained_output_path(output_directory, s->file);
                core.save_volume(path);
                result.written.push_back(path);
            } else if (const auto* l = std::get_if<LightStep>(&step)) {
                core.set_lighting(l->lighting);
            } else if (const auto* c = std::get_if<CameraStep>(&step)) {
                image.camera = c->camera;
            } else if (const auto* u = std::get_if<UndoStep>(&step)) {
                for (int k = 0; k < u->count; ++k) {
                    if (!core.undo()) fail_json(context_name, "nothing left to undo");
                }
            } else {
                for (int k = 0; k < std::get<RedoStep>(step).count; ++k) {
                    if (!core.redo()) fail_json(context_name, "nothing left to redo");
                }
            }
        } catch (const Error&) {
            rethrow_in_step(context_name);
        }
        m.milliseconds = milliseconds_since(start);
        m.tets = core.document().mesh().tet_count();
        m.vertices = core.document().mesh().vertex_count();
        const std::optional<double> error = core.live().estimated_error();
        m.estimated_error = error.value_or(-1);
        progress.steps.push_back(Json{{"step", i},
                               {"name", m.name},
                               {"milliseconds", m.milliseconds},
                               {"tets", m.tets},
                               {"vertices", m.vertices},
                               {"solver_iterations", m.solver_iterations},
                               {"estimated_error", error ? Json(*error) : Json(nullptr)}});
        result.steps.push_back(m);
    }
    const FrameBudget budget = session_frame_budget(session, run_options);
    const Json summary{{"load_milliseconds", result.load_ms},
                       {"input_tets", result.input_tets},
                       {"mm_per_unit", result.scale.mm_per_unit},
                       {"scale_source", scale_source_name(result.scale.source)},
                       {"undo_bytes", core.document().undo_bytes()},
                       {"undo_entries_evicted", core.document().evicted_undo_count()},
                       {"solver_backend", live_backend_name(core.live().backend())},
                       {"solver_method", live_method_name(run_options.method)},
                       // The time budget of the frames of render steps with "frames"; null: frame_iterations.
                       {"frame_ms", budget.limits_time() ? Json(budget.max_milliseconds) : Json(nullptr)},
                       {"gpu_fallback_reason", core.live().gpu_fallback_reason()},
                       {"method_fallback_reason", core.live().method_fallback_reason()},
                       {"steps", progress.steps}};
    result.mesh = core.document().mesh();
    result.solver_backend = core.live().backend();
    result.gpu_fallback_reason = core.live().gpu_fallback_reason();
    result.method_fallback_reason = core.live().method_fallback_reason();
    return summary;
}

}  // namespace

SessionScene replay_session_scene(const Session& session) {
    SessionVolume input = load_session_input(session);
    Session setup = session;
    setup.scale = input.scale.mm_per_unit;
    SessionScene out;
    out.scale = input.scale;
    out.camera = session.camera;
    out.width = session.width;
    out.height = session.height;
    SceneCore core(Document(std::move(input.mesh), session.material), setup, LiveSceneOptions{});
    for (size_t i = 0; i < session.steps.size(); ++i) {
        const SessionStep& step = session.steps[i];
        const std::string context_name = session.name + ": step " + std::to_string(i) + " (" + step_kind(step) + ")";
        try {
            if (const auto* op = std::get_if<EditOperation>(&step)) {
                core.apply(*op);
            } else if (const auto* l = std::get_if<LightStep>(&step)) {
                core.set_lighting(l->lighting);
            } else if (const auto* c = std::get_if<CameraStep>(&step)) {
                out.camera = c->camera;
            } else if (const auto* u = std::get_if<UndoStep>(&step)) {
                for (int k = 0; k < u->count; ++k)
                    if (!core.undo()) fail_json(context_name, "nothing left to undo");
            } else if (const auto* r = std::get_if<RedoStep>(&step)) {
                for (int k = 0; k < r->count; ++k)
                    if (!core.redo()) fail_json(context_name, "nothing left to redo");
            }
        } catch (const Error&) {
            rethrow_in_step(context_name);
        }
    }
    core.converge();
    out.mesh = core.document().mesh();
    out.scene = core.live().solved_scene();
    out.lighting = core.live().lighting();
    return out;
}

SessionResult run_session(const Session& session, const fs::path& output_directory, const SessionRunOptions& run_options) {
    std::error_code ec;
    fs::create_directories(output_directory, ec);
    if (ec) throw FileError(output_directory.string(), "cannot create the directory: " + ec.message());
    // Every output's whole path must fit the system's limit with a save's temporary name: checked
    // before the input is meshed, not at the step.
    for (size_t i = 0; i < session.steps.size(); ++i) {
        const std::string* name = output_file(session.steps[i]);
        const size_t length = name ? (fs::absolute(output_directory) / *name).native().size() : 0;
        if (length + (255 - kMaxSavedFileNameBytes) >= PATH_MAX)
            throw InvalidArgumentError(session.name + ": step " + std::to_string(i) + " (" + step_kind(session.steps[i]) +
                                       "): the output path is " + std::to_string(length) + " bytes long in " +
                                       output_directory.string() + "; at most " +
                                       std::to_string(PATH_MAX - 1 - (255 - kMaxSavedFileNameBytes)) + " fit");
    }
    const fs::path metrics_path = output_directory / "metrics.json";
    const auto write_metrics = [&](const Json& summary) {
        write_file_atomically(metrics_path, [&](std::ostream& out) { out << summary.dump(2) << "\n"; });
    };

    SessionResult result;
    ReplayProgress progress;
    Json summary;
    try {
        summary = replay_session(session, output_directory, run_options, result, progress);
    } catch (const Error& e) {
        // The outputs written before the failure stay (each one complete); metrics.json says which
        // they are and where the replay stopped. The step's error is the one reported: a folder that
        // cannot take metrics.json either must not hide it.
        try {
            write_metrics(Json{{"session", session.name},
                               {"status", "failed"},
                               {"failed_step", progress.step ? Json(*progress.step) : Json(nullptr)},
                               {"error", e.what()},
                               {"written", written_to_json(result.written, output_directory)},
                               {"steps", progress.steps}});
        } catch (const Error&) {
        }
        throw;
    }
    Json out{{"session", session.name}, {"status", "ok"}};
    out.update(summary);
    out["written"] = written_to_json(result.written, output_directory);
    write_metrics(out);
    return result;
}

}  // namespace waxwork
