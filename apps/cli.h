// What every sdfcsg command shares: exit codes, error reporting and Ctrl-C.
#pragma once

#include <sdfcsg/error.h>

#include <filesystem>
#include <string>
#include <string_view>

namespace sdfcsg::app {

// Exit codes, documented in docs/cli.md.
enum Exit : int {
    kOk = 0,
    kInvalidScene = 1,  // the scene failed to parse or validate, or a limit was exceeded
    kUsage = 2,         // bad command line
    kIo = 3,            // a file could not be read or written
    kGpu = 4,           // no usable Vulkan device, or a shader failed to compile
    kRemote = 5,        // the language model endpoint failed, refused or answered unusably
    kInterrupted = 130, // Ctrl-C (SIGINT) or SIGTERM; nothing written but a recording or report
};

int exitCode(const Error& e);
// Prints the error's diagnostics on stderr and returns its exit code.
int fail(const Error& e);
// "sdfcsg COMMAND: MESSAGE" and a pointer to --help; returns kUsage.
int usageError(std::string_view command, std::string_view message);

// From the first SIGINT or SIGTERM on, interrupted() is true, and long work (renders, mesh
// extraction) stops at its next progress check, before any output is written. Work that cannot
// be cancelled (a kernel build inside the driver) does not hold the command up: a watchdog ends
// it with kInterrupted well within a second of the signal, though never while a Finishing lives.
// A second signal ends the process at once.
void catchInterrupts();
bool interrupted();

// Prints `message` as the reason the command stops (once, whoever stops it) and returns
// kInterrupted.
int stopInterrupted(const std::string& message);

// While one lives, an interrupted command is not ended: the span of writing an output whole, or
// the recording and report an interrupted command leaves. Keep it short.
class Finishing {
  public:
    Finishing();
    ~Finishing();
    Finishing(const Finishing&) = delete;
    Finishing& operator=(const Finishing&) = delete;
};

// Runs `write`, which writes an output whole or not at all, under a Finishing.
template <class Write> Status writeWhole(Write&& write) {
    Finishing finishing;
    return write();
}

// Writes `bytes` to `path` (sdfcsg::OutputFile), unless the command is interrupted first: then
// nothing is written (a Cancelled error). Once in place, an interruption's message names it.
Status writeOutput(const std::filesystem::path& path, std::string_view bytes);

} // namespace sdfcsg::app
