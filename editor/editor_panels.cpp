// The ImGui side of EditorApp: theme, menus, tool palette, material, light, solver and view panels,
// status bar, progress, overlays and dialogs. Everything here runs on the UI thread between
// ImGui::NewFrame and ImGui::Render and only reads or edits EditorApp's state.
#include "editor/editor_app.h"

#include "editor/material_swatch.h"
#include "render/turntable.h"
#include "solver/material.h"
#include "solver/mesh_resolution.h"
#include "tetops/model_scale.h"

#include <GLFW/glfw3.h>
#include <imgui.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

namespace waxwork {

namespace fs = std::filesystem;

namespace {

constexpr const char* kDejaVuSans = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

const std::vector<std::string>& openable_extensions() {
    static const std::vector<std::string> e = {".obj", ".off", ".ply", ".stl", ".vtu", ".msh", ".mesh", ".node", ".json"};
    return e;
}

ImVec4 swatch(const TetMaterial& m) {
    const auto c = swatch_colour(m);
    return ImVec4(c[0], c[1], c[2], 1.0f);
}

}  // namespace

void EditorApp::apply_theme(float scale) {
    ImGui::StyleColorsDark();
    ImGuiStyle& style = ImGui::GetStyle();
    style.WindowRounding = 4;
    style.FrameRounding = 3;
    style.GrabRounding = 3;
    style.WindowBorderSize = 0;
    style.FramePadding = ImVec2(6, 4);
    style.ItemSpacing = ImVec2(8, 6);
    ImVec4* c = style.Colors;
    c[ImGuiCol_WindowBg] = ImVec4(0.11f, 0.11f, 0.13f, 0.97f);
    c[ImGuiCol_MenuBarBg] = ImVec4(0.14f, 0.14f, 0.16f, 1.0f);
    c[ImGuiCol_Header] = ImVec4(0.72f, 0.55f, 0.30f, 0.35f);  // warm wax accent
    c[ImGuiCol_HeaderHovered] = ImVec4(0.72f, 0.55f, 0.30f, 0.55f);
    c[ImGuiCol_HeaderActive] = ImVec4(0.72f, 0.55f, 0.30f, 0.75f);
    c[ImGuiCol_Button] = ImVec4(0.24f, 0.24f, 0.28f, 1.0f);
    c[ImGuiCol_ButtonHovered] = ImVec4(0.72f, 0.55f, 0.30f, 0.60f);
    c[ImGuiCol_ButtonActive] = ImVec4(0.72f, 0.55f, 0.30f, 0.85f);
    c[ImGuiCol_FrameBg] = ImVec4(0.20f, 0.20f, 0.23f, 1.0f);
    c[ImGuiCol_SliderGrab] = ImVec4(0.85f, 0.66f, 0.38f, 1.0f);
    c[ImGuiCol_CheckMark] = ImVec4(0.92f, 0.74f, 0.45f, 1.0f);
    c[ImGuiCol_PlotHistogram] = ImVec4(0.85f, 0.66f, 0.38f, 1.0f);
    style.ScaleAllSizes(scale);

    // DejaVu Sans (fonts-dejavu-core, present on nearly every Debian desktop) scaled for HiDPI: the
    // built-in bitmap font turns blurry when scaled. Fall back to it when DejaVu is missing.
    ImGuiIO& io = ImGui::GetIO();
    std::error_code error;
    if (std::filesystem::exists(kDejaVuSans, error)) io.Fonts->AddFontFromFileTTF(kDejaVuSans, 15.0f * scale);
    else io.FontGlobalScale = scale;
}

void EditorApp::open_dialog(FileDialog::Mode mode, SaveKind kind) {
    // Saving starts in the folder the user last saved into, else the working directory: not the
    // input's folder, which may be the repository's assets/meshes.
    const fs::path directory = mode == FileDialog::Mode::Save ? (recent_.output_folder.empty() ? fs::current_path() : recent_.output_folder)
                               : current_file_.empty() ? fs::current_path()
                                                       : current_file_.parent_path();
    saving_ = kind;
    const std::string stem = current_file_.empty() ? "" : current_file_.stem().string();
    if (mode == FileDialog::Mode::Open) {
        file_dialog_.open(mode, "Open", directory, openable_extensions());
    } else if (kind == SaveKind::Session) {
        file_dialog_.open(mode, "Save session", directory, {".json"}, "session.json");
    } else if (kind == SaveKind::Surface) {
        file_dialog_.open(mode, "Export surface", directory, {".ply", ".obj", ".stl"},
                          (stem.empty() ? "surface" : stem) + ".ply");
    } else if (kind == SaveKind::Turntable) {
        file_dialog_.open(mode, "Export turntable (frames go to a folder of the same name)", directory, {".mp4"},
                          (stem.empty() ? "turntable" : stem) + "_turntable.mp4");
    } else if (kind == SaveKind::Image) {
        file_dialog_.open(mode, "Save image", directory, {".png", ".jpg", ".jpeg"}, (stem.empty() ? "view" : stem) + ".png");
    } else if (kind == SaveKind::Reference) {
        file_dialog_.open(mode, "Save reference comparison", directory, {".png"},
                          (stem.empty() ? "reference" : stem) + "_reference.png");
    } else {
        file_dialog_.open(mode, "Save volume", directory, {".vtu", ".msh", ".mesh", ".node"},
                          (stem.empty() ? "volume" : stem) + ".vtu");
    }
}

void EditorApp::file_dialog_result() {
    if (options_.hide_ui) return;
    if (const auto chosen = file_dialog_.draw(ui_scale_)) {
        if (file_dialog_.mode() == FileDialog::Mode::Open) request_open(*chosen);
        else if (saving_ == SaveKind::Session) save_session(*chosen);
        else if (saving_ == SaveKind::Surface) export_surface(*chosen);
        else if (saving_ == SaveKind::Reference) save_reference(*chosen);
        else if (saving_ == SaveKind::Image) save_image(*chosen);
        else if (saving_ == SaveKind::Turntable) export_turntable(*chosen, kDefaultTurntableFrames);
        else save_volume(*chosen);
    }
}

void EditorApp::draw_ui() {
    draw_menu_bar();
    draw_tool_palette();
    draw_side_panel();
    draw_status_bar();
    if (start_screen_shown()) draw_start_screen();
    // The Reference window opens over the lower part of the view, clear of the tool palette.
    const float reference_x = (kToolPaletteWidth + 12) * ui_scale_;
    const float reference_y = ImGui::GetIO().DisplaySize.y - (360 + 48) * ui_scale_;
    switch (reference_->draw(scene_->light_version, ui_scale_, reference_x, std::max(reference_y, 40.0f))) {
    case ReferenceView::Request::Render: render_reference(); break;
    case ReferenceView::Request::Save: open_dialog(FileDialog::Mode::Save, SaveKind::Reference); break;
    case ReferenceView::Request::None: break;
    }
    if (show_error_popup_) {
        ImGui::OpenPopup("Error");
        show_error_popup_ = false;
    }
    std::string chosen_repair;
    if (ImGui::BeginPopupModal("Error", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        ImGui::PushTextWrapPos(ImGui::GetFontSize() * 36);
        ImGui::TextUnformatted(error_message_.c_str());
        ImGui::PopTextWrapPos();
        // A refused surface: the repairs that apply, each reopening it (with progress and Cancel).
        if (refusal_) {
            ImGui::Separator();
            ImGui::TextUnformatted("Repair the surface and open it again:");
            for (const RepairChoice& choice : refusal_->choices) {
                if (ImGui::Button(choice.label.c_str())) chosen_repair = choice.id;
                ImGui::SameLine();
            }
            ImGui::NewLine();
        }
        if (ImGui::Button(refusal_ ? "Close" : "OK", ImVec2(100 * ui_scale_, 0))) {
            refusal_.reset();
            ImGui::CloseCurrentPopup();
        }
        if (close_error_popup_ || !chosen_repair.empty()) ImGui::CloseCurrentPopup();
        ImGui::EndPopup();
    }
    close_error_popup_ = false;
    if (!chosen_repair.empty()) choose_repair(chosen_repair);  // may show a new error: after EndPopup
}

void EditorApp::draw_menu_bar() {
    if (!ImGui::BeginMainMenuBar()) return;
    if (ImGui::BeginMenu("File")) {
        if (ImGui::MenuItem("Open...", "Ctrl+O")) open_dialog(FileDialog::Mode::Open);
        draw_open_recent_menu();
        if (ImGui::MenuItem("Save volume...", "Ctrl+S", false, scene_->core != nullptr)) open_dialog(FileDialog::Mode::Save);
        if (ImGui::MenuItem("Save session...", nullptr, false, scene_->core != nullptr)) open_dialog(FileDialog::Mode::Save, SaveKind::Session);
        if (ImGui::MenuItem("Snapshot", nullptr, false, scene_->core != nullptr)) snapshot();
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("Record this view at this point of the edits: saved sessions render it when replayed");
        if (ImGui::MenuItem("Export surface...", nullptr, false, scene_->core != nullptr))
            open_dialog(FileDialog::Mode::Save, SaveKind::Surface);
        if (ImGui::MenuItem("Save image...", nullptr, false, scene_->render_input.has_value()))
            open_dialog(FileDialog::Mode::Save, SaveKind::Image);
        if (ImGui::MenuItem("Export turntable...", nullptr, false, scene_->render_input.has_value() && !turntable_))
            open_dialog(FileDialog::Mode::Save, SaveKind::Turntable);
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("%d frames of the view circling the model, at its exposure; an MP4 when ffmpeg is installed",
                              kDefaultTurntableFrames);
        ImGui::Separator();
        if (ImGui::MenuItem("Quit", "Ctrl+Q")) request_quit();
        ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("Edit")) {
        if (ImGui::MenuItem("Undo", "Ctrl+Z", false, can_undo())) undo();
        if (ImGui::MenuItem("Redo", "Ctrl+Shift+Z", false, can_redo())) redo();
        ImGui::Separator();
        // Specks a cut of a concave shape leaves floating (tetops/fragments.h); the size is the user's.
        if (ImGui::MenuItem("Remove fragments", "D", false, scene_->core != nullptr)) remove_fragments();
        ImGui::SetNextItemWidth(ImGui::GetFontSize() * 8);
        ImGui::SliderFloat("% of the volume", &fragment_percent_, 0.01f, 10.0f, "under %.3g",
                           ImGuiSliderFlags_Logarithmic | ImGuiSliderFlags_AlwaysClamp);
        ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("Tools")) {
        for (const ToolInfo& info : tool_infos()) {
            if (ImGui::MenuItem(info.name, info.shortcut, tools_.tool() == info.tool)) select_tool(info.tool);
        }
        ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("View")) {
        if (ImGui::MenuItem("Reset camera", "Home")) camera_.reset();
        if (ImGui::MenuItem("Hide panels", "Tab", options_.hide_ui)) options_.hide_ui = !options_.hide_ui;
        draw_view_mode_menu();
        ImGui::Separator();
        if (ImGui::MenuItem("Render reference", nullptr, false, scene_->core && !reference_->busy())) render_reference();
        ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("Help")) {
        for (const std::string& line : control_lines()) ImGui::TextUnformatted(line.c_str());
        ImGui::TextUnformatted("Drop a mesh or volume file onto the window to open it.");
        ImGui::EndMenu();
    }
    ImGui::EndMainMenuBar();
}

void EditorApp::draw_tool_palette() {
    const float top = ImGui::GetFrameHeight();
    const ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(0, top));
    ImGui::SetNextWindowSize(ImVec2(kToolPaletteWidth * ui_scale_, io.DisplaySize.y - top - ImGui::GetFrameHeight() * 1.2f));
    ImGui::Begin("Tools", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
    const float width = ImGui::GetContentRegionAvail().x;
    for (const ToolInfo& info : tool_infos()) {
        const bool active = tools_.tool() == info.tool;
        if (active) ImGui::PushStyleColor(ImGuiCol_Button, ImGui::GetStyle().Colors[ImGuiCol_ButtonActive]);
        char label[64];
        std::snprintf(label, sizeof label, "%s", info.name);
        if (ImGui::Button(label, ImVec2(width, 0))) select_tool(info.tool);
        if (active) ImGui::PopStyleColor();
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s (%s)\n%s", info.name, info.shortcut, tool_hint(info.tool));
    }
    ImGui::Separator();
    ImGui::TextDisabled("pieces");
    ImGui::SetNextItemWidth(width);
    ImGui::SliderInt("##pieces", &fracture_pieces_, 2, 12);
    ImGui::End();
}

void EditorApp::draw_side_panel() {
    const float top = ImGui::GetFrameHeight();
    const ImGuiIO& io = ImGui::GetIO();
    const float width = kSidePanelWidth * ui_scale_;
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - width, top));
    ImGui::SetNextWindowSize(ImVec2(width, io.DisplaySize.y - top - ImGui::GetFrameHeight() * 1.2f));
    ImGui::Begin("Scene", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
    if (ImGui::CollapsingHeader("Material", ImGuiTreeNodeFlags_DefaultOpen)) draw_material_panel();
    if (open_brush_panel_) ImGui::SetNextItemOpen(true);
    open_brush_panel_ = false;
    if (ImGui::CollapsingHeader("Brush")) draw_brush_panel();
    if (ImGui::CollapsingHeader("Deform")) draw_deform_panel();
    if (ImGui::CollapsingHeader("Lights", ImGuiTreeNodeFlags_DefaultOpen)) draw_light_panel();
    if (ImGui::CollapsingHeader("Solver", ImGuiTreeNodeFlags_DefaultOpen)) draw_solver_panel();
    if (ImGui::CollapsingHeader("View")) draw_view_panel();
    ImGui::End();
}

namespace {

// A preset list (click to take a preset) above the coefficients it filled in, which stay editable:
// the Material and the Brush panels each have one, for their own material.
void material_editor(const char* id, int& preset, TetMaterial& m) {
    const std::vector<std::string> names = material_preset_names();
    preset = std::clamp(preset, 0, static_cast<int>(names.size()) - 1);
    ImGui::PushID(id);
    const float swatch_size = ImGui::GetFrameHeight();
    ImGui::BeginChild("presets", ImVec2(0, 5.3f * ImGui::GetFrameHeightWithSpacing()), true);
    for (int i = 0; i < static_cast<int>(names.size()); ++i) {
        const TetMaterial p = material_preset(names[i]);
        ImGui::PushID(i);
        ImGui::ColorButton("##swatch", swatch(p), ImGuiColorEditFlags_NoTooltip, ImVec2(swatch_size, swatch_size * 0.8f));
        ImGui::SameLine();
        if (ImGui::Selectable(names[i].c_str(), preset == i)) {
            preset = i;
            m = p;
        }
        if (ImGui::IsItemHovered()) {
            ImGui::SetTooltip("mu_a  %.4f %.4f %.4f /mm\nmu_s' %.2f %.2f %.2f /mm\neta %.2f", p.mua[0], p.mua[1], p.mua[2],
                              p.musp[0], p.musp[1], p.musp[2], p.eta);
        }
        ImGui::PopID();
    }
    ImGui::EndChild();
    float mua[3] = {static_cast<float>(m.mua[0]), static_cast<float>(m.mua[1]), static_cast<float>(m.mua[2])};
    float musp[3] = {static_cast<float>(m.musp[0]), static_cast<float>(m.musp[1]), static_cast<float>(m.musp[2])};
    float eta = static_cast<float>(m.eta);
    bool changed = ImGui::DragFloat3("mu_a /mm", mua, 0.0005f, 0.0f, 100.0f, "%.4f");
    changed |= ImGui::DragFloat3("mu_s' /mm", musp, 0.01f, 0.001f, 1000.0f, "%.3f");
    changed |= ImGui::DragFloat("eta", &eta, 0.005f, 1.0f, 3.0f, "%.3f");
    if (changed) {
        for (int c = 0; c < 3; ++c) {
            m.mua[c] = std::max(0.0f, mua[c]);
            m.musp[c] = std::max(0.001f, musp[c]);
        }
        m.eta = std::clamp(static_cast<double>(eta), 1.0, 3.0);
    }
    ImGui::ColorButton("##custom", swatch(m), ImGuiColorEditFlags_NoTooltip, ImVec2(swatch_size * 2, swatch_size));
    ImGui::PopID();
}

}  // namespace

void EditorApp::draw_material_panel() {
    const std::vector<std::string> names = material_preset_names();
    ImGui::TextDisabled("Jensen et al. 2001, per mm; swatch: diffuse reflectance");
    if (!custom_material_) custom_material_ = material_preset(names[std::clamp(selected_preset_, 0, static_cast<int>(names.size()) - 1)]);
    TetMaterial& m = *custom_material_;
    material_editor("object", selected_preset_, m);
    ImGui::SameLine();
    const bool has_scene = scene_->core != nullptr;
    if (ImGui::Button("Apply to the whole object") && has_scene) set_whole_material(m, names[selected_preset_]);
    ImGui::TextDisabled("Object: %s", scene_->material_name.c_str());
}

void EditorApp::draw_brush_panel() {
    ImGui::TextDisabled("Paint (P) brushes this material into the volume");
    material_editor("brush", brush_preset_, brush_material_);
    ImGui::SameLine();
    ImGui::TextUnformatted(material_preset_names()[brush_preset_].c_str());
    ImGui::SliderFloat("brush radius", &brush_radius_, 0.005f, 0.3f, "%.3f x size");
    ImGui::TextDisabled("Rings on the surface: half strength, a tenth");
}

void EditorApp::draw_deform_panel() {
    ImGui::TextDisabled("As rigid as possible (Sorkine and Alexa 2007)");
    ImGui::TextDisabled("G grab, B bend, T twist about the pins, N pin");
    ImGui::SliderFloat("handle radius", &deform_radius_, 0.02f, 1.0f, "%.2f x size");
    ImGui::SliderInt("iterations per frame", &deform_preview_iterations_, 1, 8);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("ARAP iterations while dragging; the release commits %d steps of %d from the rest shape",
                          ViewportTools::kCommitSteps, ViewportTools::kCommitIterations);
    ImGui::Text("%zu pins", pins_.size());
    ImGui::SameLine();
    if (ImGui::SmallButton("clear pins")) pins_.clear();
}

void EditorApp::draw_solver_panel() {
    ImGui::TextDisabled("TransCut matrix, warm-started CG per frame");
    draw_solver_choice();
    draw_frame_budget_choice();  // frame_budget_choice.cpp: iterations or ms per frame
    float tolerance_exponent = static_cast<float>(std::log10(live_options_.relative_tolerance));
    // Solver settings rebuild the live scene: only when the user lets go of the slider.
    if (ImGui::SliderFloat("tolerance", &tolerance_exponent, -6.0f, -1.0f, "1e%.1f"))
        live_options_.relative_tolerance = std::pow(10.0, tolerance_exponent);
    if (ImGui::IsItemDeactivatedAfterEdit()) rebuild_live_scene();
    float scale = static_cast<float>(live_options_.mm_per_unit);
    if (ImGui::DragFloat("mm per unit", &scale, 0.1f, 0.01f, 10000.0f, "%.2f", ImGuiSliderFlags_Logarithmic))
        live_options_.mm_per_unit = std::clamp(static_cast<double>(scale), 1e-3, 1e6);
    if (ImGui::IsItemDeactivatedAfterEdit()) rebuild_live_scene();
    draw_scale_fit();
    ImGui::SliderFloat("exposure", &exposure_stops_, -4.0f, 4.0f, "%+.1f stops");
    ImGui::SameLine();
    if (ImGui::SmallButton("auto")) {
        exposure_stops_ = 0;
        scene_->exposure_locked = false;
        request_solve();
    }

    const Scene& s = *scene_;
    if (s.core) {
        const FrameReport& f = s.last_frame;
        ImGui::Text("%s", s.converged ? "converged" : "refining...");
        if (s.solver_description.find("V-cycle") != std::string::npos)  // multigrid CG: rgb in one pass
            ImGui::Text("V-cycles     %d (last frame, three channels each)", f.iterations[0]);
        else
            ImGui::Text("iterations   %d %d %d (last frame)", f.iterations[0], f.iterations[1], f.iterations[2]);
        if (s.estimated_error)
            ImGui::Text("est. error   %.1e (tolerance %.0e)", *s.estimated_error, live_options_.relative_tolerance);
        ImGui::Text("solver tick  %.1f ms", s.tick_ms);
        ImGui::Text("%zu tets, %zu vertices, min dihedral %.1f deg", s.tets, s.vertices, s.min_dihedral_deg);
        if (!s.trust_warning.empty()) {
            ImGui::PushTextWrapPos(0.0f);
            ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "%s", s.trust_warning.c_str());
            ImGui::PopTextWrapPos();
        }
        ImGui::Text("%zu edits in the history", s.history_size);
    }
    const ImGuiIO& io = ImGui::GetIO();
    ImGui::Text("frame %.1f ms (%.0f fps), 3D view %.1f ms", 1000.0f / std::max(io.Framerate, 1e-3f), io.Framerate,
                last_render_ms_);
}

