// Containment of outputs named by a file rather than by the user: a session's "render" and "save"
// steps name files relative to the folder given with `waxwork run -o OUTDIR`, and a session from
// elsewhere must write nothing outside that folder.
//
// Names are checked as text when the session is read (output_name_problem), and their folders are
// checked on disk when the file is written (contained_output_path): a symbolic link inside OUTDIR
// may lead to another place inside it, never outside. The file itself is replaced by rename(2)
// (io/atomic_file.h), which replaces a link of that name rather than writing through it.
//
// What this does not defend against: another process that swaps a checked folder for a link between
// the check and the write (it would need write access to OUTDIR, where it could write anyway).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace waxwork {

// The longest file name a save can replace: write_file_atomically writes ".NAME.tmp-PID-N-R" beside
// its target, which must fit the file system's 255-byte limit on one name (NAME_MAX).
inline constexpr size_t kMaxSavedFileNameBytes = 255 - 32;

// What is wrong with `name` as an output name relative to an output folder, or "" when nothing is:
// empty, absolute, a ".." part, a control character (a NUL ends the name early at the system call:
// "evil.sh\0.vtu" would write evil.sh), or a part longer than kMaxSavedFileNameBytes.
std::string output_name_problem(std::string_view name);

// `folder / name` once its parent folders exist inside `folder`: each existing part is resolved
// (following links) and must lie inside `folder`; a missing part is created, never through a link.
// Throws FileError naming the offending path ("OUTDIR/link: leads outside the output folder OUTDIR
// (a symbolic link)") or a folder that cannot be made. `folder` must exist; `name` must pass
// output_name_problem.
std::filesystem::path contained_output_path(const std::filesystem::path& folder, const std::filesystem::path& name);

}  // namespace waxwork
