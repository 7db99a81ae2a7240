// Open and save dialogs drawn with ImGui. Hand-written because Debian packages no native file dialog
// library (nativefiledialog, portable-file-dialogs, ImGuiFileDialog are all absent) and GLFW has none;
// std::filesystem lists the directories. Files can also be dropped onto the window (glfwSetDropCallback
// in editor_app.cpp).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace waxwork {

struct DirectoryEntry {
    std::string name;
    bool is_directory = false;
};

// The entries of `directory` a dialog shows: sub-directories first, then files whose extension
// (case-insensitive, with the dot: ".obj") is in `extensions` (all files when empty), each group sorted
// by name; hidden entries (leading dot) left out. Unreadable entries are skipped; an unreadable
// directory gives an empty list.
std::vector<DirectoryEntry> list_directory(const std::filesystem::path& directory,
                                           const std::vector<std::string>& extensions);

class FileDialog {
public:
    enum class Mode { Open, Save };

    void open(Mode mode, std::string title, const std::filesystem::path& directory,
              std::vector<std::string> extensions, std::string file_name = {});
    bool is_open() const { return open_; }
    // Draws the dialog while it is open (once per frame); returns the chosen path on the frame the
    // user confirms, nullopt otherwise.
    std::optional<std::filesystem::path> draw(float scale);
    Mode mode() const { return mode_; }

private:
    void change_directory(const std::filesystem::path& directory);

    bool open_ = false;
    bool just_opened_ = false;
    Mode mode_ = Mode::Open;
    std::string title_;
    std::filesystem::path directory_;
    std::vector<std::string> extensions_;
    std::vector<DirectoryEntry> entries_;
    char file_name_[512] = {};
    char directory_text_[1024] = {};
};

}  // namespace waxwork
