// What every sdfcsg command shares: exit codes, error reporting and Ctrl-C.
#pragma once

#include <sdfcsg/error.h>

#include <string_view>

namespace sdfcsg::app {

// Exit codes, documented in the README.
enum Exit : int {
    kOk = 0,
    kInvalidScene = 1, // the scene failed to parse or validate, or a limit was exceeded
    kUsage = 2,        // bad command line
    kIo = 3,           // a file could not be read or written
    kGpu = 4,          // no usable Vulkan device, or a shader failed to compile
    kRemote = 5,       // the language model endpoint failed, refused or answered unusably
    kInterrupted = 130, // Ctrl-C (SIGINT) or SIGTERM; nothing written but a recording or report
};

int exitCode(const Error& e);
// Prints the error's diagnostics on stderr and returns its exit code.
int fail(const Error& e);
// "sdfcsg COMMAND: MESSAGE" and a pointer to --help; returns kUsage.
int usageError(std::string_view command, std::string_view message);

// From the first SIGINT or SIGTERM on, interrupted() is true, and long work (renders, mesh
// extraction) stops at its next progress check, before any output is written. A second signal
// ends the process at once.
void catchInterrupts();
bool interrupted();

} // namespace sdfcsg::app
