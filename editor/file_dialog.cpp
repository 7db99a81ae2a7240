#include "editor/file_dialog.h"

#include <imgui.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <system_error>

namespace waxwork {

namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

void copy_text(char* destination, size_t size, const std::string& text) {
    std::strncpy(destination, text.c_str(), size - 1);
    destination[size - 1] = '\0';
}

}  // namespace

std::vector<DirectoryEntry> list_directory(const std::filesystem::path& directory,
                                           const std::vector<std::string>& extensions) {
    std::vector<DirectoryEntry> directories, files;
    std::error_code error;
    std::filesystem::directory_iterator it(directory, std::filesystem::directory_options::skip_permission_denied, error);
    if (error) return {};
    for (; it != std::filesystem::directory_iterator(); it.increment(error)) {
        if (error) break;
        const std::string name = it->path().filename().string();
        if (name.empty() || name[0] == '.') continue;
        std::error_code type_error;
        if (it->is_directory(type_error)) {
            directories.push_back({name, true});
            continue;
        }
        if (type_error) continue;
        const std::string extension = lower(it->path().extension().string());
        if (extensions.empty() ||
            std::any_of(extensions.begin(), extensions.end(), [&](const std::string& e) { return lower(e) == extension; }))
            files.push_back({name, false});
    }
    auto by_name = [](const DirectoryEntry& a, const DirectoryEntry& b) { return a.name < b.name; };
    std::sort(directories.begin(), directories.end(), by_name);
    std::sort(files.begin(), files.end(), by_name);
    directories.insert(directories.end(), files.begin(), files.end());
    return directories;
}

void FileDialog::open(Mode mode, std::string title, const std::filesystem::path& directory,
                      std::vector<std::string> extensions, std::string file_name) {
    mode_ = mode;
    title_ = std::move(title);
    extensions_ = std::move(extensions);
    copy_text(file_name_, sizeof file_name_, file_name);
    std::error_code error;
    change_directory(std::filesystem::is_directory(directory, error) ? directory : std::filesystem::current_path(error));
    open_ = true;
    just_opened_ = true;
}

void FileDialog::change_directory(const std::filesystem::path& directory) {
    std::error_code error;
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(directory, error);
    directory_ = error ? directory : canonical;
    copy_text(directory_text_, sizeof directory_text_, directory_.string());
    entries_ = list_directory(directory_, extensions_);
}

std::optional<std::filesystem::path> FileDialog::draw(float scale) {
    if (!open_) return std::nullopt;
    const std::string id = title_ + "##file_dialog";
    if (just_opened_) {
        ImGui::OpenPopup(id.c_str());
        just_opened_ = false;
    }
    std::optional<std::filesystem::path> chosen;
    ImGui::SetNextWindowSize(ImVec2(640 * scale, 440 * scale), ImGuiCond_Appearing);
    if (!ImGui::BeginPopupModal(id.c_str(), &open_)) return std::nullopt;

    if (ImGui::Button("Up")) change_directory(directory_.parent_path());
    ImGui::SameLine();
    ImGui::SetNextItemWidth(-1);
    if (ImGui::InputText("##directory", directory_text_, sizeof directory_text_, ImGuiInputTextFlags_EnterReturnsTrue))
        change_directory(directory_text_);

    const float footer = ImGui::GetFrameHeightWithSpacing() * 2.2f;
    ImGui::BeginChild("entries", ImVec2(0, -footer), true);
    std::optional<std::filesystem::path> enter;
    for (const DirectoryEntry& entry : entries_) {
        const std::string label = (entry.is_directory ? "[dir]  " : "       ") + entry.name;
        const bool selected = !entry.is_directory && entry.name == file_name_;
        if (ImGui::Selectable(label.c_str(), selected, ImGuiSelectableFlags_AllowDoubleClick)) {
            if (entry.is_directory) {
                if (ImGui::IsMouseDoubleClicked(0)) enter = directory_ / entry.name;
            } else {
                copy_text(file_name_, sizeof file_name_, entry.name);
                if (ImGui::IsMouseDoubleClicked(0)) chosen = directory_ / entry.name;
            }
        }
    }
    if (entries_.empty()) ImGui::TextDisabled("(no matching files)");
    ImGui::EndChild();
    if (enter) change_directory(*enter);

    std::string filter;
    for (const std::string& e : extensions_) filter += (filter.empty() ? "" : " ") + e;
    ImGui::SetNextItemWidth(-150 * scale);
    const bool typed_enter =
        ImGui::InputText("##file_name", file_name_, sizeof file_name_, ImGuiInputTextFlags_EnterReturnsTrue);
    ImGui::SameLine();
    const bool confirm = ImGui::Button(mode_ == Mode::Open ? "Open" : "Save", ImVec2(65 * scale, 0));
    ImGui::SameLine();
    if (ImGui::Button("Cancel", ImVec2(65 * scale, 0))) open_ = false;
    ImGui::TextDisabled("%s", filter.empty() ? "all files" : filter.c_str());
    if ((confirm || typed_enter) && file_name_[0] != '\0') {
        const std::filesystem::path typed(file_name_);
        chosen = typed.is_absolute() ? typed : directory_ / typed;
    }
    if (chosen) {
        open_ = false;
        ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
    return chosen;
}

}  // namespace waxwork
