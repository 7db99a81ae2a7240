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
// and so does a target that is a directory (refused before the first rename). Each file is replaced
// atomically; the set as a whole is not (a crash or an I/O error between two renames can leave one
// new and one old file), which no POSIX file system can offer.
void write_files_atomically(const std::vector<FileWriter>& files);

}  // namespace waxwork
