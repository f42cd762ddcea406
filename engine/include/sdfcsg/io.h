// sdfcsg: file output that is whole or absent, and never replaces what it should not.
#pragma once

#include "sdfcsg/error.h"

#include <filesystem>
#include <string_view>

namespace sdfcsg {

// An output opened where `path` leads:
// - "-": standard output, streamed into;
// - a symbolic link: the file it names (links followed to the end), as below;
// - a FIFO or a character device (/dev/null, /dev/stdout): streamed into;
// - a regular file, or nothing yet: a temporary file beside it, renamed over it by commit(), so
//   readers see either the old file or the complete new one. Temporaries that a killed process
//   left beside the same target (NAME.tmp-PID-N, PID no longer running) are removed first.
// Anything else (a folder, a block device, a socket) is refused, as is a folder that does not
// exist or cannot be written. Errors are Io errors naming `path`.
class OutputFile {
  public:
    static Result<OutputFile> open(const std::filesystem::path& path);
    OutputFile(OutputFile&& other) noexcept;
    OutputFile& operator=(OutputFile&& other) noexcept;
    ~OutputFile(); // an output not committed: the temporary is removed, the target untouched

    // Appends `data`.
    Status write(std::string_view data);
    // Puts the output in place (renames the temporary over the target; a stream is done).
    Status commit();
    // Written straight into its target (standard output, a FIFO, a device): no temporary.
    bool streamed() const { return temporary_.empty(); }

  private:
    OutputFile() = default;
    void close();

    std::filesystem::path path_;      // as given, for messages
    std::filesystem::path target_;    // where the output ends up (links followed)
    std::filesystem::path temporary_; // empty when streamed
    int fd_ = -1;
    bool ownsFd_ = false; // false for standard output
};

// What OutputFile::open would refuse, checked without creating anything: for the checks of a
// command's arguments, before its work starts.
Status checkOutput(const std::filesystem::path& path);

// Opens, writes `data` and commits (see OutputFile).
Status writeFileAtomic(const std::filesystem::path& path, std::string_view data);

} // namespace sdfcsg
