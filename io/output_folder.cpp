#include "io/output_folder.h"

#include "base/error.h"

#include <algorithm>

namespace waxwork {
namespace {

namespace fs = std::filesystem;

// `path` lies in `root` or is `root` (both canonical).
bool lies_inside(const fs::path& path, const fs::path& root) {
    const fs::path relative = path.lexically_relative(root);
    return !relative.empty() && *relative.begin() != "..";
}

std::string quoted_for_message(std::string_view name) {
    std::string out;
    for (const char c : name) {
        const auto byte = static_cast<unsigned char>(c);
        if (byte < 0x20 || byte == 0x7f) {
            static const char* const kHex = "0123456789abcdef";
            out += "\\x";
            out += kHex[byte >> 4];
            out += kHex[byte & 15];
        } else {
            out += c;
        }
    }
    return "'" + out + "'";
}

}  // namespace

std::string output_name_problem(std::string_view name) {
    if (name.empty()) return "an output name must not be empty";
    const std::string shown = quoted_for_message(name);
    if (std::any_of(name.begin(), name.end(), [](char c) {
            const auto byte = static_cast<unsigned char>(c);
            return byte < 0x20 || byte == 0x7f;
        }))
        return shown + " contains a control character";
    const fs::path path{std::string(name)};
    for (const fs::path& part : path) {
        if (part == "..") return shown + " must stay inside the output directory (a relative path without '..')";
        if (part.string().size() > kMaxSavedFileNameBytes)
            return shown + " has a part of " + std::to_string(part.string().size()) + " bytes; at most " +
                   std::to_string(kMaxSavedFileNameBytes) + " fit a file name";
    }
    if (path.is_absolute()) return shown + " must stay inside the output directory (a relative path without '..')";
    if (!path.has_filename()) return shown + " names a folder, not a file";
    return "";
}

fs::path contained_output_path(const fs::path& folder, const fs::path& name) {
    std::error_code ec;
    const fs::path root = fs::canonical(folder, ec);
    if (ec) throw FileError(folder.string(), "cannot resolve the output folder: " + ec.message());
    fs::path current = folder;
    for (const fs::path& part : name.parent_path()) {
        if (part == "." || part.empty()) continue;
        current /= part;
        const fs::file_status status = fs::symlink_status(current, ec);
        if (ec && ec != std::errc::no_such_file_or_directory)
            throw FileError(current.string(), "cannot inspect: " + ec.message());
        if (!fs::exists(status)) {
            if (!fs::create_directory(current, ec) && ec)
                throw FileError(current.string(), "cannot create the directory: " + ec.message());
            continue;
        }
        const fs::path resolved = fs::canonical(current, ec);
        if (ec) throw FileError(current.string(), "cannot resolve: " + ec.message());
        if (!lies_inside(resolved, root))
            throw FileError(current.string(), "leads outside the output folder " + folder.string() +
                                                  (fs::is_symlink(status) ? " (a symbolic link)" : ""));
        if (!fs::is_directory(resolved, ec))
            throw FileError(current.string(), "cannot create the directory: a file of that name exists");
    }
    return folder / name;
}

}  // namespace waxwork
