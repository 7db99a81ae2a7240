// EditorApp's document safety: the modified state and the window title, the Save / Discard / Cancel
// dialog before quitting or opening another file, the periodic recovery copy and its offer after a
// run that did not exit cleanly (scene/recovery_files.h), and the recent files
// (scene/recent_files.h).
#include "editor/editor_app.h"

#include "io/file_extension.h"
#include "io/volume_file.h"

#include <GLFW/glfw3.h>
#include <imgui.h>

#include <cstdio>
#include <system_error>

namespace waxwork {

namespace fs = std::filesystem;

void EditorApp::mark_modified() {
    modified_ = true;
    if (!unsaved_since_autosave_) unsaved_since_autosave_ = std::chrono::steady_clock::now();
}

void EditorApp::mark_saved(const fs::path& path) {
    // Jobs run in order: everything queued so far is in what this save writes.
    modified_ = false;
    unsaved_since_autosave_.reset();
    save_target_ = path;
    ++saves_;
    remember_output(path, true);
}

void EditorApp::remember_output(const fs::path& path, bool recent) {
    std::error_code error;
    const fs::path absolute = fs::absolute(path, error);
    recent_.output_folder = (error ? path : absolute).parent_path();
    if (recent) remember_file(recent_, path);
    try {
        write_recent_files(state_dir_ / "recent.json", recent_);
    } catch (const std::exception& e) {
        status_ = std::string("Could not keep the recent files: ") + e.what();
    }
}

void EditorApp::document_opened(const fs::path& path) {
    modified_ = false;  // a session's replayed edits are what it holds, not new ones
    unsaved_since_autosave_.reset();
    save_target_.clear();
    if (recovering_ && path == recovering_->volume()) {
        // The recovered edits are saved nowhere of the user's: modified, named after their source,
        // and copied to this run's own recovery folder at once before the old one goes.
        const std::string source = recovered_source(*recovering_);
        current_file_ = source.empty() ? fs::path("recovered.vtu") : fs::path(source);
        mark_modified();
        autosave();
        remove_recovery_files(*recovering_);
        recovering_.reset();
        status_ += "; recovered from the previous run";
        return;
    }
    const std::string extension = lower_extension(path);
    if (extension == ".json" || is_volume_path(path)) save_target_ = path;
    std::error_code error;
    if (fs::is_regular_file(path, error)) {
        remember_file(recent_, path);
        try {
            write_recent_files(state_dir_ / "recent.json", recent_);
        } catch (const std::exception& e) {
            status_ += std::string("; could not keep the recent files: ") + e.what();
        }
    }
}

void EditorApp::request_quit() { ask_or_do({true, {}, std::nullopt}); }

void EditorApp::request_open(const fs::path& path, std::optional<CameraSettings> camera) {
    ask_or_do({false, path, std::move(camera)});
}

void EditorApp::ask_or_do(DocumentAction action) {
    if (!modified_ || !scene_->core) return do_action(action);
    unsaved_dialog_ = std::move(action);
    open_unsaved_popup_ = true;
}

void EditorApp::do_action(const DocumentAction& action) {
    if (action.quit) {
        glfwSetWindowShouldClose(window_, GLFW_TRUE);
        return;
    }
    next_camera_ = action.camera;
    open_file(action.open);
}

void EditorApp::answer_unsaved_dialog(const std::string& button, const fs::path& file) {
    if (!unsaved_dialog_) return set_error("dialog '" + button + "': no unsaved-changes dialog is asking");
    const DocumentAction action = *unsaved_dialog_;
    unsaved_dialog_.reset();
    if (button == "cancel") {
        status_ = action.quit ? "Quit cancelled" : "Opening " + action.open.filename().string() + " cancelled";
        return;
    }
    if (button == "discard") return do_action(action);
    if (button != "save") return set_error("dialog '" + button + "': expected save, discard or cancel");
    // Carry on when the save has finished without an error (document_frame).
    saves_before_ = saves_;
    errors_before_ = errors_;
    after_save_ = action;
    const fs::path target = file.empty() ? save_target_ : file;
    if (target.empty()) {
        options_.hide_ui = false;  // the Save dialog is one of the panels
        open_dialog(FileDialog::Mode::Save, SaveKind::Session);
    }
    else if (lower_extension(target) == ".json") save_session(target);
    else save_volume(target);
}

void EditorApp::autosave() {
    if (!scene_->core) return;
    unsaved_since_autosave_.reset();
    recovery_written_ = true;
    const RecoveryFiles files = own_recovery_;
    const Session current = view_session();
    const fs::path source = current_file_.empty() ? fs::path() : fs::absolute(current_file_);
    queue_job("autosave", [files, current, source](SceneCore& core) {
        fs::create_directories(files.directory);
        // The volume first: it is what a recovery opens (the session beside it replays the edits
        // onto the source, which may have moved since).
        core.save_volume(files.volume());
        core.save_session(files.session(), with_view(core.setup(), current));
        write_recovered_source(files, source);
        return "Autosaved a recovery copy to " + files.directory.string();
    });
}

void EditorApp::remove_own_recovery() { remove_recovery_files(own_recovery_); }

void EditorApp::recover() {
    if (abandoned_.empty()) return set_error("recover: no recovery files of an earlier run are waiting");
    open_recovery_popup_ = false;
    recovering_ = abandoned_.front();
    abandoned_.erase(abandoned_.begin());
    open_file(recovering_->volume());
}

void EditorApp::discard_recovery() {
    if (abandoned_.empty()) return set_error("discard recovery: no recovery files of an earlier run are waiting");
    open_recovery_popup_ = false;
    for (const RecoveryFiles& files : abandoned_) remove_recovery_files(files);
    abandoned_.clear();
    status_ = "Discarded the recovery files of the earlier run";
}

void EditorApp::document_frame() {
    // The title names the document and marks unsaved edits.
    std::string title = "Waxwork";
    if (!current_file_.empty()) title += " - " + current_file_.filename().string();
    if (modified_) title += " *";
    if (title != shown_title_) {
        glfwSetWindowTitle(window_, title.c_str());
        shown_title_ = title;
    }
    // The dialog's Save: carry on once written; a failed save, or a Save dialog closed without
    // saving, keeps the document open.
    if (after_save_) {
        const bool saved = saves_ > saves_before_;
        if (errors_ > errors_before_ || (!saved && !file_dialog_.is_open())) {
            after_save_.reset();
        } else if (saved && pending_jobs_.empty() && !tick_task_.busy()) {
            const DocumentAction action = *after_save_;
            after_save_.reset();
            do_action(action);
        }
    }
    // Saved since the last copy: the copy is older than the save, nothing is left to recover.
    if (recovery_written_ && !modified_ && pending_jobs_.empty() && !tick_task_.busy()) {
        remove_own_recovery();
        recovery_written_ = false;
    }
    if (modified_ && unsaved_since_autosave_ && scene_->core &&
        std::chrono::steady_clock::now() - *unsaved_since_autosave_ >=
            std::chrono::duration<double>(options_.autosave_seconds))
        autosave();
}

void EditorApp::draw_open_recent_menu() {
    if (!ImGui::BeginMenu("Open Recent", !recent_.files.empty())) return;
    for (const fs::path& file : recent_.files) {
        if (ImGui::MenuItem(file.filename().string().c_str())) request_open(file);
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", file.string().c_str());
    }
    ImGui::EndMenu();
}

void EditorApp::draw_document_dialogs() {
    const ImVec2 centre(ImGui::GetIO().DisplaySize.x * 0.5f, ImGui::GetIO().DisplaySize.y * 0.5f);
    if (open_unsaved_popup_) {
        ImGui::OpenPopup("Unsaved changes");
        open_unsaved_popup_ = false;
    }
    std::string answer;
    ImGui::SetNextWindowPos(centre, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    if (ImGui::BeginPopupModal("Unsaved changes", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        const std::string name = current_file_.empty() ? "the document" : current_file_.filename().string();
        ImGui::Text("%s has edits that are not saved.", name.c_str());
        ImGui::TextDisabled("%s", save_target_.empty() ? "Save asks where to write the session."
                                                       : ("Save writes " + save_target_.string()).c_str());
        const ImVec2 size(100 * ui_scale_, 0);
        if (ImGui::Button("Save", size)) answer = "save";
        ImGui::SameLine();
        if (ImGui::Button("Discard", size)) answer = "discard";
        ImGui::SameLine();
        if (ImGui::Button("Cancel", size) || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))) answer = "cancel";
        if (!answer.empty() || !unsaved_dialog_) ImGui::CloseCurrentPopup();
        ImGui::EndPopup();
    }
    if (!answer.empty() && unsaved_dialog_) answer_unsaved_dialog(answer);

    if (open_recovery_popup_ && !abandoned_.empty()) {
        ImGui::OpenPopup("Recover unsaved work?");
        open_recovery_popup_ = false;
    }
    int choice = 0;
    ImGui::SetNextWindowPos(centre, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    if (ImGui::BeginPopupModal("Recover unsaved work?", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        if (!abandoned_.empty()) {
            const std::string source = recovered_source(abandoned_.front());
            ImGui::TextUnformatted("Waxwork did not exit cleanly last time.");
            ImGui::Text("Recover the edited volume of %s?",
                        source.empty() ? "the document" : fs::path(source).filename().string().c_str());
            ImGui::TextDisabled("%s", abandoned_.front().directory.string().c_str());
            if (ImGui::Button("Recover", ImVec2(100 * ui_scale_, 0))) choice = 1;
            ImGui::SameLine();
            if (ImGui::Button("Discard", ImVec2(100 * ui_scale_, 0))) choice = 2;
        }
        if (choice != 0 || abandoned_.empty()) ImGui::CloseCurrentPopup();
        ImGui::EndPopup();
    }
    if (choice == 1) recover();
    else if (choice == 2) discard_recovery();
}

}  // namespace waxwork
