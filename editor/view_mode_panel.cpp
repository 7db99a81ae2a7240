// The View panel's choice of optional view (render/view_modes.h) and its legend. A change only marks
// the view dirty: the worker builds the view's geometry (ViewGeometryCache) with the next tick, so
// the UI never waits for a hierarchy build or the slice of a large volume.
#include "editor/editor_app.h"

#include "base/error.h"
#include "render/srgb.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace waxwork {

namespace {

// Linear rgb to what ImGui draws (sRGB), so the legend matches the picture.
ImU32 legend_colour(const std::array<float, 3>& c) {
    auto encode = [](float x) { return static_cast<float>(srgb_encode(std::clamp(x, 0.0f, 1.0f))); };
    return ImGui::ColorConvertFloat4ToU32(ImVec4(encode(c[0]), encode(c[1]), encode(c[2]), 1.0f));
}

void draw_legend(const ViewLegend& legend) {
    ImGui::TextWrapped("%s", legend.title.c_str());
    if (legend.stops.size() >= 2) {
        const ImVec2 origin = ImGui::GetCursorScreenPos();
        const float width = ImGui::GetContentRegionAvail().x, height = ImGui::GetFrameHeight() * 0.7f;
        ImDrawList* draw = ImGui::GetWindowDrawList();
        const size_t segments = legend.stops.size() - 1;
        for (size_t i = 0; i < segments; ++i) {
            const float x0 = origin.x + width * static_cast<float>(i) / segments;
            const float x1 = origin.x + width * static_cast<float>(i + 1) / segments;
            const ImU32 a = legend_colour(legend.stops[i]), b = legend_colour(legend.stops[i + 1]);
            draw->AddRectFilledMultiColor(ImVec2(x0, origin.y), ImVec2(x1, origin.y + height), a, b, b, a);
        }
        ImGui::Dummy(ImVec2(width, height));
        if (legend.logarithmic) {
            ImGui::Text("%.0e", legend.low);
            ImGui::SameLine(std::max(0.0f, width - ImGui::CalcTextSize("1e+00").x));
            ImGui::Text("%.0e", legend.high);
        } else {
            ImGui::Text("%g", legend.low);
            ImGui::SameLine(std::max(0.0f, width - ImGui::CalcTextSize("40+").x));
            ImGui::Text("%g+", legend.high);
        }
        if (!legend.units.empty()) ImGui::TextDisabled("%s", legend.units.c_str());
    }
    for (const auto& [label, colour] : legend.swatches) {
        const float size = ImGui::GetFrameHeight() * 0.7f;
        const ImVec2 p = ImGui::GetCursorScreenPos();
        ImGui::GetWindowDrawList()->AddRectFilled(p, ImVec2(p.x + size, p.y + size), legend_colour(colour));
        ImGui::Dummy(ImVec2(size, size));
        ImGui::SameLine();
        ImGui::TextUnformatted(label.c_str());
    }
}

}  // namespace

void EditorApp::draw_view_mode_menu() {
    if (!ImGui::BeginMenu("Show")) return;
    for (ViewMode mode : all_view_modes()) {
        if (ImGui::MenuItem(view_mode_name(mode), nullptr, view_options_.mode == mode) && view_options_.mode != mode) {
            view_options_.mode = mode;
            view_dirty_ = true;
        }
    }
    ImGui::EndMenu();
}

void EditorApp::draw_view_mode_panel() {
    int current = 0;
    std::string items;
    const std::vector<ViewMode>& modes = all_view_modes();
    for (size_t i = 0; i < modes.size(); ++i) {
        if (modes[i] == view_options_.mode) current = static_cast<int>(i);
        items += view_mode_name(modes[i]);
        items += '\0';
    }
    if (ImGui::Combo("show", &current, items.c_str())) {
        view_options_.mode = modes[static_cast<size_t>(current)];
        view_dirty_ = true;
    }
    if (view_options_.mode == ViewMode::Quality &&
        ImGui::Checkbox("interior (cross-section)", &view_options_.quality_interior))
        view_dirty_ = true;
    if (view_options_.mode == ViewMode::Slice || (view_options_.mode == ViewMode::Quality && view_options_.quality_interior)) {
        float offset = static_cast<float>(view_options_.slice_offset);
        if (ImGui::SliderFloat("slice offset", &offset, -1.0f, 1.0f, "%.2f")) {
            view_options_.slice_offset = offset;
            view_dirty_ = true;
        }
        int axis = view_options_.slice_normal == Eigen::Vector3d(1, 0, 0)   ? 0
                   : view_options_.slice_normal == Eigen::Vector3d(0, 1, 0) ? 1
                   : view_options_.slice_normal == Eigen::Vector3d(0, 0, 1) ? 2
                                                                            : 3;
        if (ImGui::Combo("slice normal", &axis, "+x\0+y\0+z\0towards the camera\0")) {
            if (axis < 3) {
                view_options_.slice_normal = Eigen::Vector3d::Unit(axis);
            } else if (camera_) {
                view_options_.slice_normal = camera_->eye_direction().normalized();
            }
            view_dirty_ = true;
        }
    }
    // Where the surface folds (solver/shading_surface.h): each side is shaded and lit as itself, so the
    // right-hand sides change and the solve goes on warm, as after a light change.
    float crease = static_cast<float>(live_options_.crease_angle_degrees);
    if (ImGui::SliderFloat("crease angle", &crease, 0.0f, 180.0f, "%.0f deg")) {
        set_crease_angle(std::clamp(static_cast<double>(crease), 0.0, 180.0));
    }
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("Box edges and cut rims are shaded and lit as folded where neighbouring triangles turn\n"
                          "by more than this; 180 uses one averaged normal per vertex");
    if (view_options_.mode != ViewMode::Radiance) {
        if (view_geometry_ && view_geometry_->mode == view_options_.mode) {
            draw_legend(view_geometry_->legend);
        } else {
            ImGui::TextDisabled("building the view...");
        }
    }
}

}  // namespace waxwork