// The object's size at the scale, and what the scale asks of the mesh: the rule's surface edge
// (solver/mesh_resolution.h) against the mesh's. A scale changed after meshing can leave the mesh too
// coarse for the diffusion length (blotchy light) or far finer than it needs (slow); a mesh made from a
// surface can be made again at the new scale.
void EditorApp::draw_scale_fit() {
    const Scene& s = *scene_;
    if (!s.core || !(s.extent.norm() > 0) || !(s.surface_edge > 0)) return;
    const double mm = live_options_.mm_per_unit;
    ImGui::TextDisabled("object %s", size_in_mm(s.extent, mm).c_str());
    const double wanted = default_surface_edge(s.extent.norm(), s.setup_material, mm);
    const double ratio = s.surface_edge / wanted;
    if (ratio >= 1.0 / kResolutionTolerance && ratio <= kResolutionTolerance) return;
    if (ratio > kResolutionTolerance)
        ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "mesh %.1fx coarser than the light needs at this scale",
                           ratio);
    else
        ImGui::TextDisabled("mesh %.1fx finer than the light needs at this scale (slower)", 1.0 / ratio);
    if (s.source_surface.empty()) return;
    if (ImGui::SmallButton("Remesh at this scale")) open_file(s.source_surface, mm, s.source_repair);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("Meshes %s again for %.3g mm per unit (edits are not kept)",
                          s.source_surface.filename().string().c_str(), mm);
}

