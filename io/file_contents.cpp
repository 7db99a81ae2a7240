#include "io/file_contents.h"

#include "base/error.h"

#include <cerrno>
#include <cstring>
#include <fstream>

namespace waxwork {

std::string read_file_contents(const std::filesystem::path& path) {
    std::error_code status_error;
    const auto status = std::filesystem::status(path, status_error);
    if (std::filesystem::is_directory(status)) throw FileError(path.string(), "is a directory, not a file");
    // A pipe or a device would block the read or never end (a FIFO nobody writes, /dev/zero).
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
        throw FileError(path.string(), "not a regular file (a pipe, socket or device)");
    std::ifstream stream(path, std::ios::binary);
    if (!stream) throw FileError(path.string(), std::string("cannot open: ") + std::strerror(errno));
    stream.seekg(0, std::ios::end);
    const std::streamoff size = stream.tellg();
    if (size < 0) throw FileError(path.string(), "cannot determine the file size");
    stream.seekg(0, std::ios::beg);
    std::string contents(static_cast<size_t>(size), '\0');
    stream.read(contents.data(), size);
    if (stream.gcount() != size) throw FileError(path.string(), "cannot read the whole file");
    return contents;
}

}  // namespace waxwork
