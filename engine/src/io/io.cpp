#include "sdfcsg/io.h"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <string>
#include <unistd.h>

namespace sdfcsg {

Status writeFileAtomic(const std::filesystem::path& path, std::string_view data) {
    auto fail = [&](const char* what) {
        return Error::message(ErrorKind::Io, path.string(),
                              std::string(what) + ": " + std::strerror(errno));
    };
    // A unique name in the target's directory keeps the rename on one filesystem, hence atomic.
    // open() with 0666 lets the umask decide the permissions, as for any new file.
    static std::atomic<unsigned> counter{0};
    std::string tmp = path.string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                      std::to_string(counter.fetch_add(1));
    int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) return fail("cannot create a temporary file");
    size_t done = 0;
    while (done < data.size()) {
        ssize_t n = ::write(fd, data.data() + done, data.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            Error e = fail("cannot write");
            ::close(fd);
            ::unlink(tmp.c_str());
            return e;
        }
        done += size_t(n);
    }
    if (::close(fd) != 0) {
        Error e = fail("cannot write");
        ::unlink(tmp.c_str());
        return e;
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        Error e = fail("cannot replace");
        ::unlink(tmp.c_str());
        return e;
    }
    return Ok{};
}

} // namespace sdfcsg