void EditorApp::draw_view_panel() {
    draw_view_mode_panel();
    int msaa = msaa_samples_ >= 4 ? 2 : msaa_samples_ >= 2 ? 1 : 0;
    if (ImGui::Combo("antialiasing", &msaa, "off\0" "2x MSAA\0" "4x MSAA\0")) msaa_samples_ = msaa == 2 ? 4 : msaa == 1 ? 2 : 1;
    ImGui::Checkbox("show light gizmos", &show_light_gizmos_);
    if (ImGui::Checkbox("ground plane", &ground_plane_)) view_cache_->invalidate();
    // Behind the model (also in saved images and turntables): what render --background takes, but
    // transparency, which a window cannot show.
    int kind = background_.kind == BackgroundKind::Colour ? 1 : background_.kind == BackgroundKind::Environment ? 2 : 0;
    if (ImGui::Combo("background", &kind, "automatic\0" "colour\0" "environment\0")) {
        background_.kind = kind == 1 ? BackgroundKind::Colour : kind == 2 ? BackgroundKind::Environment : BackgroundKind::Automatic;
        view_cache_->invalidate();
    }
    if (background_.kind == BackgroundKind::Colour) {
        float colour[3] = {background_.colour[0] / 255.0f, background_.colour[1] / 255.0f, background_.colour[2] / 255.0f};
        if (ImGui::ColorEdit3("background colour", colour)) {
            for (int c = 0; c < 3; ++c) background_.colour[c] = static_cast<uint8_t>(std::lround(std::clamp(colour[c], 0.0f, 1.0f) * 255));
            view_cache_->invalidate();
        }
    }
    if (ImGui::Button("Reset camera (Home)")) camera_.reset();
    if (camera_) {
        const Eigen::Vector3d d = camera_->eye_direction();
        ImGui::TextDisabled("view direction %.2f %.2f %.2f", d.x(), d.y(), d.z());
    }
}

