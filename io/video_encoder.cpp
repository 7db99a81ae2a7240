#include "io/video_encoder.h"

#include <cerrno>
#include <cstdlib>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace waxwork {

namespace fs = std::filesystem;

std::string find_on_path(const std::string& name) {
    const char* path = std::getenv("PATH");
    std::stringstream folders(path ? path : "");
    std::string folder;
    while (std::getline(folders, folder, ':')) {
        const fs::path candidate = fs::path(folder.empty() ? "." : folder) / name;
        std::error_code error;
        if (::access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate, error)) return candidate.string();
    }
    return "";
}

bool encode_mp4(const std::string& ffmpeg, const fs::path& dir, const fs::path& mp4, double fps) {
    const std::vector<std::string> arguments = {
        ffmpeg, "-y", "-loglevel", "error", "-framerate", std::to_string(fps), "-i", (dir / "frame_%04d.png").string(),
        "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p", mp4.string()};
    std::vector<char*> argv;
    for (const std::string& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    // The child execs at once (or exits with _exit), so it neither runs nor flushes this process's
    // buffered output.
    const pid_t child = ::fork();
    if (child < 0) return false;
    if (child == 0) {
        ::execv(argv[0], argv.data());
        ::_exit(127);
    }
    int status = 0;
    while (::waitpid(child, &status, 0) < 0) {
        if (errno != EINTR) return false;
    }
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace waxwork
