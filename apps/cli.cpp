#include "cli.h"

#include <csignal>
#include <cstdio>

#include <unistd.h>

namespace sdfcsg::app {
namespace {

volatile std::sig_atomic_t gInterrupted = 0;

extern "C" void onInterrupt(int) {
    if (gInterrupted) ::_exit(kInterrupted);
    gInterrupted = 1;
}

} // namespace

int exitCode(const Error& e) {
    switch (e.kind) {
    case ErrorKind::Io: return kIo;
    case ErrorKind::Syntax:
    case ErrorKind::Validation:
    case ErrorKind::Limit: return kInvalidScene;
    case ErrorKind::Usage: return kUsage;
    case ErrorKind::Shader:
    case ErrorKind::Vulkan: return kGpu;
    case ErrorKind::Remote: return kRemote;
    case ErrorKind::Cancelled: return kInterrupted;
    }
    return kGpu;
}

int fail(const Error& e) {
    if (e.kind == ErrorKind::Cancelled && interrupted())
        std::fputs("sdfcsg: interrupted; nothing was written\n", stderr);
    else
        std::fprintf(stderr, "%s\n", e.str().c_str());
    return exitCode(e);
}

int usageError(std::string_view command, std::string_view message) {
    std::fprintf(stderr, "sdfcsg %.*s: %.*s\nTry 'sdfcsg %.*s --help'.\n", int(command.size()),
                 command.data(), int(message.size()), message.data(), int(command.size()),
                 command.data());
    return kUsage;
}

void catchInterrupts() {
    struct sigaction action = {};
    action.sa_handler = onInterrupt;
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGINT, &action, nullptr);
    ::sigaction(SIGTERM, &action, nullptr);
}

bool interrupted() {
    return gInterrupted != 0;
}

} // namespace sdfcsg::app
