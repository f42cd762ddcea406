#include "cli.h"

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <mutex>
#include <thread>

#include <semaphore.h>
#include <unistd.h>

namespace sdfcsg::app {
namespace {

// How long an interrupted command may take to stop by itself before the watchdog ends it: work
// that cannot be cancelled (a kernel build inside the driver, a dispatch already submitted)
// must not keep it running past the second the user expects.
constexpr auto kGrace = std::chrono::milliseconds(600);

volatile std::sig_atomic_t gInterrupted = 0;
sem_t gSignalled;                   // posted by the signal handler (sem_post is signal-safe)
std::mutex gFinishing;              // held while outputs are written whole, or reports left
std::atomic<bool> gReported{false}; // the reason of the stop has been printed

extern "C" void onInterrupt(int) {
    if (gInterrupted) ::_exit(kInterrupted);
    gInterrupted = 1;
    ::sem_post(&gSignalled);
}

void watchdog() {
    while (::sem_wait(&gSignalled) != 0) {
    }
    std::this_thread::sleep_for(kGrace);
    std::lock_guard lock(gFinishing); // an output being written is written whole
    if (!gReported.exchange(true)) {
        static const char kMessage[] = "sdfcsg: interrupted; nothing was written\n";
        (void)!::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
    }
    ::_exit(kInterrupted);
}

} // namespace

int exitCode(const Error& e) {
    switch (e.kind) {
    case ErrorKind::Io:
        return kIo;
    case ErrorKind::Syntax:
    case ErrorKind::Validation:
    case ErrorKind::Limit:
        return kInvalidScene;
    case ErrorKind::Usage:
        return kUsage;
    case ErrorKind::Shader:
    case ErrorKind::Vulkan:
        return kGpu;
    case ErrorKind::Remote:
        return kRemote;
    case ErrorKind::Cancelled:
        return kInterrupted;
    }
    return kGpu;
}

int fail(const Error& e) {
    if (e.kind == ErrorKind::Cancelled && interrupted())
        return stopInterrupted("sdfcsg: interrupted; nothing was written");
    std::fprintf(stderr, "%s\n", e.str().c_str());
    return exitCode(e);
}

int stopInterrupted(const std::string& message) {
    if (!gReported.exchange(true)) std::fprintf(stderr, "%s\n", message.c_str());
    return kInterrupted;
}

int usageError(std::string_view command, std::string_view message) {
    std::fprintf(stderr, "sdfcsg %.*s: %.*s\nTry 'sdfcsg %.*s --help'.\n", int(command.size()),
                 command.data(), int(message.size()), message.data(), int(command.size()),
                 command.data());
    return kUsage;
}

void catchInterrupts() {
    static std::once_flag once;
    std::call_once(once, [] {
        ::sem_init(&gSignalled, 0, 0);
        std::thread(watchdog).detach();
        struct sigaction action = {};
        action.sa_handler = onInterrupt;
        sigemptyset(&action.sa_mask);
        ::sigaction(SIGINT, &action, nullptr);
        ::sigaction(SIGTERM, &action, nullptr);
    });
}

bool interrupted() {
    return gInterrupted != 0;
}

Finishing::Finishing() {
    gFinishing.lock();
}

Finishing::~Finishing() {
    gFinishing.unlock();
}

} // namespace sdfcsg::app
