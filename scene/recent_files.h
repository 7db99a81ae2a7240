// What the editor remembers between runs, kept in the user's state directory: the recently opened
// or saved files (File > Open Recent and the start screen) and the folder the user last saved into
// (where Save dialogs start, rather than the input's folder, which may be the repository's
// assets/meshes).
#pragma once

#include <cstddef>
#include <filesystem>
#include <vector>

namespace waxwork {

// $WAXWORK_STATE_DIR when set (tests point it at a scratch folder), else $XDG_STATE_HOME/waxwork,
// else ~/.local/state/waxwork (the XDG Base Directory default). Not created here.
std::filesystem::path state_directory();

struct RecentFiles {
    static constexpr size_t kMaxFiles = 10;
    std::vector<std::filesystem::path> files;  // most recent first, absolute, no duplicates
    std::filesystem::path output_folder;       // where the user last saved (empty: none yet)
};

// `file` moves (or is added) to the front; the list keeps at most kMaxFiles.
void remember_file(RecentFiles& recent, const std::filesystem::path& file);

// The list in `path` (recent.json) without the files that no longer exist, and without an output
// folder that no longer exists. A missing or unreadable file gives an empty list: losing the list
// must never keep the editor from starting.
RecentFiles read_recent_files(const std::filesystem::path& path);
// Writes it atomically (io/atomic_file.h), creating the folder; FileError when that fails.
void write_recent_files(const std::filesystem::path& path, const RecentFiles& recent);

}  // namespace waxwork
