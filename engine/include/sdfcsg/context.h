// sdfcsg: the headless Vulkan compute context.
//
// No window and no surface extensions. Any device with a compute queue is acceptable,
// CPU devices (Mesa lavapipe) included; a discrete GPU is preferred, then integrated, virtual,
// CPU. SDFCSG_DEVICE=<index or part of the name> overrides the choice.
//
// Environment: where a field of ContextOptions or CompileOptions is left at its default, the
// library takes the setting from these variables, read once per process when the library first
// needs one of them (by the first Context::create or compileKernel()); later changes to the
// environment are not seen, so a program that wants other settings passes options instead.
//   SDFCSG_VALIDATION   1 turns the validation layer on, 0 off (ContextOptions::validation)
//   SDFCSG_DEVICE       a device index or part of its name (ContextOptions::device)
//   SDFCSG_CACHE_DIR    the SPIR-V disk cache ("off": none), else $XDG_CACHE_HOME/sdfcsg, else
//                       $HOME/.cache/sdfcsg (ContextOptions::shaderCacheDir, CompileOptions)
//   SDFCSG_CACHE_SIZE   that cache's cap in MiB, default 64; past it the least recently used
//                       entries are removed (CompileOptions::cacheMaxBytes)
// Mesa's own MESA_SHADER_CACHE_DISABLE and MESA_GLSL_CACHE_DISABLE, which Mesa reads whenever a
// device is made, are read by every Context::create (see ContextOptions::compileHelper). The
// language model's settings come from the environment only through llmConfigFromEnvironment()
// (sdfcsg/generate.h), when a program calls it.
//
// Threads: a Context may be shared. Renderers and Meshers made from one Context can be used
// from different threads at the same time (say, meshing in the background while a viewer
// renders); their GPU submissions take turns on the context's queue. Each Renderer or Mesher
// is used by one thread at a time. Scene loading, code generation, compileKernel() and the
// Evaluator's const methods are safe to call from any thread.
#pragma once

#include "sdfcsg/error.h"

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace sdfcsg {

namespace detail {
struct ContextAccess; // how the library reaches a context's internals
} // namespace detail

struct ContextOptions {
    // Enable VK_LAYER_KHRONOS_validation and count its messages. 0: off; 1: on (an error if the
    // layer is missing); -1: as SDFCSG_VALIDATION says, and where it is unset, on in debug builds
    // where the layer is installed.
    int validation = -1;
    // The device: its index in the Vulkan loader's order, or part of its name (any case). Empty:
    // SDFCSG_DEVICE's, and where that is unset, the preferred device.
    std::string device;
    // On lavapipe, which compiles kernels to machine code one after the other on its one queue,
    // compile a renderer's new kernels side by side on a second device of the same driver, which
    // hands the machine code over through Mesa's shader cache on disk (so only while that cache
    // is on, as it is by default). Other drivers compile in parallel threads anyway.
    bool compileHelper = true;
    // The folder where the context's renderers and meshers keep compiled SPIR-V between runs
    // (CompileOptions::cacheDir); an empty path: no disk cache. Unset: the environment's (above).
    std::optional<std::filesystem::path> shaderCacheDir;
};

class Context {
  public:
    static Result<std::unique_ptr<Context>> create(const ContextOptions& options = {});
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    std::string deviceName() const;
    // The device is a CPU implementation (lavapipe): invocations run in SIMD lanes through both
    // sides of every branch, so kernels with values baked in run several times faster there.
    bool cpuDevice() const;
    bool validationEnabled() const;
    // Messages the validation layer has reported so far (warnings and errors). Each is also
    // printed to stderr.
    uint32_t validationMessageCount() const;

    struct Impl; // the library's own (engine/src/gpu/vk.h)

  private:
    friend struct detail::ContextAccess;
    explicit Context(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

} // namespace sdfcsg