void EditorApp::draw_status_bar() {
    const ImGuiIO& io = ImGui::GetIO();
    const float height = ImGui::GetFrameHeight() * 1.2f;
    ImGui::SetNextWindowPos(ImVec2(0, io.DisplaySize.y - height));
    ImGui::SetNextWindowSize(ImVec2(io.DisplaySize.x, height));
    ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(8 * ui_scale_, 3 * ui_scale_));
    ImGui::Begin("##status", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings);
    // Progress of anything that has run longer than 200 ms; the UI keeps drawing meanwhile.
    const BackgroundTask* task = load_task_.busy() ? &load_task_ : tick_task_.busy() ? &tick_task_ : nullptr;
    if (task && task->elapsed_seconds() > 0.2) {
        const float fraction = task->progress()->fraction();
        char overlay[160];
        std::snprintf(overlay, sizeof overlay, "%s: %s (%.1f s)", task->label().c_str(), task->progress()->stage().c_str(),
                      task->elapsed_seconds());
        // Unknown fraction: a bar sweeping back and forth.
        const float shown = fraction >= 0 ? fraction : 0.5f + 0.5f * std::sin(static_cast<float>(ImGui::GetTime()) * 3.0f);
        ImGui::ProgressBar(shown, ImVec2(300 * ui_scale_, 0), overlay);
        ImGui::SameLine();
        // Loading can stop between any two stages (and CGAL's mesher within its refinement); a tick
        // holds queued edits, so it always runs to its end.
        if (task == &load_task_) {
            ImGui::BeginDisabled(load_task_.cancel_requested());
            if (ImGui::SmallButton("Cancel")) cancel_loading();
            ImGui::EndDisabled();
            ImGui::SameLine();
        }
    }
    ImGui::TextUnformatted(status_.c_str());
    ImGui::End();
    ImGui::PopStyleVar();
}

