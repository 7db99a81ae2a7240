// EditorApp's start screen: what the empty view shows while no document is open. The bundled
// examples (example_models.h, each opened at the scale the model's size suggests and seen from its
// front), Open..., the drag-and-drop hint and the recent files.
#include "editor/editor_app.h"

#include "editor/example_models.h"

#include <imgui.h>

#include <algorithm>

namespace waxwork {

namespace fs = std::filesystem;

void EditorApp::open_example(const std::string& name) {
    for (const ExampleModel& example : example_models(example_directory())) {
        if (example.name != name) continue;
        CameraSettings camera = options_.camera;
        camera.eye_direction = example.eye_direction;
        request_open(example.file, camera);
        return;
    }
    std::string offered;
    for (const ExampleModel& example : example_models(example_directory()))
        offered += (offered.empty() ? "" : ", ") + example.name;
    set_error("example '" + name + "': not among the bundled examples (" +
              (offered.empty() ? "none found in " + example_directory().string() : offered) + ")");
}

void EditorApp::draw_start_screen() {
    // Centred in the 3D view (framebuffer pixels to ImGui's window coordinates).
    const double s = framebuffer_scale_;
    const ImVec2 centre(static_cast<float>((view_x_ + 0.5 * view_w_) / s), static_cast<float>((view_y_ + 0.5 * view_h_) / s));
    ImGui::SetNextWindowPos(centre, ImGuiCond_Always, ImVec2(0.5f, 0.5f));
    // Inside the view, clear of the panels on either side.
    const float width = std::min(440 * ui_scale_, static_cast<float>(view_w_ / s) - 24 * ui_scale_);
    ImGui::SetNextWindowSize(ImVec2(std::max(width, 160 * ui_scale_), 0));
    ImGui::Begin("Start", nullptr,
                 ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                     ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoSavedSettings);
    ImGui::PushTextWrapPos(0.0f);
    ImGui::TextUnformatted("Waxwork");
    ImGui::TextDisabled("Carve, paint and light translucent solids.");
    ImGui::Separator();
    const std::vector<ExampleModel> examples = example_models(example_directory());
    if (!examples.empty()) {
        ImGui::TextUnformatted("Open an example");
        const float button = ImGui::GetContentRegionAvail().x * 0.3f;
        for (const ExampleModel& example : examples) {
            if (ImGui::Button(example.name.c_str(), ImVec2(button, 0))) open_example(example.name);
            ImGui::SameLine();
            ImGui::TextDisabled("%s", example.description.c_str());
        }
        ImGui::Separator();
    }
    if (ImGui::Button("Open...", ImVec2(120 * ui_scale_, 0))) open_dialog(FileDialog::Mode::Open);
    ImGui::SameLine();
    ImGui::TextDisabled("Ctrl+O");
    ImGui::TextDisabled("Or drop a file onto the window: a surface (OBJ, OFF, PLY, STL), a volume (VTU, MSH, "
                        "MESH) or a session (JSON).");
    if (!recent_.files.empty()) {
        ImGui::Separator();
        ImGui::TextUnformatted("Recent");
        for (const fs::path& file : recent_.files) {
            if (ImGui::Selectable(file.filename().string().c_str())) request_open(file);
            if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", file.string().c_str());
        }
    }
    ImGui::PopTextWrapPos();
    ImGui::End();
}

}  // namespace waxwork
