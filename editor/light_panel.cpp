// The Lights panel of EditorApp: add and remove directional, point and area lights, pick the one the
// Light tool drags in the view, and set each light's colour and intensity separately (the solver
// takes their product per channel, solver/lighting.h); an area light's size and the way it faces too;
// choose, turn and scale the environment light.
#include "editor/editor_app.h"

#include "base/error.h"
#include "scene/environment_loading.h"

#include <imgui.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <utility>

namespace waxwork {

namespace {

// A new point light: above and in front of the view's target, outside the object.
Light new_point_light(const std::optional<OrbitCamera>& camera) {
    Light light;
    light.type = LightType::Point;
    const Eigen::Vector3d centre = camera ? camera->target() : Eigen::Vector3d::Zero();
    const double reach = camera ? 2.5 * camera->scene_radius() : 2.0;
    const Eigen::Vector3d towards = camera ? Eigen::Vector3d(camera->eye_direction() + camera->up_axis()).normalized()
                                           : Eigen::Vector3d(0, 1, 1).normalized();
    light.vector = centre + reach * towards;
    // Point intensity is radiant intensity: at the reach it lights like a unit directional light.
    light.intensity = {reach * reach, reach * reach, reach * reach};
    return light;
}

// A new area light where a new point light goes, facing the view's target, about the object's size
// (soft shadows need a source that is not small against the distance); the same intensity along its
// axis as the point light's, so it lights the object about as brightly.
Light new_area_light(const std::optional<OrbitCamera>& camera, LightType type) {
    Light light = new_point_light(camera);
    light.type = type;
    const Eigen::Vector3d centre = camera ? camera->target() : Eigen::Vector3d::Zero();
    light.axis = (centre - light.vector).normalized();
    light.tangent = default_rect_tangent(light.axis);
    const double size = camera ? camera->scene_radius() : 1.0;
    light.size = type == LightType::Rectangle ? Eigen::Vector2d(size, size) : Eigen::Vector2d(0.5 * size, 0);
    return light;
}

// The area light's shape: size (model units) and, for the one-sided shapes, the side it faces. Returns
// whether anything changed.
bool edit_area_shape(Light& light, const std::optional<OrbitCamera>& camera) {
    bool changed = false;
    constexpr float kMinSize = 1e-4f;
    if (light.type == LightType::Rectangle) {
        float size[2] = {static_cast<float>(light.size.x()), static_cast<float>(light.size.y())};
        if (ImGui::DragFloat2("width, height", size, 0.005f, kMinSize, 1e4f, "%.3f")) {
            light.size = Eigen::Vector2d(std::max(size[0], kMinSize), std::max(size[1], kMinSize));
            changed = true;
        }
    } else {
        float radius = static_cast<float>(light.size.x());
        if (ImGui::DragFloat("radius", &radius, 0.005f, kMinSize, 1e4f, "%.3f")) {
            light.size.x() = std::max(radius, kMinSize);
            changed = true;
        }
    }
    if (light.type == LightType::Sphere) return changed;
    float axis[3] = {static_cast<float>(light.axis.x()), static_cast<float>(light.axis.y()),
                     static_cast<float>(light.axis.z())};
    if (ImGui::DragFloat3("faces", axis, 0.01f)) {
        const Eigen::Vector3d next(axis[0], axis[1], axis[2]);
        if (next.allFinite() && next.norm() > 1e-6) {
            light.axis = next;
            changed = true;
        }
    }
    ImGui::SameLine();
    if (camera && ImGui::SmallButton("aim")) {
        const Eigen::Vector3d to_target = camera->target() - light.vector;
        if (to_target.norm() > 1e-9) {
            light.axis = to_target.normalized();
            changed = true;
        }
    }
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Face the view's target");
    // Only the width direction's part across the axis counts: keep one that is not along it.
    if (changed && light.type == LightType::Rectangle &&
        light.tangent.cross(light.axis).norm() < 1e-3 * light.tangent.norm() * light.axis.norm())
        light.tangent = default_rect_tangent(light.axis);
    return changed;
}

}  // namespace

void EditorApp::draw_light_panel() {
    int remove = -1;
    for (int i = 0; i < static_cast<int>(lighting_.lights.size()); ++i) {
        Light& light = lighting_.lights[i];
        ImGui::PushID(i);
        bool changed = false;
        char title[48];
        std::snprintf(title, sizeof title, "%s light %d", light_type_name(light.type), i + 1);
        title[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(title[0])));
        if (ImGui::RadioButton(title, selected_light_ == i)) selected_light_ = i;
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("The Light tool (L) drags the selected light in the view");
        ImGui::SameLine(ImGui::GetContentRegionAvail().x - 60 * ui_scale_);
        if (ImGui::SmallButton("remove")) remove = i;
        int type = light.type == LightType::Directional ? 0 : 1;
        if (is_area_light(light.type)) {
            changed |= edit_area_shape(light, camera_);
        } else if (ImGui::Combo("type", &type, "directional\0point\0")) {
            const bool to_point = type == 1;
            if (to_point != (light.type == LightType::Point)) {
                // A point light placed where the directional light comes from, outside the object.
                const double reach = camera_ ? 2.5 * camera_->scene_radius() : 2.0;
                const Eigen::Vector3d centre = camera_ ? camera_->target() : Eigen::Vector3d::Zero();
                light.type = to_point ? LightType::Point : LightType::Directional;
                light.vector = to_point ? Eigen::Vector3d(centre - reach * light.vector.normalized())
                                        : Eigen::Vector3d((centre - light.vector).normalized());
                changed = true;
            }
        }
        float v[3] = {static_cast<float>(light.vector.x()), static_cast<float>(light.vector.y()),
                      static_cast<float>(light.vector.z())};
        const char* vector_label = light.type == LightType::Directional ? "travels along"
                                   : light.type == LightType::Point     ? "position"
                                                                        : "center";
        if (ImGui::DragFloat3(vector_label, v, 0.01f)) {
            const Eigen::Vector3d next(v[0], v[1], v[2]);
            if (next.allFinite() && (has_position(light.type) || next.norm() > 1e-6)) {
                light.vector = next;
                changed = true;
            }
        }
        // Colour (brightest channel 1) times intensity: the two edited apart.
        const double strength = std::max({light.intensity[0], light.intensity[1], light.intensity[2]});
        float colour[3] = {1, 1, 1};
        if (strength > 0)
            for (int c = 0; c < 3; ++c) colour[c] = static_cast<float>(light.intensity[c] / strength);
        float intensity = static_cast<float>(strength);
        const bool colour_changed = ImGui::ColorEdit3("colour", colour, ImGuiColorEditFlags_Float);
        const bool intensity_changed = ImGui::DragFloat("intensity", &intensity, 0.01f * std::max(intensity, 0.1f), 0.0f,
                                                        1e6f, "%.3f", ImGuiSliderFlags_Logarithmic);
        if (colour_changed || intensity_changed) {
            const float peak = std::max({colour[0], colour[1], colour[2]});
            for (int c = 0; c < 3; ++c) {
                const double normalised = peak > 0 ? std::clamp(colour[c] / peak, 0.0f, 1.0f) : 1.0;
                light.intensity[c] = std::max(0.0f, intensity) * normalised;
            }
            changed = true;
        }
        if (changed) request_solve();
        ImGui::Separator();
        ImGui::PopID();
    }
    if (remove >= 0) {
        lighting_.lights.erase(lighting_.lights.begin() + remove);
        selected_light_ = std::clamp(selected_light_, 0, std::max(0, static_cast<int>(lighting_.lights.size()) - 1));
        request_solve();
    }
    const bool room = lighting_.lights.size() < static_cast<size_t>(kMaxRenderLights);
    if (!room) ImGui::BeginDisabled();
    if (ImGui::Button("Add directional")) {
        lighting_.lights.push_back(default_key_light());
        selected_light_ = static_cast<int>(lighting_.lights.size()) - 1;
        request_solve();
    }
    ImGui::SameLine();
    if (ImGui::Button("Add point")) {
        lighting_.lights.push_back(new_point_light(camera_));
        selected_light_ = static_cast<int>(lighting_.lights.size()) - 1;
        request_solve();
    }
    // Area lights: soft shadows (solver/area_light.h).
    for (const auto& [type, label] : {std::pair{LightType::Rectangle, "Add rectangle"}, std::pair{LightType::Disk, "Add disk"},
                                      std::pair{LightType::Sphere, "Add sphere"}}) {
        if (type != LightType::Rectangle) ImGui::SameLine();
        if (ImGui::Button(label)) {
            lighting_.lights.push_back(new_area_light(camera_, type));
            selected_light_ = static_cast<int>(lighting_.lights.size()) - 1;
            request_solve();
        }
    }
    if (!room) ImGui::EndDisabled();
    ImGui::TextDisabled("Light tool (L): drag in the view to turn or move the selected light");
    float ambient = static_cast<float>(lighting_.ambient[0]);
    if (ImGui::DragFloat("ambient", &ambient, 0.002f, 0.0f, 10.0f, "%.3f")) {
        lighting_.ambient = {std::max(0.0f, ambient), std::max(0.0f, ambient), std::max(0.0f, ambient)};
        request_solve();
    }
    if (ImGui::Checkbox("shadows", &lighting_.shadows)) request_solve();
    draw_environment_controls();
}