void EditorApp::draw_overlays() {
    ImDrawList* draw = ImGui::GetBackgroundDrawList();
    const double s = framebuffer_scale_;
    auto to_screen = [&](float x, float y) {
        return ImVec2(static_cast<float>((x + view_x_) / s), static_cast<float>((y + view_y_) / s));
    };
    draw_tool_overlay();  // the stroke being drawn and the side a cut takes away
    // On the view itself, so that whoever judges the image sees it; the Solver panel says why.
    if (!scene_->trust_warning.empty() && !options_.hide_ui)
        draw->AddText(to_screen(8.0f, static_cast<float>(view_h_) - 24.0f * static_cast<float>(ui_scale_)),
                      IM_COL32(255, 205, 80, 255), "diffusion may be off here: low-albedo material (Solver panel)");
    if (!camera_ || !show_light_gizmos_) return;
    // Light gizmos: point and area lights as suns at their position (centre), directional ones as an
    // arrow towards the target from where the light comes.
    for (int i = 0; i < static_cast<int>(lighting_.lights.size()); ++i) {
        const Light& light = lighting_.lights[i];
        const ImU32 colour = i == selected_light_ ? IM_COL32(255, 220, 120, 255) : IM_COL32(200, 200, 200, 180);
        const Eigen::Vector3d from = has_position(light.type)
                                         ? light.vector
                                         : Eigen::Vector3d(camera_->target() - 1.3 * camera_->scene_radius() * light.vector.normalized());
        const Eigen::Vector3d p = camera_->project(from, view_w_, view_h_);
        if (!(p.z() > 0 && p.z() < 1)) continue;
        const ImVec2 at = to_screen(static_cast<float>(p.x()), static_cast<float>(p.y()));
        draw->AddCircleFilled(at, 6.0f * ui_scale_, colour);
        if (light.type == LightType::Directional) {
            const Eigen::Vector3d q = camera_->project(
                Eigen::Vector3d(camera_->target() - 0.9 * camera_->scene_radius() * light.vector.normalized()), view_w_, view_h_);
            draw->AddLine(at, to_screen(static_cast<float>(q.x()), static_cast<float>(q.y())), colour, 2.0f * ui_scale_);
        }
    }
    const char* hint = tool_hint(tools_.tool());
    draw->AddText(to_screen(10, 8), IM_COL32(220, 220, 220, 200), hint);
}

}  // namespace waxwork
