#include "io/atomic_file.h"

#include "base/error.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <charconv>
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

// The hidden names a save gives its temporary files beside `target`: ".NAME.tmp-PID-..." for the new
// content, ".NAME.bak-PID-..." for the old content kept until a set of files is replaced.
std::string hidden_prefix(const std::filesystem::path& target, const char* kind) {
    return "." + target.filename().string() + "." + kind + "-";
}

// Removes the temporaries and backups of `target` left by a process that no longer runs (killed during
// a save): the PID in the name is checked with kill(pid, 0). A live process's files, and names that do
// not parse, are left alone; a reused PID only means a leftover waits for a later save.
void remove_stale_temporaries(const std::filesystem::path& target) {
    const std::filesystem::path directory = directory_of(target);
    DIR* dir = ::opendir(directory.c_str());
    if (!dir) return;
    const std::string prefixes[] = {hidden_prefix(target, "tmp"), hidden_prefix(target, "bak")};
    while (const dirent* entry = ::readdir(dir)) {
        const std::string_view name(entry->d_name);
        for (const std::string& prefix : prefixes) {
            if (!name.starts_with(prefix)) continue;
            const std::string_view rest = name.substr(prefix.size());
            long pid = 0;
            const auto [end, error] = std::from_chars(rest.data(), rest.data() + rest.size(), pid);
            if (error != std::errc() || end == rest.data() || *end != '-' || pid <= 0) continue;
            if (pid == ::getpid() || ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
            (void)::unlinkat(::dirfd(dir), entry->d_name, 0);
        }
    }
    ::closedir(dir);
}

// A hidden name beside `target` (see hidden_prefix) that no other save uses: the PID, a counter and
// a random number.
std::filesystem::path hidden_name(const std::filesystem::path& target, const char* kind) {
    static std::atomic<unsigned> counter{0};
    thread_local std::mt19937_64 random(std::random_device{}());
    return directory_of(target) / (hidden_prefix(target, kind) + std::to_string(::getpid()) + "-" +
                                   std::to_string(counter++) + "-" + std::to_string(random() % 1000000));
}

// A new hidden file beside `target`. O_EXCL makes the name ours alone even when two processes save
// the same file; mode 0666 lets the umask decide permissions as for any new file.
TemporaryFile create_hidden_file(const std::filesystem::path& target, const char* kind) {
    TemporaryFile temporary;
    temporary.target = target;
    for (int attempt = 0; attempt < 100; ++attempt) {
        temporary.path = hidden_name(target, kind);
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
    return temporary;
}

TemporaryFile create_temporary(const std::filesystem::path& target) {
    remove_stale_temporaries(target);
    TemporaryFile temporary = create_hidden_file(target, "tmp");
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

// The old content of a target that exists, kept beside it until every file of a set is replaced, so
// that a set whose later rename fails can be put back as it was. A hard link costs nothing; where one
// cannot be made (a file system without hard links, an immutable file) the content is copied.
struct Backup {
    std::filesystem::path path;  // empty: the target did not exist
};

Backup back_up(const std::filesystem::path& target) {
    struct stat existing {};
    if (::lstat(target.c_str(), &existing) != 0) return {};
    for (int attempt = 0; attempt < 100; ++attempt) {
        const std::filesystem::path link = hidden_name(target, "bak");
        if (::link(target.c_str(), link.c_str()) == 0) return {link};
        if (errno != EEXIST) break;
    }
    TemporaryFile copy = create_hidden_file(target, "bak");
    const int source = ::open(target.c_str(), O_RDONLY | O_CLOEXEC);
    int error = source < 0 ? errno : 0;
    std::vector<char> block(size_t{1} << 20);
    while (error == 0) {
        const ssize_t count = ::read(source, block.data(), block.size());
        if (count == 0) break;
        if (count < 0) {
            if (errno != EINTR) error = errno;
            continue;
        }
        for (ssize_t done = 0; done < count && error == 0;) {
            const ssize_t written = ::write(copy.fd, block.data() + done, static_cast<size_t>(count - done));
            if (written > 0) done += written;
            else if (errno != EINTR) error = errno;
        }
    }
    if (source >= 0) ::close(source);
    ::close(copy.fd);
    if (error != 0) {
        ::unlink(copy.path.c_str());
        throw FileError(target.string(), "cannot keep a copy of the old file while replacing it: " +
                                             system_error_text(error));
    }
    return {copy.path};
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
    // A single file needs no backup: its rename either happens or not.
    std::vector<Backup> backups;
    const auto drop_backups = [&] {
        for (const Backup& backup : backups)
            if (!backup.path.empty()) ::unlink(backup.path.c_str());
    };
    try {
        for (const auto& [target, write] : files) {
            temporaries.push_back(create_temporary(target));
            write_temporary(temporaries.back(), write);
        }
        if (files.size() > 1)
            for (const auto& file : files) backups.push_back(back_up(file.first));
        for (size_t i = 0; i < temporaries.size(); ++i) {
            TemporaryFile& temporary = temporaries[i];
            if (::rename(temporary.path.c_str(), temporary.target.c_str()) != 0) {
                std::string message = "cannot replace: " + system_error_text(errno);
                // Put the files already replaced back as they were, so the set stays consistent.
                for (size_t j = 0; j < i && j < backups.size(); ++j) {
                    const std::filesystem::path& replaced = temporaries[j].target;
                    if (backups[j].path.empty() ? ::unlink(replaced.c_str()) == 0
                                                : ::rename(backups[j].path.c_str(), replaced.c_str()) == 0) {
                        backups[j].path.clear();
                        continue;
                    }
                    message += "; " + replaced.string() + " could not be put back (" + system_error_text(errno) +
                               (backups[j].path.empty() ? ")" : "): its old content is in " + backups[j].path.string());
                    backups[j].path.clear();  // kept for the user
                }
                throw FileError(temporary.target.string(), message);
            }
            temporary.renamed = true;
        }
    } catch (...) {
        for (TemporaryFile& temporary : temporaries) discard(temporary);
        drop_backups();
        throw;
    }
    drop_backups();
    for (const TemporaryFile& temporary : temporaries) sync_directory(directory_of(temporary.target));
}

void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write) {
    write_files_atomically({FileWriter{path, write}});
}

}  // namespace waxwork
