#include "scene/recovery_files.h"

#include "io/atomic_file.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <fstream>
#include <iterator>

namespace waxwork {

namespace fs = std::filesystem;

namespace {

// kill(pid, 0) probes without signalling: ESRCH means no such process. EPERM means one runs under
// another user, which is not ours to recover.
bool process_running(long pid) { return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM); }

}  // namespace

RecoveryFiles own_recovery_files(const fs::path& state) {
    return {state / "recovery" / std::to_string(static_cast<long>(::getpid()))};
}

std::vector<RecoveryFiles> abandoned_recovery_files(const fs::path& state) {
    std::vector<std::pair<fs::file_time_type, RecoveryFiles>> found;
    std::error_code error;
    for (fs::directory_iterator it(state / "recovery", error), end; !error && it != end; it.increment(error)) {
        const std::string name = it->path().filename().string();
        if (name.empty() || !std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; }) ||
            name.size() > 9)
            continue;
        const RecoveryFiles files{it->path()};
        std::error_code file_error;
        if (process_running(std::stol(name)) || !fs::is_regular_file(files.volume(), file_error)) continue;
        found.emplace_back(fs::last_write_time(files.volume(), file_error), files);
    }
    std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    std::vector<RecoveryFiles> result;
    for (auto& f : found) result.push_back(std::move(f.second));
    return result;
}

std::string recovered_source(const RecoveryFiles& files) {
    std::ifstream in(files.source());
    std::string line;
    std::getline(in, line);
    return line;
}

void write_recovered_source(const RecoveryFiles& files, const fs::path& source) {
    write_file_atomically(files.source(), [&source](std::ostream& out) { out << source.string() << "\n"; });
}

void remove_recovery_files(const RecoveryFiles& files) {
    std::error_code error;
    fs::remove_all(files.directory, error);
}

}  // namespace waxwork
