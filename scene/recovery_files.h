// Crash recovery for the editor: while a document has unsaved edits, the editor writes its session
// and volume now and then to a folder of its own under STATE/recovery (STATE: state_directory(),
// recent_files.h), named after its process id so that editors running side by side never share one.
// A clean exit removes the folder; a folder whose process no longer runs is what a crash (or a kill)
// left behind, and the next editor offers to recover it.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace waxwork {

// The files one recovery folder holds.
struct RecoveryFiles {
    std::filesystem::path directory;
    std::filesystem::path session() const { return directory / "session.json"; }  // replays the edits
    std::filesystem::path volume() const { return directory / "volume.vtu"; }     // the edited volume itself
    std::filesystem::path source() const { return directory / "source.txt"; }     // what the document was opened from
};

// This process's folder: STATE/recovery/PID (not created here).
RecoveryFiles own_recovery_files(const std::filesystem::path& state);

// The folders under STATE/recovery that belong to processes no longer running and hold a volume,
// newest first.
std::vector<RecoveryFiles> abandoned_recovery_files(const std::filesystem::path& state);

// The file the recovered document was opened from, as written beside it ("" when unknown).
std::string recovered_source(const RecoveryFiles& files);
// Writes source.txt atomically (the volume and session are written by SceneCore's saves).
void write_recovered_source(const RecoveryFiles& files, const std::filesystem::path& source);

// Removes the folder and what it holds; errors are ignored (a folder left over is offered again).
void remove_recovery_files(const RecoveryFiles& files);

}  // namespace waxwork
