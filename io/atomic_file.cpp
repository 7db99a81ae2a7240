#include "io/atomic_file.h"

#include "base/error.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <random>
#include <streambuf>
#include <string>

namespace waxwork {
namespace {

std::string system_error_text(int error) { return std::strerror(error); }

// A std::streambuf over a POSIX file descriptor. std::ofstream cannot give us the descriptor, and we
// need it for fsync(2); the libstdc++ stdio_filebuf extension would tie us to one standard library.
// Large writes bypass the buffer so a 50 MB volume is not copied twice.
class DescriptorStreamBuffer : public std::streambuf {
public:
    explicit DescriptorStreamBuffer(int fd) : fd_(fd), buffer_(size_t{1} << 20) { reset_buffer(); }

    // errno of the first failed write, 0 when every write succeeded.
    int error() const { return error_; }

protected:
    int_type overflow(int_type ch) override {
        if (!flush_buffer()) return traits_type::eof();
        if (!traits_type::eq_int_type(ch, traits_type::eof())) {
            *pptr() = traits_type::to_char_type(ch);
            pbump(1);
        }
        return traits_type::not_eof(ch);
    }

    std::streamsize xsputn(const char* data, std::streamsize count) override {
        if (static_cast<size_t>(count) < buffer_.size() / 2) return std::streambuf::xsputn(data, count);
        if (!flush_buffer() || !write_all(data, static_cast<size_t>(count))) return 0;
        return count;
    }

    int sync() override { return flush_buffer() ? 0 : -1; }

private:
    void reset_buffer() { setp(buffer_.data(), buffer_.data() + buffer_.size()); }

    bool flush_buffer() {
        const size_t pending = static_cast<size_t>(pptr() - pbase());
        const bool ok = pending == 0 || write_all(pbase(), pending);
        reset_buffer();
        return ok;
    }

    bool write_all(const char* data, size_t count) {
        if (error_ != 0) return false;
        while (count > 0) {
            const ssize_t written = ::write(fd_, data, count);
            if (written < 0) {
                if (errno == EINTR) continue;
                error_ = errno;
                return false;
            }
            data += written;
            count -= static_cast<size_t>(written);
        }
        return true;
    }

    int fd_;
    std::vector<char> buffer_;
    int error_ = 0;
};

struct TemporaryFile {
    std::filesystem::path target;
    std::filesystem::path path;
    int fd = -1;
    bool renamed = false;
};

std::filesystem::path directory_of(const std::filesystem::path& target) {
    const std::filesystem::path parent = target.parent_path();
    return parent.empty() ? std::filesystem::path(".") : parent;
}

// A new, uniquely named file beside `target`. O_EXCL makes the name ours alone even when two
// processes save the same file; mode 0666 lets the umask decide permissions as for any new file.
TemporaryFile create_temporary(const std::filesystem::path& target) {
    static std::atomic<unsigned> counter{0};
    thread_local std::mt19937_64 random(std::random_device{}());
    TemporaryFile temporary;
    temporary.target = target;
    for (int attempt = 0; attempt < 100; ++attempt) {
        const std::string name = "." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) +
                                 "-" + std::to_string(counter++) + "-" + std::to_string(random() % 1000000);
        temporary.path = directory_of(target) / name;
        temporary.fd = ::open(temporary.path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (temporary.fd >= 0) break;
        if (errno != EEXIST) {
            throw FileError(target.string(), "cannot create a temporary file in " +
                                                 directory_of(target).string() + ": " +
                                                 system_error_text(errno));
        }
    }
    if (temporary.fd < 0) {
        throw FileError(target.string(), "cannot find an unused temporary file name");
    }
    // Replacing a file keeps its permissions (a read-only-for-others volume stays so).
    struct stat existing {};
    if (::stat(target.c_str(), &existing) == 0 && S_ISREG(existing.st_mode)) {
        (void)::fchmod(temporary.fd, existing.st_mode & 07777);
    }
    return temporary;
}

void write_temporary(TemporaryFile& temporary, const std::function<void(std::ostream&)>& write) {
    const std::string name = temporary.target.string();
    {
        DescriptorStreamBuffer buffer(temporary.fd);
        std::ostream stream(&buffer);
        write(stream);
        stream.flush();
        if (!stream || buffer.error() != 0) {
            const int error = buffer.error();
            throw FileError(name, "cannot write: " +
                                      (error != 0 ? system_error_text(error) : std::string("stream error")));
        }
    }
    // fsync before rename: otherwise a crash after the rename can leave an empty file on ext4/xfs.
    if (::fsync(temporary.fd) != 0) {
        throw FileError(name, "cannot flush to disk: " + system_error_text(errno));
    }
    const int fd = temporary.fd;
    temporary.fd = -1;
    if (::close(fd) != 0) {
        throw FileError(name, "cannot close: " + system_error_text(errno));
    }
}

void discard(TemporaryFile& temporary) {
    if (temporary.fd >= 0) {
        ::close(temporary.fd);
        temporary.fd = -1;
    }
    if (!temporary.renamed && !temporary.path.empty()) ::unlink(temporary.path.c_str());
}

// Makes the renames durable; failure only weakens durability, never correctness, so it is ignored.
void sync_directory(const std::filesystem::path& directory) {
    const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    (void)::fsync(fd);
    ::close(fd);
}

}  // namespace

void write_files_atomically(const std::vector<FileWriter>& files) {
    // A target that is a directory cannot be replaced: refused before any file is, not halfway
    // through the renames (the .ele of a pair after its .node was replaced).
    for (const auto& file : files) {
        std::error_code error;
        if (std::filesystem::is_directory(file.first, error))
            throw FileError(file.first.string(), "cannot replace: it is a directory");
    }
    std::vector<TemporaryFile> temporaries;
    temporaries.reserve(files.size());
    try {
        for (const auto& [target, write] : files) {
            temporaries.push_back(create_temporary(target));
            write_temporary(temporaries.back(), write);
        }
        for (TemporaryFile& temporary : temporaries) {
            if (::rename(temporary.path.c_str(), temporary.target.c_str()) != 0) {
                throw FileError(temporary.target.string(), "cannot replace: " + system_error_text(errno));
            }
            temporary.renamed = true;
        }
    } catch (...) {
        for (TemporaryFile& temporary : temporaries) discard(temporary);
        throw;
    }
    for (const TemporaryFile& temporary : temporaries) sync_directory(directory_of(temporary.target));
}

void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write) {
    write_files_atomically({FileWriter{path, write}});
}

}  // namespace waxwork
