#include "cli.h"

#include <sdfcsg/io.h>

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
// Under gFinishing: the outputs in place, and one being streamed (into a FIFO, standard
// output), for the message of an interruption.
std::string gWritten, gStreaming;

// Under gFinishing.
std::string interruptedMessage() {
    std::string message = "sdfcsg: interrupted; ";
    message += gWritten.empty() ? "nothing was written" : "wrote " + gWritten + " in full";
    if (!gStreaming.empty()) message += "; " + gStreaming + " holds part of its output";
    return message;
}

extern "C" void onInterrupt(int) {
    if (gInterrupted) ::_exit(kInterrupted);
    gInterrupted = 1;
    ::sem_post(&gSignalled);
}

void watchdog() {
    while (::sem_wait(&gSignalled) != 0) {
    }
    std::this_thread::sleep_for(kGrace);
    std::lock_guard lock(gFinishing); // an output being put in place is put there
    if (!gReported.exchange(true)) {
        const std::string message = interruptedMessage() + "\n";
        (void)!::write(STDERR_FILENO, message.data(), message.size());
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
    if (e.kind == ErrorKind::Cancelled && interrupted()) {
        std::lock_guard lock(gFinishing);
        return stopInterrupted(interruptedMessage());
    }
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

Status writeOutput(const std::filesystem::path& path, std::string_view bytes) {
    const Error cancelled = Error::message(ErrorKind::Cancelled, path.string(), "cancelled");
    if (interrupted()) return cancelled;
    auto file = OutputFile::open(path);
    if (!file) return file.error();
    if (file->streamed()) {
        std::lock_guard lock(gFinishing);
        gStreaming = path == "-" ? "standard output" : path.string();
    }
    // In pieces, so that an interruption stops the write within a piece's time, and the
    // temporary file goes with the OutputFile.
    constexpr size_t kPiece = size_t(4) << 20;
    for (size_t at = 0; at < bytes.size(); at += kPiece) {
        if (interrupted()) return cancelled;
        if (auto written = file->write(bytes.substr(at, kPiece)); !written) return written;
    }
    std::lock_guard lock(gFinishing);
    if (interrupted()) return cancelled;
    if (auto committed = file->commit(); !committed) return committed;
    gWritten += (gWritten.empty() ? "" : ", ") + (path == "-" ? "standard output" : path.string());
    gStreaming.clear();
    return Ok{};
}

Finishing::Finishing() {
    gFinishing.lock();
}

Finishing::~Finishing() {
    gFinishing.unlock();
}

} // namespace sdfcsg::app
