#include "scene/recent_files.h"

#include "io/atomic_file.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <fstream>

namespace waxwork {

namespace fs = std::filesystem;

namespace {

fs::path environment_path(const char* name) {
    const char* value = std::getenv(name);
    return value && *value ? fs::path(value) : fs::path();
}

}  // namespace

fs::path state_directory() {
    if (fs::path own = environment_path("WAXWORK_STATE_DIR"); !own.empty()) return own;
    if (fs::path xdg = environment_path("XDG_STATE_HOME"); !xdg.empty() && xdg.is_absolute()) return xdg / "waxwork";
    if (fs::path home = environment_path("HOME"); !home.empty()) return home / ".local" / "state" / "waxwork";
    return fs::temp_directory_path() / "waxwork-state";
}

void remember_file(RecentFiles& recent, const fs::path& file) {
    std::error_code error;
    fs::path absolute = fs::absolute(file, error);
    if (error) absolute = file;
    absolute = absolute.lexically_normal();
    auto& list = recent.files;
    list.erase(std::remove(list.begin(), list.end(), absolute), list.end());
    list.insert(list.begin(), absolute);
    if (list.size() > RecentFiles::kMaxFiles) list.resize(RecentFiles::kMaxFiles);
}

RecentFiles read_recent_files(const fs::path& path) {
    RecentFiles recent;
    std::ifstream in(path);
    if (!in) return recent;
    const nlohmann::json json = nlohmann::json::parse(in, nullptr, false);
    if (!json.is_object()) return recent;
    std::error_code error;
    if (const auto files = json.find("files"); files != json.end() && files->is_array()) {
        for (const auto& f : *files) {
            if (!f.is_string()) continue;
            const fs::path file = f.get<std::string>();
            if (file.is_absolute() && fs::is_regular_file(file, error) &&
                std::find(recent.files.begin(), recent.files.end(), file) == recent.files.end())
                recent.files.push_back(file);
            if (recent.files.size() == RecentFiles::kMaxFiles) break;
        }
    }
    if (const auto folder = json.find("output_folder"); folder != json.end() && folder->is_string()) {
        const fs::path directory = folder->get<std::string>();
        if (fs::is_directory(directory, error)) recent.output_folder = directory;
    }
    return recent;
}

void write_recent_files(const fs::path& path, const RecentFiles& recent) {
    nlohmann::json json;
    json["files"] = nlohmann::json::array();
    for (const fs::path& f : recent.files) json["files"].push_back(f.string());
    json["output_folder"] = recent.output_folder.string();
    std::error_code error;
    fs::create_directories(path.parent_path(), error);
    write_file_atomically(path, [&json](std::ostream& out) { out << json.dump(2) << "\n"; });
}

}  // namespace waxwork
