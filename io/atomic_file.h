// Atomic saves: a file on disk is either its old content or its complete new content, never half of
// the new one, even when the writer throws, the disk fills up or the process dies mid-save.
//
// The new content goes to a temporary file in the target's directory (same file system, so the final
// rename(2) is atomic), is flushed and fsync'ed, then renamed over the target. On any failure the
// temporary file is removed and the previous target is untouched.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <utility>
#include <vector>

namespace waxwork {

// Writes the stream content produced by `write` to `path` atomically. Exceptions thrown by `write`
// propagate unchanged (after cleanup); I/O failures throw FileError naming `path`. The stream is
// binary (no newline translation) and buffered; `write` need not flush it.
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write);

using FileWriter = std::pair<std::filesystem::path, std::function<void(std::ostream&)>>;

// Several files that belong together (TetGen's .node and .ele): every temporary is written and
// synced before the first rename, so a failure while producing any of them leaves all targets intact,
// and so does a target that is a directory (refused before the first rename). The old content of each
// existing target is kept aside (a hard link, else a copy) until all are replaced: when a later rename
// fails (an immutable file, a full directory), the files already replaced are put back and the error
// names the file that failed. Each file is replaced atomically; the set as a whole survives any
// failure the process sees, but not a crash between two renames (no POSIX file system offers that),
// which can leave one new and one old file beside a hidden .NAME.bak-* copy of the old one.
//
// Both functions first remove the hidden temporaries and backups of the same targets left by
// processes that no longer run (killed during a save).
void write_files_atomically(const std::vector<FileWriter>& files);

}  // namespace waxwork
