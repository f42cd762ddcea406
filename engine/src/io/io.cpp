#include "sdfcsg/io.h"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <utility>

namespace sdfcsg {
namespace {

namespace fs = std::filesystem;

enum class Sink { Stdout, Stream, File };

struct Where {
    Sink sink = Sink::File;
    fs::path target; // the stream to open, or the file to replace (links followed)
};

Error ioError(const fs::path& path, const std::string& text) {
    return Error::message(ErrorKind::Io, path.string(), text);
}

Error ioErrno(const fs::path& path, const char* what) {
    return ioError(path, std::string(what) + ": " + std::strerror(errno));
}

// The file a dangling symbolic link names, links followed (it is made there).
Result<fs::path> danglingTarget(const fs::path& path) {
    fs::path at = path;
    for (int hops = 0; hops < 40; ++hops) {
        std::error_code ec;
        if (!fs::is_symlink(fs::symlink_status(at, ec))) return at;
        const fs::path next = fs::read_symlink(at, ec);
        if (ec) return ioError(path, "cannot read the symbolic link: " + ec.message());
        at = next.is_absolute() ? next : at.parent_path() / next;
    }
    return ioError(path, "too many levels of symbolic links");
}

Result<Where> locate(const fs::path& path) {
    if (path == "-") return Where{Sink::Stdout, {}};
    struct stat st;
    if (::lstat(path.c_str(), &st) != 0) {
        if (errno != ENOENT) return ioErrno(path, "cannot inspect the output");
        return Where{Sink::File, path};
    }
    Where where{Sink::File, path};
    if (S_ISLNK(st.st_mode)) {
        // The standard streams and descriptors are links to what the shell opened (a pipe, a
        // terminal, a file it redirected to): written into, as the shell would.
        const std::string text = path.lexically_normal().string();
        if (text.starts_with("/dev/") || text.starts_with("/proc/"))
            return Where{Sink::Stream, path};
        if (::stat(path.c_str(), &st) != 0) {
            if (errno != ENOENT) return ioErrno(path, "cannot inspect the output");
            auto target = danglingTarget(path);
            if (!target) return target.error();
            return Where{Sink::File, *target};
        }
        std::error_code ec;
        where.target = fs::canonical(path, ec);
        if (ec) return ioError(path, "cannot follow the symbolic link: " + ec.message());
    }
    if (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode)) return Where{Sink::Stream, path};
    if (!S_ISREG(st.st_mode))
        return ioError(path, S_ISDIR(st.st_mode)
                                 ? "is a folder, not a file to write"
                                 : "is not a regular file, a FIFO or a character device; "
                                   "refusing to replace it");
    return where;
}

// The checks of a file's folder: it exists and can be written.
Status checkFolder(const fs::path& path, const fs::path& target) {
    const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    struct stat st;
    if (::stat(folder.c_str(), &st) != 0)
        return ioError(path, "the folder " + folder.string() + " does not exist");
    if (!S_ISDIR(st.st_mode)) return ioError(path, folder.string() + " is not a folder");
    if (::access(folder.c_str(), W_OK) != 0)
        return ioErrno(path, ("cannot write in the folder " + folder.string()).c_str());
    return Ok{};
}

// Removes NAME.tmp-PID-N beside `target` where no process PID runs any more.
void removeStaleTemporaries(const fs::path& target) {
    const std::string prefix = target.filename().string() + ".tmp-";
    const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    std::error_code ec;
    for (auto it = fs::directory_iterator(folder, ec); !ec && it != fs::directory_iterator();
         it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (!name.starts_with(prefix)) continue;
        char* end = nullptr;
        const long pid = std::strtol(name.c_str() + prefix.size(), &end, 10);
        if (pid <= 0 || *end != '-' || pid == ::getpid()) continue;
        if (::kill(pid_t(pid), 0) != 0 && errno == ESRCH) fs::remove(it->path(), ec);
    }
}

} // namespace

Status checkOutput(const fs::path& path) {
    auto where = locate(path);
    if (!where) return where.error();
    if (where->sink != Sink::File) return Ok{};
    return checkFolder(path, where->target);
}

Result<OutputFile> OutputFile::open(const fs::path& path) {
    auto where = locate(path);
    if (!where) return where.error();
    OutputFile file;
    file.path_ = path;
    file.target_ = where->target;
    switch (where->sink) {
    case Sink::Stdout:
        std::fflush(stdout);
        file.fd_ = STDOUT_FILENO;
        return file;
    case Sink::Stream:
        file.fd_ = ::open(where->target.c_str(), O_WRONLY | O_CLOEXEC);
        if (file.fd_ < 0) return ioErrno(path, "cannot open the output");
        file.ownsFd_ = true;
        return file;
    case Sink::File:
        break;
    }
    if (auto ok = checkFolder(path, where->target); !ok) return ok.error();
    removeStaleTemporaries(where->target);
    // A unique name in the target's folder keeps the rename on one filesystem, hence atomic.
    // 0666 lets the umask decide the permissions, as for any new file.
    static std::atomic<unsigned> counter{0};
    file.temporary_ = where->target.string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                      std::to_string(counter.fetch_add(1));
    file.fd_ = ::open(file.temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (file.fd_ < 0) {
        file.temporary_.clear();
        return ioErrno(path, "cannot create a temporary file");
    }
    file.ownsFd_ = true;
    return file;
}

OutputFile::OutputFile(OutputFile&& other) noexcept {
    *this = std::move(other);
}

OutputFile& OutputFile::operator=(OutputFile&& other) noexcept {
    if (this != &other) {
        close();
        if (!temporary_.empty()) ::unlink(temporary_.c_str());
        path_ = std::move(other.path_);
        target_ = std::move(other.target_);
        temporary_ = std::exchange(other.temporary_, {});
        fd_ = std::exchange(other.fd_, -1);
        ownsFd_ = std::exchange(other.ownsFd_, false);
    }
    return *this;
}

OutputFile::~OutputFile() {
    close();
    if (!temporary_.empty()) ::unlink(temporary_.c_str());
}

void OutputFile::close() {
    if (fd_ >= 0 && ownsFd_) ::close(fd_);
    fd_ = -1;
}

Status OutputFile::write(std::string_view data) {
    if (fd_ < 0) return ioError(path_, "the output is closed");
    size_t done = 0;
    while (done < data.size()) {
        const ssize_t n = ::write(fd_, data.data() + done, data.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return ioErrno(path_, "cannot write");
        done += size_t(n);
    }
    return Ok{};
}

Status OutputFile::commit() {
    if (fd_ < 0) return ioError(path_, "the output is closed");
    const bool owned = ownsFd_;
    const int fd = std::exchange(fd_, -1);
    if (owned && ::close(fd) != 0) return ioErrno(path_, "cannot write");
    if (temporary_.empty()) return Ok{};
    if (std::rename(temporary_.c_str(), target_.c_str()) != 0)
        return ioErrno(path_, "cannot replace");
    temporary_.clear();
    return Ok{};
}

Status writeFileAtomic(const fs::path& path, std::string_view data) {
    auto file = OutputFile::open(path);
    if (!file) return file.error();
    if (auto written = file->write(data); !written) return written;
    return file->commit();
}

} // namespace sdfcsg
