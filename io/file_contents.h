// Whole-file reads for the parsers: every format here is parsed from memory, which is simpler and
// faster than stream extraction and lets parsers check claimed counts against the bytes present.
#pragma once

#include <filesystem>
#include <string>

namespace waxwork {

// The bytes of `path`. Throws FileError naming the file when it is missing, a directory, not a regular
// file (a pipe or device, which could block or never end), or unreadable.
std::string read_file_contents(const std::filesystem::path& path);

}  // namespace waxwork