void EditorApp::draw_environment_controls() {
    ImGui::Separator();
    ImGui::TextUnformatted("Environment");
    const bool sky = lighting_.environment && lighting_.environment->sky;
    int kind = !lighting_.environment ? 0 : sky ? 1 : 2;
    bool rebuild_sky = false;
    if (ImGui::Combo("source", &kind, "none\0sky\0HDR file\0")) {
        if (kind == 0) {
            lighting_.environment.reset();
            request_solve();
        } else if (kind == 1) {
            rebuild_sky = true;
        }
    }
    if (kind == 1) {
        float elevation = static_cast<float>(environment_sky_.sun_elevation_degrees);
        float azimuth = static_cast<float>(environment_sky_.sun_azimuth_degrees);
        float turbidity = static_cast<float>(environment_sky_.turbidity);
        rebuild_sky |= ImGui::SliderFloat("sun elevation", &elevation, 1.0f, 90.0f, "%.1f deg");
        rebuild_sky |= ImGui::SliderFloat("sun azimuth", &azimuth, -180.0f, 180.0f, "%.1f deg");
        rebuild_sky |= ImGui::SliderFloat("turbidity", &turbidity, 2.0f, 10.0f, "%.1f");
        if (rebuild_sky) {
            environment_sky_ = {elevation, azimuth, turbidity};
            // A new sky keeps the rotation, intensity and background of the environment it replaces.
            EnvironmentLight next = sky_environment_light(environment_sky_);
            if (lighting_.environment) {
                next.rotation_degrees = lighting_.environment->rotation_degrees;
                next.intensity = lighting_.environment->intensity;
                next.background = lighting_.environment->background;
            } else {
                lighting_.lights.clear();  // the sun lights the scene in the key light's place
                lighting_.ambient = {0, 0, 0};
            }
            lighting_.environment = std::move(next);
            request_solve();
        }
    } else if (kind == 2) {
        ImGui::InputText("file", environment_file_.data(), environment_file_.size());
        ImGui::SameLine();
        if (ImGui::Button("Load")) {
            try {
                EnvironmentSpec spec;
                spec.file = environment_file_.data();
                EnvironmentLight next = load_environment(spec);
                if (lighting_.environment) {
                    next.rotation_degrees = lighting_.environment->rotation_degrees;
                    next.intensity = lighting_.environment->intensity;
                    next.background = lighting_.environment->background;
                }
                lighting_.environment = std::move(next);
                request_solve();
            } catch (const Error& e) {
                show_error(e.what());
            }
        }
        if (lighting_.environment && !lighting_.environment->sky)
            ImGui::TextDisabled("%s", lighting_.environment->map->name().c_str());
    }
    if (!lighting_.environment) return;
    EnvironmentLight& environment = *lighting_.environment;
    float rotation = static_cast<float>(environment.rotation_degrees);
    if (ImGui::SliderFloat("rotation", &rotation, -180.0f, 180.0f, "%.1f deg")) {
        // Relit by a dot product per vertex (environment_transfer.h): no rays are cast for a turn.
        environment.rotation_degrees = rotation;
        request_solve();
    }
    float intensity = static_cast<float>(environment.intensity);
    if (ImGui::DragFloat("strength", &intensity, 0.01f * std::max(intensity, 0.1f), 0.0f, 1e6f, "%.3f",
                         ImGuiSliderFlags_Logarithmic)) {
        environment.intensity = std::max(0.0f, intensity);
        request_solve();
    }
    // Drawing only: the light is the same either way.
    if (ImGui::Checkbox("draw as background", &environment.background)) request_solve();
}

}  // namespace waxwork
